// SPDX-License-Identifier: MIT
/// @file Error types and the always-on input checks (MLC_CHECK) and debug-only asserts
/// (MLC_ASSERT).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace mlc {

/// Bad input from a user: a scene, a mesh, a parameter. The message names the problem.
class InvalidInput : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

/// A numerical breakdown: NaN/Inf residual, zero inner product in a Krylov method, singular pivot.
class SolverBreakdown : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A solve stopped on request (levels::SolveObserver::interrupt_requested), between Newton
/// iterations; the message says where.
class Interrupted : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A nonlinear (Newton) solve that did not converge; the message says where and how.
class ConvergenceFailure : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

namespace detail {
[[noreturn]] void throw_invalid_input(const char* cond, const std::string& msg, const char* func,
                                      const char* file, int line);
} // namespace detail

} // namespace mlc

/// Always-on check: throws mlc::InvalidInput with the condition, the streamed message and the
/// place. Usage: `MLC_CHECK(E > 0, "Young's modulus E must be positive, found " << E);`
#define MLC_CHECK(cond, msg)                                                                       \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            std::ostringstream mlc_check_os_;                                                      \
            mlc_check_os_ << msg;                                                                  \
            ::mlc::detail::throw_invalid_input(#cond, mlc_check_os_.str(), __func__, __FILE__,     \
                                               __LINE__);                                          \
        }                                                                                          \
    } while (false)

/// Debug-only internal invariant.
#ifndef NDEBUG
#define MLC_ASSERT(cond, msg) MLC_CHECK(cond, msg)
#else
#define MLC_ASSERT(cond, msg)                                                                      \
    do {                                                                                           \
    } while (false)
#endif
