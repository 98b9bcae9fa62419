// SPDX-License-Identifier: MIT
// Write to "<file>.tmp", rename when complete.
#include "core/atomic_file.hpp"

#include "core/check.hpp"

#include <fstream>
#include <stdexcept>
#include <system_error>

namespace mlc {

std::filesystem::path temporary_path(const std::filesystem::path& file) {
    std::filesystem::path tmp = file;
    tmp += ".tmp";
    return tmp;
}

void write_file_atomically(const std::filesystem::path& file,
                           const std::function<void(std::ostream&)>& write) {
    const std::filesystem::path tmp = temporary_path(file);
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    MLC_CHECK(out.is_open(), "cannot open '" << tmp.string()
                                             << "' for writing; does the folder exist and is it "
                                                "writable?");
    try {
        write(out);
        out.close();
        if (out.fail())
            throw std::runtime_error("writing '" + tmp.string() + "' failed (disk full?)");
        std::error_code ec;
        std::filesystem::rename(tmp, file, ec);
        if (ec)
            throw std::runtime_error("cannot rename '" + tmp.string() + "' to '" + file.string() +
                                     "': " + ec.message());
    } catch (...) {
        out.close();
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
    }
}

} // namespace mlc
