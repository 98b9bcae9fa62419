// SPDX-License-Identifier: MIT
// Point and block SOR / SSOR sweeps on a CSR matrix, with dense-LU inverted diagonal blocks.
#include "smoothers/block_sor.hpp"

#include "core/check.hpp"
#include "smoothers/matrix_checks.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlc::smoothers {

std::string_view to_string(Sweep s) {
    switch (s) {
    case Sweep::forward:
        return "forward";
    case Sweep::backward:
        return "backward";
    case Sweep::symmetric:
        return "symmetric";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, Sweep s) {
    return os << to_string(s);
}

void BlockSORParams::validate() const {
    MLC_CHECK(omega > 0.0 && omega < 2.0,
              "BlockSORParams::omega must be in (0, 2), found " << omega);
    MLC_CHECK(n_sweeps >= 1, "BlockSORParams::n_sweeps must be >= 1, found " << n_sweeps);
    MLC_CHECK(singular_tol >= 0.0 && singular_tol < 1.0,
              "BlockSORParams::singular_tol must be in [0, 1), found " << singular_tol);
    MLC_CHECK(block_size >= 1, "BlockSORParams::block_size must be >= 1, found " << block_size);
    MLC_CHECK(block_starts.empty() || block_starts.front() == 0,
              "BlockSORParams::block_starts must start at 0, found " << block_starts.front());
    for (size_t k = 1; k < block_starts.size(); ++k)
        MLC_CHECK(block_starts[k] > block_starts[k - 1],
                  "BlockSORParams::block_starts must be strictly increasing, found "
                      << block_starts[k - 1] << " then " << block_starts[k] << " at position "
                      << k);
}

std::ostream& operator<<(std::ostream& os, const BlockSORParams& p) {
    Index largest = p.block_starts.empty() ? 1 : 0;
    for (size_t k = 1; k < p.block_starts.size(); ++k)
        largest = std::max(largest, p.block_starts[k] - p.block_starts[k - 1]);
    os << "BlockSORParams{omega=" << p.omega << ", sweep=" << p.sweep << ", n_sweeps=" << p.n_sweeps
       << ", block_size=" << p.block_size << ", block_starts=";
    if (p.block_starts.empty())
        os << "[]";
    else
        os << "[" << p.block_starts.size() << " starts, largest inner block " << largest << "]";
    return os << ", singular_tol=" << p.singular_tol << "}";
}

std::vector<Index> uniform_block_starts(Index n, Index block_size) {
    MLC_CHECK(n >= 0 && block_size >= 1,
              "uniform_block_starts: need n >= 0 and block_size >= 1, found n = "
                  << n << ", block_size = " << block_size);
    std::vector<Index> s;
    s.reserve(static_cast<size_t>(n / block_size + 1));
    for (Index i = 0; i < n; i += block_size)
        s.push_back(i);
    return s;
}

BlockSOR::BlockSOR(BlockSORParams params) : params_(std::move(params)) {
    params_.validate();
}

void BlockSOR::setup(const SparseMatrix& A) {
    check_setup_matrix(A, "BlockSOR::setup");
    const Index n = A.rows();
    params_.validate();
    if (params_.block_starts.empty()) {
        starts_ = uniform_block_starts(n, params_.block_size);
        starts_.push_back(n);
    } else {
        starts_ = params_.block_starts;
        MLC_CHECK(starts_.back() <= n, "BlockSOR::setup: block start "
                                           << starts_.back() << " is beyond the matrix size " << n
                                           << "; block_starts must match A");
        if (starts_.back() != n) starts_.push_back(n);
    }
    const Index nb = n_blocks();
    offset_.resize(static_cast<size_t>(nb) + 1);
    offset_[0] = 0;
    max_block_ = 0;
    for (Index b = 0; b < nb; ++b) {
        const Index s = starts_[b + 1] - starts_[b];
        max_block_ = std::max(max_block_, s);
        offset_[b + 1] = offset_[b] + s * s;
    }
    dinv_.assign(static_cast<size_t>(offset_[nb]), 0.0);

    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    const double* av = A.valuePtr();
    Eigen::MatrixXd block;
    for (Index b = 0; b < nb; ++b) {
        const Index s0 = starts_[b], s = starts_[b + 1] - s0;
        block.setZero(s, s);
        for (Index i = s0; i < s0 + s; ++i)
            for (int p = ao[i]; p < ao[i + 1]; ++p)
                if (ai[p] >= s0 && ai[p] < s0 + s) block(i - s0, ai[p] - s0) = av[p];
        const double scale = block.cwiseAbs().maxCoeff();
        Eigen::PartialPivLU<Eigen::MatrixXd> lu(block);
        const double min_pivot = lu.matrixLU().diagonal().cwiseAbs().minCoeff();
        if (!(min_pivot > params_.singular_tol * scale) || min_pivot == 0.0) {
            std::ostringstream os;
            if (s == 1)
                os << "BlockSOR::setup: zero or missing diagonal in row " << s0
                   << "; contact-multiplier rows have zero diagonals: use blocks that group each "
                      "contact node's multipliers with its vertex, or ILU/LU";
            else
                os << "BlockSOR::setup: singular " << s << "x" << s << " diagonal block " << b
                   << " (rows " << s0 << ".." << s0 + s - 1 << ", smallest LU pivot " << min_pivot
                   << ", largest entry " << scale
                   << "); group each contact node's multipliers with its vertex";
            MLC_CHECK(false, os.str());
        }
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> inv(
            dinv_.data() + offset_[b], s, s);
        inv = lu.inverse();
    }
    A_ = &A;
    work_.resize(max_block_);
    res_.resize(n);
}

// One half-sweep. With from_zero, x is zero on entry and only the already-visited part of each
// row contributes (the lower part for forward, the upper part for backward sweeps).
void BlockSOR::half_sweep(const Vector& b, Vector& x, bool forward, bool from_zero) const {
    const int* ao = A_->outerIndexPtr();
    const int* ai = A_->innerIndexPtr();
    const double* av = A_->valuePtr();
    const double w = params_.omega;
    double* t = work_.data();
    double* xv = x.data();
    const Index nb = n_blocks();
    for (Index k = 0; k < nb; ++k) {
        const Index blk = forward ? k : nb - 1 - k;
        const Index s0 = starts_[blk], s1 = starts_[blk + 1], s = s1 - s0;
        for (Index i = s0; i < s1; ++i) {
            double acc = b[i];
            if (!from_zero) {
                for (int p = ao[i]; p < ao[i + 1]; ++p)
                    acc -= av[p] * xv[ai[p]];
            } else if (forward) {
                for (int p = ao[i]; p < ao[i + 1] && ai[p] < s0; ++p)
                    acc -= av[p] * xv[ai[p]];
            } else {
                for (int p = ao[i + 1] - 1; p >= ao[i] && ai[p] >= s1; --p)
                    acc -= av[p] * xv[ai[p]];
            }
            t[i - s0] = acc;
        }
        const double* D = dinv_.data() + offset_[blk];
        for (Index a = 0; a < s; ++a) {
            double c = 0.0;
            for (Index q = 0; q < s; ++q)
                c += D[a * s + q] * t[q];
            xv[s0 + a] += w * c;
        }
    }
}

void BlockSOR::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(A_ != nullptr, "BlockSOR::apply called before setup");
    check_size(r, A_->rows(), "BlockSOR::apply", "r");
    z.setZero(r.size());
    const bool sym = params_.sweep == Sweep::symmetric;
    const bool first_forward = params_.sweep != Sweep::backward;
    for (int k = 0; k < params_.n_sweeps; ++k) {
        half_sweep(r, z, first_forward, k == 0);
        if (sym) half_sweep(r, z, false, false);
    }
}

