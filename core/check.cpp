// SPDX-License-Identifier: MIT
// Out-of-line thrower for MLC_CHECK (keeps the macro small).
#include "core/check.hpp"

#include <filesystem>

namespace mlc::detail {

void throw_invalid_input(const char* cond, const std::string& msg, const char* func,
                         const char* file, int line) {
    std::ostringstream os;
    os << msg << " [check `" << cond << "` in " << func << ", "
       << std::filesystem::path(file).filename().string() << ":" << line << "]";
    throw InvalidInput(os.str());
}

} // namespace mlc::detail
