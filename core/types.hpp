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
/// One (row, col, value) entry for assembly.
using Triplet = Eigen::Triplet<double, int>;

} // namespace mlc
