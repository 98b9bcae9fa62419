// SPDX-License-Identifier: MIT
// Out-of-line thrower for MLC_CHECK (keeps the macro small).
#include "core/check.hpp"
#include "core/user_message.hpp"

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

namespace mlc {

std::string user_message(const std::string& what, std::string* locations) {
    // The form throw_invalid_input writes: " [check `" cond "` in " func ", " file ":" line "]".
    const std::string open = " [check `";
    std::string out, where;
    size_t pos = 0;
    while (pos < what.size()) {
        const size_t b = what.find(open, pos);
        if (b == std::string::npos) break;
        const size_t in = what.find("` in ", b + open.size());
        size_t e = std::string::npos;
        if (in != std::string::npos) {
            // The closing "]" after ":<digits>" (the condition may hold brackets itself).
            for (size_t c = what.find(':', in); c != std::string::npos; c = what.find(':', c + 1)) {
                size_t d = c + 1;
                while (d < what.size() && what[d] >= '0' && what[d] <= '9')
                    ++d;
                if (d > c + 1 && d < what.size() && what[d] == ']') {
                    e = d;
                    break;
                }
            }
        }
        if (e == std::string::npos) break;
        out.append(what, pos, b - pos);
        if (!where.empty()) where += "; ";
        where.append(what, b + 2, e - b - 2);
        pos = e + 1;
    }
    out.append(what, pos, std::string::npos);
    if (locations) *locations = where;
    return out;
}

} // namespace mlc
