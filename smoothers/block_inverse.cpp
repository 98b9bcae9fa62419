// SPDX-License-Identifier: MIT
// The inverted diagonal blocks of BlockSOR (and of the lattice smoother's row-swept blocks): the
// kernels' unrolled fast paths and the equilibrated fallback for the blocks they reject.
#include "smoothers/block_sor.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "core/parallel.hpp"
#include "smoothers/matrix_checks.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlc::smoothers {

namespace {

// 2^round(log2(1/m)) for m > 0: a scaling factor that is exact in floating point.
double inverse_power_of_two(double m) {
    int e = 0;
    std::frexp(m, &e); // m = f 2^e, f in [0.5, 1)
    return std::ldexp(1.0, 1 - e);
}

void print_block(std::ostream& os, const Eigen::MatrixXd& D) {
    const Eigen::IOFormat f(6, 0, ", ", "; ", "", "", "[", "]");
    os << D.format(f);
}

} // namespace

// The fallback inverse of a diagonal block that the kernel's fast path rejected. The fast paths
// test pivots against the largest entry of the block, but a vertex + multiplier block mixes
// displacement rows of size E (times the mesh's scale) with multiplier rows of size 1 and 1/r:
// a stick block [[K, I], [I, 0]] has LU pivots of about |K| and 1/|K| (their product is det =
// 1), a gap block [[K, 0], [0, -I/r]] has |K| and 1/r, and with large E/r or nu near 1/2 the
// small pivot falls below singular_tol times the large one although the block is perfectly
// invertible. So the block is equilibrated first, D_s = R D C with R, C diagonal powers of two
// (exact; Ruiz's iteration: rows and columns scaled by 1/sqrt of their largest entry until all
// are within a factor 2 of 1), D_s is inverted by full-pivoting LU with the threshold
// singular_tol relative to its largest pivot, and D^{-1} = C D_s^{-1} R. A zero row or column of
// the block is a blocking that does not suit A (mlc::InvalidInput, as a zero point diagonal);
// an equilibrated block that is still singular is a numerical breakdown (mlc::SolverBreakdown,
// with the block printed).
void robust_block_inverse(const Eigen::MatrixXd& D, Index b, Index s0, double singular_tol,
                          BlockInverseMap inv) {
    const Index s = D.rows();
    // An unknown whose row and column are both zero in the block is decoupled from the others
    // (e.g. the tangential multiplier of a stuck node whose tangential displacement is
    // prescribed: its equation and its column vanish from the Jacobian, or, node on facet, keep
    // only the couplings to the target vertices, in other blocks). Its correction from its own
    // block is zero (the pseudo-inverse), and the rest of the block is inverted without it.
    // Only in a block of several unknowns (a point block's zero diagonal stays the error below);
    // a zero row with a nonzero column (or the reverse) is a blocking that does not suit A.
    auto decoupled = [&](Index i) {
        return s > 1 && D.row(i).cwiseAbs().maxCoeff() == 0.0 &&
               D.col(i).cwiseAbs().maxCoeff() == 0.0;
    };
    std::vector<Index> keep;
    for (Index i = 0; i < s; ++i)
        if (!decoupled(i)) keep.push_back(i);
    if (static_cast<Index>(keep.size()) < s) {
        inv.setZero();
        const Index k = static_cast<Index>(keep.size());
        if (k == 0) return;
        Eigen::MatrixXd Dk(k, k);
        for (Index i = 0; i < k; ++i)
            for (Index j = 0; j < k; ++j)
                Dk(i, j) = D(keep[static_cast<size_t>(i)], keep[static_cast<size_t>(j)]);
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Ik(k, k);
        robust_block_inverse(Dk, b, s0, singular_tol, BlockInverseMap(Ik.data(), k, k));
        for (Index i = 0; i < k; ++i)
            for (Index j = 0; j < k; ++j)
                inv(keep[static_cast<size_t>(i)], keep[static_cast<size_t>(j)]) = Ik(i, j);
        return;
    }
    for (Index i = 0; i < s; ++i) {
        if (D.row(i).cwiseAbs().maxCoeff() > 0.0 && D.col(i).cwiseAbs().maxCoeff() > 0.0) continue;
        std::ostringstream os;
        if (s == 1)
            os << "BlockSOR::setup: zero or missing diagonal in row " << s0
               << "; contact-multiplier rows have zero diagonals: use blocks that group each "
                  "contact node's multipliers with its vertex, or ILU/LU";
        else
            os << "BlockSOR::setup: singular " << s << "x" << s << " diagonal block " << b
               << " (rows " << s0 << ".." << s0 + s - 1 << "): its "
               << (D.row(i).cwiseAbs().maxCoeff() > 0.0 ? "column " : "row ") << i
               << " is zero; group each contact node's multipliers with its vertex";
        MLC_CHECK(false, os.str());
    }
    Eigen::VectorXd r = Eigen::VectorXd::Ones(s), c = Eigen::VectorXd::Ones(s);
    Eigen::MatrixXd Ds = D;
    for (int it = 0; it < 20; ++it) {
        bool balanced = true;
        for (Index i = 0; i < s; ++i) {
            const double m = Ds.row(i).cwiseAbs().maxCoeff();
            if (m < 0.5 || m > 2.0) balanced = false;
            const double f = inverse_power_of_two(std::sqrt(m));
            Ds.row(i) *= f;
            r[i] *= f;
        }
        for (Index j = 0; j < s; ++j) {
            const double m = Ds.col(j).cwiseAbs().maxCoeff();
            if (m < 0.5 || m > 2.0) balanced = false;
            const double f = inverse_power_of_two(std::sqrt(m));
            Ds.col(j) *= f;
            c[j] *= f;
        }
        if (balanced) break;
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Ds);
    lu.setThreshold(singular_tol);
    if (!lu.isInvertible()) {
        std::ostringstream os;
        os << "BlockSOR::setup: diagonal block " << b << " (rows " << s0 << ".." << s0 + s - 1
           << ") is singular even after equilibration (rank " << lu.rank() << " of " << s
           << " at relative pivot threshold " << singular_tol << "); block ";
        print_block(os, D);
        os << "; the Jacobian is singular at this node: check its supports and contact "
              "statuses, or solve with --linear schur/lu";
        throw SolverBreakdown(os.str());
    }
    inv = c.asDiagonal() * lu.inverse() * r.asDiagonal();
}

