// SPDX-License-Identifier: MIT
/// @file Fundamental scalar, index, vector and sparse-matrix types used everywhere in mlcontact.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace mlc {

/// Floating-point type of every field and matrix entry.
using Scalar = double;
/// Size and position type (signed, as Eigen uses).
using Index = Eigen::Index;
/// Dense vector of unknowns or nodal values.
using Vector = Eigen::VectorXd;
/// A 2D point or vector.
using Vec2 = Eigen::Vector2d;
/// Compressed sparse row matrix; `int` storage index keeps the pattern small.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
/// Column-major variant, for Eigen's direct solvers.
using SparseMatrixCol = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
/// A SparseMatrix that moves by swapping its arrays. Eigen 3.4's SparseMatrix has no move
/// constructor or move assignment, so moving one copies it: a Level moved into the hierarchy
/// copied its K twice. Used for the large matrices of structs
/// that are returned and moved (fem::ElasticSystem, transfer::LevelTransfer); it is a
/// SparseMatrix everywhere else.
class MovableSparseMatrix : public SparseMatrix {
public:
    MovableSparseMatrix() = default;
    MovableSparseMatrix(const MovableSparseMatrix&) = default;
    MovableSparseMatrix(MovableSparseMatrix&& other) noexcept { swap(other); }
    MovableSparseMatrix(const SparseMatrix& other) : SparseMatrix(other) {}
    MovableSparseMatrix(SparseMatrix&& other) noexcept { swap(other); }
    MovableSparseMatrix(Index rows, Index cols) : SparseMatrix(rows, cols) {}
    ~MovableSparseMatrix() = default;
    MovableSparseMatrix& operator=(const MovableSparseMatrix& other) {
        SparseMatrix::operator=(other);
        return *this;
    }
    MovableSparseMatrix& operator=(MovableSparseMatrix&& other) noexcept {
        swap(other);
        return *this;
    }
    MovableSparseMatrix& operator=(SparseMatrix&& other) noexcept {
        swap(other);
        return *this;
    }
    template <class Other>
    MovableSparseMatrix& operator=(const Eigen::SparseMatrixBase<Other>& other) {
        SparseMatrix::operator=(other.derived());
        return *this;
    }
};

/// One (row, col, value) entry for assembly.
using Triplet = Eigen::Triplet<double, int>;

} // namespace mlc
