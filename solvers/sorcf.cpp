// SPDX-License-Identifier: MIT
// SSOR with the generalized diagonal D* (Alart & Lebon 1995, sect. 4.2) and SORCF.
#include "solvers/sorcf.hpp"

#include "core/check.hpp"
#include "smoothers/matrix_checks.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlc::solvers {

void SorcfParams::validate() const {
    MLC_CHECK(omega > 0.0 && omega < 2.0, "SorcfParams::omega must be in (0, 2), found " << omega);
    MLC_CHECK(zero_tol >= 0.0 && zero_tol < 1.0,
              "SorcfParams::zero_tol must be in [0, 1), found " << zero_tol);
}

std::ostream& operator<<(std::ostream& os, const SorcfParams& p) {
    return os << "SorcfParams{omega=" << p.omega << ", block=" << (p.block ? 1 : 0)
              << ", zero_tol=" << p.zero_tol << "}";
}

GeneralizedSSOR::GeneralizedSSOR(SorcfParams params, std::vector<Index> block_starts)
    : params_(params), starts_(std::move(block_starts)) {
    params_.validate();
    MLC_CHECK(!params_.block || !starts_.empty(),
              "GeneralizedSSOR: block mode needs the block starts (vertex groups of the unknowns)");
}

void GeneralizedSSOR::setup(const SparseMatrix& A) {
    smoothers::check_setup_matrix(A, "GeneralizedSSOR::setup");
    A_ = &A;
    n_ = A.rows();
    y_.resize(n_);
    const double w2 = params_.omega * params_.omega;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    auto entry = [&](Index i, Index j) {
        const int* b = inner + outer[i];
        const int* e = inner + outer[i + 1];
        const int* it = std::lower_bound(b, e, static_cast<int>(j));
        return (it != e && *it == j) ? val[it - inner] : 0.0;
    };
    if (!params_.block) {
        dstar_.resize(n_);
        n_generated_ = 0;
        for (Index i = 0; i < n_; ++i) {
            const double aii = entry(i, i);
            if (std::abs(aii) > params_.zero_tol * smoothers::row_max_abs(A, i)) {
                dstar_[i] = aii;
                continue;
            }
            // Eqs. 29 and 33 generalized: the D*_ii that gives (P_omega)_ii = 0.
            double s = 0.0;
            for (int p = outer[i]; p < outer[i + 1] && inner[p] < i; ++p)
                s += val[p] * entry(inner[p], i) / dstar_[inner[p]];
            dstar_[i] = -w2 * s;
            ++n_generated_;
            if (!(std::abs(dstar_[i]) > 0.0) || !std::isfinite(dstar_[i])) {
                std::ostringstream os;
                os << "GeneralizedSSOR::setup: row " << i
                   << " has a zero diagonal and no earlier coupling A_ik A_ki to generate D*_ii "
                      "from; order each multiplier after the displacements it couples to";
                throw SolverBreakdown(os.str());
            }
        }
        return;
    }
    // Block mode.
    std::vector<Index> s = starts_;
    MLC_CHECK(s.front() == 0, "GeneralizedSSOR::setup: block starts must begin at 0");
    if (s.back() != n_) s.push_back(n_);
    for (size_t k = 1; k < s.size(); ++k)
        MLC_CHECK(s[k] > s[k - 1] && s[k] <= n_,
                  "GeneralizedSSOR::setup: block starts must increase within [0, "
                      << n_ << "], found " << s[k - 1] << " then " << s[k]);
    starts_ = s;
    const auto nb = static_cast<Index>(starts_.size()) - 1;
    block_.resize(static_cast<size_t>(n_));
    offset_.assign(1, 0);
    for (Index b = 0; b < nb; ++b) {
        const Index m = starts_[static_cast<size_t>(b) + 1] - starts_[static_cast<size_t>(b)];
        MLC_CHECK(m <= 16, "GeneralizedSSOR::setup: block " << b << " has " << m
                                                            << " rows, at most 16 are supported");
        for (Index i = starts_[static_cast<size_t>(b)]; i < starts_[static_cast<size_t>(b) + 1];
             ++i)
            block_[static_cast<size_t>(i)] = b;
        offset_.push_back(offset_.back() + m * m);
    }
    dblk_.assign(static_cast<size_t>(offset_.back()), 0.0);
    dinv_.assign(static_cast<size_t>(offset_.back()), 0.0);
    for (Index b = 0; b < nb; ++b) {
        const Index i0 = starts_[static_cast<size_t>(b)];
        const Index m = starts_[static_cast<size_t>(b) + 1] - i0;
        Eigen::MatrixXd D(m, m);
        for (Index a = 0; a < m; ++a)
            for (Index c = 0; c < m; ++c)
                D(a, c) = entry(i0 + a, i0 + c);
        Eigen::FullPivLU<Eigen::MatrixXd> lu(D);
        lu.setThreshold(params_.zero_tol);
        if (!lu.isInvertible()) {
            std::ostringstream os;
            os << "GeneralizedSSOR::setup: diagonal block " << b << " (rows " << i0 << " to "
               << i0 + m - 1 << ") is singular; group each multiplier with its vertex";
            throw SolverBreakdown(os.str());
        }
        const Eigen::MatrixXd Di = lu.inverse();
        const auto off = static_cast<size_t>(offset_[static_cast<size_t>(b)]);
        for (Index a = 0; a < m; ++a)
            for (Index c = 0; c < m; ++c) {
                dblk_[off + static_cast<size_t>(a * m + c)] = D(a, c);
                dinv_[off + static_cast<size_t>(a * m + c)] = Di(a, c);
            }
    }
}

