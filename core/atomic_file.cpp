// SPDX-License-Identifier: MIT
// Write to "<file>.tmp", rename when complete.
#include "core/atomic_file.hpp"

#include "core/check.hpp"

#include <exception>
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

AtomicOfstream::AtomicOfstream(const std::filesystem::path& file)
    : std::ofstream(temporary_path(file), std::ios::binary | std::ios::trunc), file_(file),
      uncaught_(std::uncaught_exceptions()), pending_(is_open()) {}

AtomicOfstream::AtomicOfstream(AtomicOfstream&& other) noexcept
    : std::ofstream(std::move(other)), file_(std::move(other.file_)), uncaught_(other.uncaught_),
      pending_(other.pending_) {
    other.pending_ = false;
}

AtomicOfstream::~AtomicOfstream() {
    if (!pending_) return;
    if (std::uncaught_exceptions() > uncaught_) {
        std::ofstream::close();
        std::error_code ec;
        std::filesystem::remove(temporary_path(file_), ec);
        return;
    }
    close();
}

void AtomicOfstream::close() {
    if (!pending_) return;
    pending_ = false;
    std::ofstream::close();
    std::error_code ec;
    if (fail()) {
        std::filesystem::remove(temporary_path(file_), ec);
        return;
    }
    std::filesystem::rename(temporary_path(file_), file_, ec);
    if (ec) {
        setstate(std::ios::failbit);
        std::filesystem::remove(temporary_path(file_), ec);
    }
}

} // namespace mlc
