// SPDX-License-Identifier: MIT
/// @file Entry checks shared by the smoothers and preconditioners: square, compressed, finite.
#pragma once

#include "core/types.hpp"

#include <string_view>

namespace mlc::smoothers {

/// Throws mlc::InvalidInput (naming `who`, e.g. "ILUK::setup") unless A is square, non-empty,
/// compressed (`A.makeCompressed()` fixes that) and every stored entry is finite.
/// Cost: one pass over the stored values; call at setup, never inside apply.
void check_setup_matrix(const SparseMatrix& A, std::string_view who);

/// Throws mlc::InvalidInput unless `v.size() == n`; `what` names the vector in the message.
void check_size(const Vector& v, Index n, std::string_view who, std::string_view what);

/// The largest |a_ij| over row i of A (0 for an empty row). A must be compressed.
double row_max_abs(const SparseMatrix& A, Index i);

} // namespace mlc::smoothers
