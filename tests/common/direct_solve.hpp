// SPDX-License-Identifier: MIT
/// @file The reference direct solve of the tests: the library's sparse LU, so that Eigen's sparse
/// factorizations are compiled once in mlc_solvers and not again in every test file.
#pragma once

#include "core/types.hpp"
#include "solvers/direct.hpp"

namespace mlc::test {

/// x = A^{-1} b by solvers::SparseLUPreconditioner (Eigen's SparseLU, COLAMD order, partial
/// pivoting). A singular A throws SolverBreakdown.
inline Vector lu_solve(const SparseMatrix& A, const Vector& b) {
    solvers::SparseLUPreconditioner lu;
    lu.setup(A);
    Vector x;
    lu.apply(b, x);
    return x;
}

} // namespace mlc::test