void GeneralizedSSOR::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(A_ != nullptr, "GeneralizedSSOR::apply: call setup first");
    smoothers::check_size(r, n_, "GeneralizedSSOR::apply", "r");
    z.resize(n_);
    const SparseMatrix& A = *A_;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    const double w = params_.omega;
    const double scale = w * (2.0 - w);
    if (!params_.block) {
        // y = (D* + omega L)^{-1} r.
        for (Index i = 0; i < n_; ++i) {
            double s = r[i];
            for (int p = outer[i]; p < outer[i + 1] && inner[p] < i; ++p)
                s -= w * val[p] * y_[inner[p]];
            y_[i] = s / dstar_[i];
        }
        // z = (D* + omega U)^{-1} D* y, times omega (2 - omega).
        for (Index i = n_ - 1; i >= 0; --i) {
            double s = dstar_[i] * y_[i];
            for (int p = outer[i + 1] - 1; p >= outer[i] && inner[p] > i; --p)
                s -= w * val[p] * z[inner[p]];
            z[i] = s / dstar_[i];
        }
        z *= scale;
        return;
    }
    const auto nb = static_cast<Index>(starts_.size()) - 1;
    double t[16];
    // out = B t for a dense row-major m x m block B (m <= 4).
    auto block_multiply = [](const double* B, Index size, const double* x, double* out) {
        for (Index a = 0; a < size; ++a) {
            double acc = 0.0;
            for (Index c = 0; c < size; ++c)
                acc += B[a * size + c] * x[c];
            out[a] = acc;
        }
    };
    // Forward block sweep: y_I = D_I^{-1} (r_I - omega sum_{J < I} A_IJ y_J).
    for (Index b = 0; b < nb; ++b) {
        const Index i0 = starts_[static_cast<size_t>(b)];
        const Index m = starts_[static_cast<size_t>(b) + 1] - i0;
        for (Index a = 0; a < m; ++a) {
            const Index i = i0 + a;
            double s = r[i];
            for (int p = outer[i]; p < outer[i + 1] && inner[p] < i0; ++p)
                s -= w * val[p] * y_[inner[p]];
            t[a] = s;
        }
        block_multiply(dinv_.data() + offset_[static_cast<size_t>(b)], m, t, y_.data() + i0);
    }
    // Backward block sweep: z_I = D_I^{-1} (D_I y_I - omega sum_{J > I} A_IJ z_J).
    for (Index b = nb - 1; b >= 0; --b) {
        const Index i0 = starts_[static_cast<size_t>(b)];
        const Index i1 = starts_[static_cast<size_t>(b) + 1];
        const Index m = i1 - i0;
        const double* D = dblk_.data() + offset_[static_cast<size_t>(b)];
        for (Index a = 0; a < m; ++a) {
            const Index i = i0 + a;
            double s = 0.0;
            for (Index c = 0; c < m; ++c)
                s += D[a * m + c] * y_[i0 + c];
            for (int p = outer[i + 1] - 1; p >= outer[i] && inner[p] >= i1; --p)
                s -= w * val[p] * z[inner[p]];
            t[a] = s;
        }
        block_multiply(dinv_.data() + offset_[static_cast<size_t>(b)], m, t, z.data() + i0);
    }
    z *= scale;
}

std::string GeneralizedSSOR::name() const {
    std::ostringstream os;
    os << "gssor(omega=" << params_.omega << ",block=" << (params_.block ? 1 : 0) << ")";
    return os.str();
}

std::unique_ptr<CoarseFinePreconditioner>
make_sorcf(CoarseFineSplit split, CoarseSolve coarse_solve, const SorcfParams& params) {
    params.validate();
    MLC_CHECK(!params.block || !split.fine_block_starts.empty(),
              "make_sorcf: block=1 needs CoarseFineSplit::fine_block_starts (vertex groups of "
              "the fine set)");
    auto inner = std::make_unique<GeneralizedSSOR>(params, params.block ? split.fine_block_starts
                                                                        : std::vector<Index>{});
    return std::make_unique<CoarseFinePreconditioner>(std::move(split), std::move(coarse_solve),
                                                      std::move(inner), "sorcf");
}

} // namespace mlc::solvers
