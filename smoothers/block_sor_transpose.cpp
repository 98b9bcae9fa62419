// SPDX-License-Identifier: MIT
// BlockSOR's transpose: the half-sweeps' triangular solves with A^T, for the adjoint of the
// smoother (apply_transpose).
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

// (D/omega + L)^T t = w: blocks in reverse; each solved block scatters A_IJ^T t_I into w_J, J < I.
void BlockSOR::solve_lower_transpose(Vector& wv) const {
    const int* ao = A_->outerIndexPtr();
    const int* ai = A_->innerIndexPtr();
    const double* av = A_->valuePtr();
    double* t = work_.data();
    double* w = wv.data();
    for (Index blk = n_blocks() - 1; blk >= 0; --blk) {
        const Index s0 = starts_[blk], s = starts_[blk + 1] - s0;
        const double* D = dinv_.data() + offset_[blk];
        for (Index a = 0; a < s; ++a) {
            double c = 0.0;
            for (Index q = 0; q < s; ++q)
                c += D[q * s + a] * w[s0 + q];
            t[a] = post_ * c;
        }
        for (Index a = 0; a < s; ++a) {
            const Index i = s0 + a;
            w[i] = t[a];
            for (int p = ao[i]; p < ao[i + 1] && ai[p] < s0; ++p)
                w[ai[p]] -= av[p] * t[a];
        }
    }
}

// (D/omega + U)^T t = w: blocks in order; each solved block scatters into w_J, J > I.
void BlockSOR::solve_upper_transpose(Vector& wv) const {
    const int* ao = A_->outerIndexPtr();
    const int* ai = A_->innerIndexPtr();
    const double* av = A_->valuePtr();
    double* t = work_.data();
    double* w = wv.data();
    for (Index blk = 0; blk < n_blocks(); ++blk) {
        const Index s0 = starts_[blk], s1 = starts_[blk + 1], s = s1 - s0;
        const double* D = dinv_.data() + offset_[blk];
        for (Index a = 0; a < s; ++a) {
            double c = 0.0;
            for (Index q = 0; q < s; ++q)
                c += D[q * s + a] * w[s0 + q];
            t[a] = post_ * c;
        }
        for (Index a = 0; a < s; ++a) {
            const Index i = s0 + a;
            w[i] = t[a];
            for (int p = ao[i + 1] - 1; p >= ao[i] && ai[p] >= s1; --p)
                w[ai[p]] -= av[p] * t[a];
        }
    }
}

// The transpose of a product of half-sweeps z <- z + M_h^{-1} (r - A z) is the same product in
// reverse order with A^T and M_h^{-T}.
void BlockSOR::apply_transpose(const Vector& r, Vector& z) const {
    MLC_CHECK(A_ != nullptr, "BlockSOR::apply_transpose called before setup");
    MLC_CHECK(parts() == 1, "BlockSOR::apply_transpose: the hybrid sweep with "
                                << parts() << " parts has no transpose here; use parts = 1");
    MLC_CHECK(params_.precision == Precision::float64,
              "BlockSOR::apply_transpose: not available with single-precision data; use "
              "precision=double");
    check_size(r, A_->rows(), "BlockSOR::apply_transpose", "r");
    z.setZero(r.size());
    const bool sym = params_.sweep == Sweep::symmetric;
    // Halves of one sweep in reverse: symmetric = [forward, backward] -> backward first.
    const bool last_forward = params_.sweep == Sweep::forward;
    bool first = true;
    for (int k = 0; k < params_.n_sweeps; ++k) {
        for (int h = 0; h < (sym ? 2 : 1); ++h) {
            const bool fwd = sym ? (h == 1) : last_forward;
            res_ = r;
            if (!first) res_.noalias() -= A_->transpose() * z;
            first = false;
            if (fwd)
                solve_lower_transpose(res_);
            else
                solve_upper_transpose(res_);
            z += res_;
        }
    }
}

} // namespace mlc::smoothers
