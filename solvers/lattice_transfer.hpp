// SPDX-License-Identifier: MIT
/// @file The multigrid's prolongation T and restriction R between two levels numbered by
/// lattices, applied through the lattice (mg:smoother=lattice).
///
/// When the fine level is the coarse one refined once and both number every macro triangle's
/// interior points row by row (levels::Problem::Numbering::lattice, smoothers::LatticeRows), the
/// nodal interpolation inside a macro needs no stored entries: fine point (i, j) of the fine
/// lattice (n_f = 2 n_c subdivisions) takes coarse point (i/2, j/2) when i and j are even, and
/// half of each end of the coarse lattice edge it halves otherwise ((i -+ 1)/2, j/2),
/// (i/2, (j -+ 1)/2) or ((i + 1)/2, (j - 1)/2) and ((i - 1)/2, (j + 1)/2)); R = T^T gathers,
/// into coarse point (I, J), fine point (2I, 2J) and half of its six lattice neighbours. The rows
/// of T and R that hold exactly these entries (checked entry by entry at construction) are
/// computed from the point's position; every other row (the points next to a macro edge, whose
/// parents are edge vertices, the edges and corners, contact multipliers, fixed components, a
/// macro that is not numbered as a lattice) by its stored entries. Each row is summed as
/// core/csr.hpp's row_dot sums it, so `prolongate` and `restrict_residual` equal
/// csr_multiply(T, ...) and csr_multiply(R, ...) bit for bit; they read the vectors and the
/// remaining rows, not the 12 bytes per entry of the structured ones.
#pragma once

#include "core/types.hpp"
#include "smoothers/lattice_gs.hpp"

#include <vector>

namespace mlc::solvers {

/// The multigrid's prolongation T and restriction R between two lattice-numbered levels, applied
/// through the lattice where the rows allow it; see the file comment.
class LatticeTransfer {
public:
    /// T: fine x coarse, R: coarse x fine (compressed CSR, borrowed: they must outlive this and
    /// keep their values, which are checked and partly copied here); `applies(fine, coarse)`.
    /// Throws InvalidInput otherwise.
    LatticeTransfer(const SparseMatrix& T, const SparseMatrix& R,
                    const smoothers::LatticeRows& fine, const smoothers::LatticeRows& coarse);

    /// Whether two lattices fit: fine.n == 2 coarse.n and the same number of macros.
    static bool applies(const smoothers::LatticeRows& fine, const smoothers::LatticeRows& coarse);

    /// y = T x (or y += T x with `add`; y must then have T.rows() entries): csr_multiply(T, x, y,
    /// add, Kind::transfer) bit for bit. Counts one `structured` pass.
    void prolongate(const Vector& x, Vector& y, bool add) const;
    /// y = R x: csr_multiply(R, x, y, false, Kind::transfer) bit for bit. Counts one
    /// `structured` pass.
    void restrict_residual(const Vector& x, Vector& y) const;

    /// Rows of T and of R computed from the lattice (the rest by their entries).
    Index structured_rows_T() const { return structured_t_; }
    Index structured_rows_R() const { return structured_r_; }

private:
    const SparseMatrix& T_;
    const SparseMatrix& R_;
    int nf_ = 0, nc_ = 0;
    // Macros whose T and R rows all matched: the first row of their interior on both levels.
    std::vector<Index> fine_base_, coarse_base_;
    // The rows of T or of R applied by their entries, copied together (so that they are read in
    // one stream): row k of the copy is row `row[k]` of the matrix.
    struct Rest {
        std::vector<int> row, outer, inner;
        std::vector<double> values;
        void take(const SparseMatrix& A, const std::vector<char>& done);
        template <bool Add> void apply(const double* x, double* y) const;
    };
    Rest rest_t_, rest_r_;
    Index structured_t_ = 0, structured_r_ = 0;
    double bytes_t_ = 0, bytes_r_ = 0;
};

} // namespace mlc::solvers
