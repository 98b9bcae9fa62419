// SPDX-License-Identifier: MIT
/// @file Sparse Cholesky factorization (CHOLMOD, supernodal) of a symmetric positive definite
/// matrix in the caller's order, with access to the trailing dense block of the factor.
#pragma once

#include "core/types.hpp"

#include <Eigen/Dense>
#include <memory>
#include <vector>

namespace mlc::solvers {

/// A = L L^T by CHOLMOD's supernodal method, with no reordering of its own: the caller orders the
/// unknowns (e.g. fill-reducing order with a chosen set last). CHOLMOD headers stay in the .cpp.
/// Not copyable; `solve` is const and allocates its result.
class SparseCholesky {
public:
    SparseCholesky();
    ~SparseCholesky();
    SparseCholesky(const SparseCholesky&) = delete;
    SparseCholesky& operator=(const SparseCholesky&) = delete;

    /// Factors A (only its lower triangle is read). Throws InvalidInput when A is not positive
    /// definite (naming the failing column).
    void factor(const SparseMatrixCol& A);
    /// x = A^{-1} b.
    void solve(const Vector& b, Vector& x) const;
    /// The bottom-right n x n block of L, dense (L lower triangular, A = L L^T in the given order).
    Eigen::MatrixXd trailing_block(Index n) const;
    /// Nonzeros of L.
    double factor_nonzeros() const;

    /// A fill-reducing symmetric order of A (CHOLMOD's choice between AMD and METIS nested
    /// dissection): order[new] = old.
    static std::vector<int> fill_reducing_order(const SparseMatrixCol& A);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace mlc::solvers
