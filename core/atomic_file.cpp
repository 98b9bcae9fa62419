// SPDX-License-Identifier: MIT
// Write to a temporary unique to the writer, rename when complete.
#include "core/atomic_file.hpp"

#include "core/check.hpp"
#include "core/stop.hpp"

#include <array>
#include <atomic>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unistd.h>

namespace mlc {

namespace {

std::atomic<unsigned long> g_temporaries{0};

/// The temporaries being written, for remove_registered_temporaries (a signal handler): a slot is
/// claimed by a writer, filled, then marked ready; the handler only reads ready slots.
constexpr int kSlots = 16;
constexpr size_t kPathBytes = 4096;
struct Slot {
    std::atomic<bool> claimed{false};
    std::atomic<bool> ready{false};
    std::array<char, kPathBytes> path{};
};
std::array<Slot, kSlots> g_slots;

/// A file buffer that fails every write once a stop is requested while writes are stoppable, so
/// that a long write ends within one buffer of the request.
class StoppableFilebuf : public std::filebuf {
protected:
    int_type overflow(int_type c) override {
        if (write_stop_requested()) return traits_type::eof();
        return std::filebuf::overflow(c);
    }
    std::streamsize xsputn(const char_type* s, std::streamsize n) override {
        if (write_stop_requested()) return 0;
        return std::filebuf::xsputn(s, n);
    }
};

} // namespace

std::filesystem::path temporary_path(const std::filesystem::path& file) {
    std::filesystem::path tmp = file;
    tmp += ".";
    tmp += std::to_string(::getpid());
    tmp += ".";
    tmp += std::to_string(g_temporaries.fetch_add(1));
    tmp += ".tmp";
    return tmp;
}

RegisteredTemporary::RegisteredTemporary(const std::filesystem::path& tmp) {
    const std::string& s = tmp.native();
    if (s.size() >= kPathBytes) return;
    for (int i = 0; i < kSlots; ++i) {
        Slot& slot = g_slots[static_cast<size_t>(i)];
        if (slot.claimed.exchange(true)) continue;
        std::memcpy(slot.path.data(), s.c_str(), s.size() + 1);
        slot.ready.store(true);
        slot_ = i;
        return;
    }
}

RegisteredTemporary::~RegisteredTemporary() {
    release();
}

void RegisteredTemporary::release() {
    if (slot_ < 0) return;
    Slot& slot = g_slots[static_cast<size_t>(slot_)];
    slot.ready.store(false);
    slot.claimed.store(false);
    slot_ = -1;
}

void remove_registered_temporaries() noexcept {
    for (Slot& slot : g_slots)
        if (slot.ready.load()) ::unlink(slot.path.data());
}

void write_file_atomically(const std::filesystem::path& file,
                           const std::function<void(std::ostream&)>& write) {
    const std::filesystem::path tmp = temporary_path(file);
    RegisteredTemporary registered(tmp);
    StoppableFilebuf buf;
    MLC_CHECK(buf.open(tmp, std::ios::out | std::ios::binary | std::ios::trunc),
              "cannot open '" << tmp.string()
                              << "' for writing; does the folder exist and is it writable?");
    std::ostream out(&buf);
    try {
        write(out);
        out.flush();
        const bool closed = buf.close() != nullptr;
        if (write_stop_requested())
            throw Interrupted("stopped while writing '" + file.string() +
                              "' (the file was left as it was)");
        if (!closed || out.fail())
            throw std::runtime_error("writing '" + tmp.string() + "' failed (disk full?)");
        std::error_code ec;
        std::filesystem::rename(tmp, file, ec);
        if (ec)
            throw std::runtime_error("cannot rename '" + tmp.string() + "' to '" + file.string() +
                                     "': " + ec.message());
        registered.release();
    } catch (...) {
        buf.close();
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
    }
}

AtomicOfstream::AtomicOfstream(const std::filesystem::path& file)
    : AtomicOfstream(file, temporary_path(file)) {}

AtomicOfstream::AtomicOfstream(const std::filesystem::path& file, std::filesystem::path tmp)
    : std::ofstream(tmp, std::ios::binary | std::ios::trunc), file_(file), tmp_(std::move(tmp)),
      uncaught_(std::uncaught_exceptions()), pending_(is_open()) {}

AtomicOfstream::AtomicOfstream(AtomicOfstream&& other) noexcept
    : std::ofstream(std::move(other)), file_(std::move(other.file_)), tmp_(std::move(other.tmp_)),
      uncaught_(other.uncaught_), pending_(other.pending_) {
    other.pending_ = false;
}

AtomicOfstream::~AtomicOfstream() {
    if (!pending_) return;
    if (std::uncaught_exceptions() > uncaught_) {
        std::ofstream::close();
        std::error_code ec;
        std::filesystem::remove(tmp_, ec);
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
        std::filesystem::remove(tmp_, ec);
        return;
    }
    std::filesystem::rename(tmp_, file_, ec);
    if (ec) {
        setstate(std::ios::failbit);
        std::filesystem::remove(tmp_, ec);
    }
}

} // namespace mlc
