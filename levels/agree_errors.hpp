// SPDX-License-Identifier: MIT
/// @file One error for every process of a distributed build: when work on some processes' parts
/// fails with InvalidInput, every process throws the message of the lowest failing process, so
/// that none waits alone in a later exchange (the 2D and 3D distributed levels).
#pragma once

#include "core/check.hpp"
#include "core/communicator.hpp"

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace mlc::levels::detail {

/// Collective. `error`: this process's message (empty: none). When some process has one, every
/// process throws InvalidInput with the message of the lowest process that has one of its own,
/// followed by its rank when there are several processes. A message starting with `placeholder`
/// (when given) only says that another process failed: it is never chosen, and it is thrown as
/// it is when no process has a message of its own.
inline void throw_first_error(const Communicator& comm, const std::string& error,
                              const char* placeholder = nullptr) {
    if (comm.max(error.empty() ? 0 : 1) == 0) return;
    const bool own = !error.empty() && !(placeholder && error.rfind(placeholder, 0) == 0);
    const int first = comm.min(own ? comm.rank() : comm.size());
    if (first == comm.size())
        throw InvalidInput(error.empty() && placeholder ? placeholder : error);
    std::int64_t n = comm.rank() == first ? static_cast<std::int64_t>(error.size()) : 0;
    comm.broadcast(std::span<std::int64_t>(&n, 1), first);
    std::vector<std::int64_t> chars(static_cast<size_t>(n));
    if (comm.rank() == first) std::copy(error.begin(), error.end(), chars.begin());
    comm.broadcast(std::span<std::int64_t>(chars), first);
    std::string message(chars.begin(), chars.end());
    if (comm.size() > 1) message += " (process " + std::to_string(first) + ")";
    throw InvalidInput(message);
}

/// Runs `local` (work on this process's part alone) and agrees on its errors
/// (throw_first_error).
template <class F> void agree_on_errors(const Communicator& comm, F&& local) {
    std::string error;
    try {
        local();
    } catch (const InvalidInput& e) {
        error = e.what();
        if (error.empty()) error = "invalid input";
    }
    throw_first_error(comm, error);
}

} // namespace mlc::levels::detail