void BlockSOR::smooth(const Vector& b, Vector& x) const {
    MLC_CHECK(A_ != nullptr, "BlockSOR::smooth called before setup");
    check_size(b, A_->rows(), "BlockSOR::smooth", "b");
    check_size(x, A_->rows(), "BlockSOR::smooth", "x");
    const bool sym = params_.sweep == Sweep::symmetric;
    const bool first_forward = params_.sweep != Sweep::backward;
    for (int k = 0; k < params_.n_sweeps; ++k) {
        half_sweep(b, x, first_forward, false);
        if (sym) half_sweep(b, x, false, false);
    }
}

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
            t[a] = params_.omega * c;
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
            t[a] = params_.omega * c;
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

std::string BlockSOR::name() const {
    std::ostringstream os;
    if (params_.sweep == Sweep::symmetric)
        os << "ssor";
    else if (params_.sweep == Sweep::backward)
        os << "backward-sor";
    else
        os << "sor";
    os << "(omega=" << params_.omega;
    if (params_.n_sweeps > 1) os << ",sweeps=" << params_.n_sweeps;
    if (!params_.block_starts.empty())
        os << ",blocks=var";
    else if (params_.block_size > 1)
        os << ",block=" << params_.block_size;
    os << ")";
    return os.str();
}

} // namespace mlc::smoothers