void BlockSOR::robust_inverse(const Eigen::MatrixXd& D, Index b, Index s0, InverseMap inv) const {
    robust_block_inverse(D, b, s0, params_.singular_tol, inv);
}

void invert_block_unrolled(const Eigen::MatrixXd& block, Index b, Index s0, double omega,
                           double tol, BlockInverseMap inv) {
    const Index s = block.rows();
    if (s == 2) {
        // Closed form (the common vertex block without multipliers).
        const double det = block(0, 0) * block(1, 1) - block(0, 1) * block(1, 0);
        const double dscale =
            std::abs(block(0, 0) * block(1, 1)) + std::abs(block(0, 1) * block(1, 0));
        if (!(dscale > 0.0 && std::abs(det) > tol * dscale)) {
            robust_block_inverse(block, b, s0, tol, inv);
            inv *= omega;
            return;
        }
        const double f = omega / det;
        inv(0, 0) = f * block(1, 1);
        inv(0, 1) = -f * block(0, 1);
        inv(1, 0) = -f * block(1, 0);
        inv(1, 1) = f * block(0, 0);
        return;
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(block);
    lu.setThreshold(tol);
    if (!lu.isInvertible()) {
        robust_block_inverse(block, b, s0, tol, inv);
        inv *= omega;
        return;
    }
    inv = omega * lu.inverse();
}

void BlockSOR::invert_blocks() {
    const int* ao = A_->outerIndexPtr();
    const int* ai = A_->innerIndexPtr();
    const double* av = A_->valuePtr();
    const double omega = params_.omega;
    const double tol = params_.singular_tol;
    dinv_.resize(static_cast<size_t>(inverse_entries()));
    // The blocks over the threads: each block's inverse is its own (the same arithmetic whichever
    // thread forms it). At level 7 of the square that is 4.2 million blocks per Newton step.
    parallel::for_rows(static_cast<size_t>(n_blocks()), kInvertBlocksPerChunk,
                       [&](size_t b_begin, size_t b_end) {
                           invert_block_range(static_cast<Index>(b_begin),
                                              static_cast<Index>(b_end), ao, ai, av, omega, tol);
                       });
}

void BlockSOR::invert_block_range(Index b_begin, Index b_end, const int* ao, const int* ai,
                                  const double* av, double omega, double tol) {
    Eigen::MatrixXd block;
    const bool unrolled = params_.kernel == Kernel::unrolled;
    for (Index b = b_begin; b < b_end; ++b) {
        const Index s0 = starts_[b], s = starts_[b + 1] - s0;
        if (unrolled && s == 2) {
            // The common vertex block in closed form, read straight from the rows (the same
            // arithmetic as the 2x2 case below; a block it rejects takes that path).
            double a[4] = {0.0, 0.0, 0.0, 0.0};
            for (Index r = 0; r < 2; ++r)
                for (int p = diag_begin_[static_cast<size_t>(s0 + r)];
                     p < ao[s0 + r + 1] && ai[p] < s0 + 2; ++p)
                    a[2 * r + (ai[p] - s0)] = av[p];
            const double det = a[0] * a[3] - a[1] * a[2];
            const double dscale = std::abs(a[0] * a[3]) + std::abs(a[1] * a[2]);
            if (dscale > 0.0 && std::abs(det) > tol * dscale) {
                double* out = dinv_.data() + offset_[b];
                const double f = omega / det;
                out[0] = f * a[3];
                out[1] = -f * a[1];
                out[2] = -f * a[2];
                out[3] = f * a[0];
                continue;
            }
        }
        block.setZero(s, s);
        // A row's entries in its block start at diag_begin_ (columns are sorted): the block is
        // read without the rest of the row.
        for (Index i = s0; i < s0 + s; ++i)
            for (int p = diag_begin_[static_cast<size_t>(i)]; p < ao[i + 1] && ai[p] < s0 + s; ++p)
                block(i - s0, ai[p] - s0) = av[p];
        double* out = dinv_.data() + offset_[b];
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> inv(
            out, s, s);
        if (params_.kernel == Kernel::in_order) {
            const double scale = block.cwiseAbs().maxCoeff();
            Eigen::PartialPivLU<Eigen::MatrixXd> lu(block);
            const double min_pivot = lu.matrixLU().diagonal().cwiseAbs().minCoeff();
            if (min_pivot > tol * scale && min_pivot != 0.0) {
                inv = lu.inverse();
                continue;
            }
            robust_inverse(block, b, s0, inv);
            continue;
        }
        invert_block_unrolled(block, b, s0, omega, tol, inv);
    }
}

} // namespace mlc::smoothers
