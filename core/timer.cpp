// SPDX-License-Identifier: MIT
// Timings table printing.
#include "core/timer.hpp"

#include <iomanip>

namespace mlc {

void Timings::print(std::ostream& os) const {
    os << "  " << std::left << std::setw(28) << "section" << std::right << std::setw(8) << "calls"
       << std::setw(12) << "seconds"
       << "\n";
    for (const auto& [name, e] : table_)
        os << "  " << std::left << std::setw(28) << name << std::right << std::setw(8) << e.calls
           << std::setw(12) << std::fixed << std::setprecision(3) << e.seconds << "\n";
    os << std::defaultfloat;
}

} // namespace mlc
