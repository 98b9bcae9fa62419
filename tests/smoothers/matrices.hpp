// SPDX-License-Identifier: MIT
/// @file Small test matrices for the smoother and solver tests: Laplacians, a non-symmetric
/// convection-diffusion matrix and an interleaved contact saddle-point Jacobian; the explicit
/// matrix of a preconditioner.
#pragma once

#include "core/linear_operator.hpp"
#include "core/types.hpp"

#include <Eigen/Dense>

#include <vector>

namespace mlc::testmat {

/// The n x n matrix of a preconditioner (or of its transpose), column j = P e_j.
inline Eigen::MatrixXd probe(const Preconditioner& P, Index n, bool transpose = false) {
    Eigen::MatrixXd C(n, n);
    for (Index j = 0; j < n; ++j) {
        Vector z;
        if (transpose)
            P.apply_transpose(Vector::Unit(n, j), z);
        else
            P.apply(Vector::Unit(n, j), z);
        C.col(j) = z;
    }
    return C;
}

/// Builds a compressed CSR matrix from triplets (duplicates summed).
inline SparseMatrix from_triplets(Index n, const std::vector<Triplet>& t) {
    SparseMatrix A(n, n);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
}

/// tridiag(-1, 2, -1) of size n.
inline SparseMatrix laplace_1d(Index n) {
    std::vector<Triplet> t;
    for (int i = 0; i < n; ++i) {
        t.emplace_back(i, i, 2.0);
        if (i > 0) t.emplace_back(i, i - 1, -1.0);
        if (i + 1 < n) t.emplace_back(i, i + 1, -1.0);
    }
    return from_triplets(n, t);
}

/// 5-point Laplacian on an m x m grid with Dirichlet boundary, n = m^2, bandwidth m.
/// With `c != 0`, central differences of c (d/dx + d/dy) u are added (h = 1): the off-diagonal
/// entries become -1 -+ c/2, a non-symmetric convection-diffusion matrix (cell Peclet c/2).
inline SparseMatrix laplace_2d(int m, double c = 0.0) {
    std::vector<Triplet> t;
    auto id = [m](int i, int j) { return i + m * j; };
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) {
            const int r = id(i, j);
            t.emplace_back(r, r, 4.0);
            if (i > 0) t.emplace_back(r, id(i - 1, j), -1.0 - c / 2);
            if (i + 1 < m) t.emplace_back(r, id(i + 1, j), -1.0 + c / 2);
            if (j > 0) t.emplace_back(r, id(i, j - 1), -1.0 - c / 2);
            if (j + 1 < m) t.emplace_back(r, id(i, j + 1), -1.0 + c / 2);
        }
    return from_triplets(static_cast<Index>(m) * m, t);
}

/// Non-symmetric convection-diffusion test matrix (m = 6, c = 1.5).
inline SparseMatrix convection_diffusion() {
    return laplace_2d(6, 1.5);
}

/// A contact-like saddle-point Jacobian, interleaved by node: a chain of `n_nodes` vertices
/// with two displacement unknowns (u_x, u_y) each, elastic stiffness K = T (x) K0 (T tridiagonal
/// SPD, K0 a 2x2 SPD block), and on every second vertex a node-on-rigid contact element with
/// multipliers (lambda_t, lambda_n) stored right after the vertex. The element tangent is
/// formulation.md's [[r M, M], [M, (1/r)(M - I)]], with statuses cycling through stick (M = I),
/// forward slip (M = [[0, -mu], [0, 1]]), backward slip (M = [[0, mu], [0, 1]]) and gap (M = 0):
/// zero diagonals on stick multiplier rows and on slip normal rows, non-symmetric in slip.
/// `vertex_starts` (optional) receives the first unknown of each vertex group.
inline SparseMatrix contact_saddle(int n_nodes, std::vector<Index>* vertex_starts = nullptr) {
    const double r = 2.0, mu = 0.3;
    Eigen::Matrix2d K0;
    K0 << 2.0, 0.5, 0.5, 1.5;
    std::vector<int> first(n_nodes);
    std::vector<int> status(n_nodes, -1);
    int n = 0, c = 0;
    for (int v = 0; v < n_nodes; ++v) {
        first[v] = n;
        n += 2;
        if (v % 2 == 1) {
            status[v] = c++ % 4;
            n += 2;
        }
    }
    if (vertex_starts) vertex_starts->assign(first.begin(), first.end());
    std::vector<Triplet> t;
    auto add_block = [&](int r0, int c0, const Eigen::Matrix2d& B) {
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b)
                if (B(a, b) != 0.0) t.emplace_back(r0 + a, c0 + b, B(a, b));
    };
    for (int v = 0; v < n_nodes; ++v) {
        add_block(first[v], first[v], 2.5 * K0);
        if (v > 0) add_block(first[v], first[v - 1], -1.0 * K0);
        if (v + 1 < n_nodes) add_block(first[v], first[v + 1], -1.0 * K0);
        if (status[v] < 0) continue;
        Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
        if (status[v] == 0) M = Eigen::Matrix2d::Identity();
        if (status[v] == 1) M << 0.0, -mu, 0.0, 1.0;
        if (status[v] == 2) M << 0.0, mu, 0.0, 1.0;
        const int u = first[v], l = first[v] + 2;
        add_block(u, u, r * M);
        add_block(u, l, M);
        add_block(l, u, M);
        Eigen::Matrix2d MM = (M - Eigen::Matrix2d::Identity()) / r;
        add_block(l, l, MM);
        // Keep the (possibly zero) multiplier diagonal stored, as an assembled Jacobian does.
        t.emplace_back(l, l, 0.0);
        t.emplace_back(l + 1, l + 1, 0.0);
    }
    return from_triplets(n, t);
}

/// Dense copy.
inline Eigen::MatrixXd dense(const SparseMatrix& A) {
    return Eigen::MatrixXd(A);
}

/// Half bandwidth max |i - j| over the stored entries.
inline Index bandwidth(const SparseMatrix& A) {
    Index w = 0;
    for (Index i = 0; i < A.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(A, i); it; ++it)
            w = std::max<Index>(w, std::abs(it.col() - it.row()));
    return w;
}

/// A deterministic "random" vector with entries in [-1, 1].
inline Vector pseudo_random(Index n, unsigned seed = 1) {
    Vector v(n);
    unsigned s = seed * 2654435761u + 12345u;
    for (Index i = 0; i < n; ++i) {
        s = s * 1664525u + 1013904223u;
        v[i] = static_cast<double>(s >> 8) / static_cast<double>(1u << 24) * 2.0 - 1.0;
    }
    return v;
}

} // namespace mlc::testmat
