// SPDX-License-Identifier: MIT
// Point and block SOR / SSOR sweeps on a CSR matrix, with dense-LU inverted diagonal blocks and
// threaded hybrid parts (the block inverses: block_inverse.cpp; the transpose:
// block_sor_transpose.cpp).
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

std::string_view to_string(Kernel k) {
    return k == Kernel::unrolled ? "unrolled" : "in_order";
}

void BlockSORParams::validate() const {
    MLC_CHECK(omega > 0.0 && omega < 2.0,
              "BlockSORParams::omega must be in (0, 2), found " << omega);
    MLC_CHECK(n_sweeps >= 1, "BlockSORParams::n_sweeps must be >= 1, found " << n_sweeps);
    MLC_CHECK(singular_tol >= 0.0 && singular_tol < 1.0,
              "BlockSORParams::singular_tol must be in [0, 1), found " << singular_tol);
    MLC_CHECK(block_size >= 1, "BlockSORParams::block_size must be >= 1, found " << block_size);
    MLC_CHECK(parts >= 0, "BlockSORParams::parts must be >= 0, found " << parts);
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
    return os << ", singular_tol=" << p.singular_tol << ", parts=" << p.parts
              << ", kernel=" << to_string(p.kernel) << ", precision=" << to_string(p.precision)
              << "}";
}

Index hybrid_part_count(int requested, Index rows, Index blocks) {
    const Index want = requested > 0 ? requested : kHybridParts;
    return std::clamp<Index>(std::min(want, rows / kMinRowsPerThread), 1,
                             std::max<Index>(blocks, 1));
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
    post_ = params_.kernel == Kernel::unrolled ? 1.0 : params_.omega;
    A_ = &A;
    derive_structure();
    invert_blocks();
    round_data();
    res_.resize(n);
}

void BlockSOR::update_values(const SparseMatrix& A) {
    if (A_ == nullptr || A.rows() != starts_.back() || A.cols() != starts_.back()) {
        setup(A);
        return;
    }
    check_setup_matrix(A, "BlockSOR::update_values");
    A_ = &A;
    // A refreshed in place (as the Jacobian assembler does) keeps its parts and diagonal
    // positions; any other pattern has them derived anew.
    if (!pattern_.matches(A)) derive_structure();
    invert_blocks();
    round_data();
}

void BlockSOR::round_data() {
    if (params_.precision != Precision::float32) return;
    round_values(*A_, values32_, "BlockSOR (single precision)");
    // The inverses over the threads; the first entry without a float value is named.
    const size_t n = dinv_.size();
    dinv32_.resize(n);
    const size_t bad =
        parallel::first_flagged(n, parallel::kTouchRowsPerChunk, [&](size_t b, size_t e) {
            size_t first = e;
            for (size_t k = b; k < e; ++k) {
                dinv32_[k] = static_cast<float>(dinv_[k]);
                if (!std::isfinite(dinv32_[k]) && first == e) first = k;
            }
            return first;
        });
    MLC_CHECK(bad == n, "BlockSOR (single precision): a block inverse entry "
                            << dinv_[bad]
                            << " has no single-precision value; use precision=double");
    decltype(dinv_)().swap(dinv_); // the double inverses are not read by float32 sweeps
}

void BlockSOR::derive_structure() {
    const SparseMatrix& A = *A_;
    const Index n = A.rows();
    const Index nb = n_blocks();
    const Index P = hybrid_part_count(params_.parts, n, nb);
    part_block_.assign(1, 0);
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double per_part = static_cast<double>(A.nonZeros()) / static_cast<double>(P);
    for (Index I = 0, p = 1; I < nb && p < P; ++I)
        if (static_cast<double>(outer[starts_[static_cast<size_t>(I) + 1]]) >= per_part * p) {
            part_block_.push_back(I + 1);
            ++p;
        }
    part_block_.push_back(nb);
    // Own-part entry range of every row, and the columns read across a cut: the rows of each
    // part over the threads, each chunk listing the columns it reads across.
    own_begin_.resize(static_cast<size_t>(n));
    own_end_.resize(static_cast<size_t>(n));
    std::vector<char> across(static_cast<size_t>(n), 0);
    for (size_t p = 0; p + 1 < part_block_.size(); ++p) {
        const Index r0 = starts_[static_cast<size_t>(part_block_[p])];
        const Index r1 = starts_[static_cast<size_t>(part_block_[p + 1])];
        const parallel::RowChunks rc = parallel::row_chunks(static_cast<size_t>(r1 - r0),
                                                            static_cast<size_t>(kMinRowsPerThread));
        std::vector<std::vector<int>> read_across(rc.count);
        parallel::for_chunks(rc.count, [&](size_t c) {
            for (Index i = r0 + static_cast<Index>(rc.begin(c));
                 i < r0 + static_cast<Index>(rc.end(c)); ++i) {
                const int* b = inner + outer[i];
                const int* e = inner + outer[i + 1];
                const int* lo = std::lower_bound(b, e, static_cast<int>(r0));
                const int* hi = std::lower_bound(lo, e, static_cast<int>(r1));
                own_begin_[static_cast<size_t>(i)] = static_cast<int>(lo - inner);
                own_end_[static_cast<size_t>(i)] = static_cast<int>(hi - inner);
                read_across[c].insert(read_across[c].end(), b, lo);
                read_across[c].insert(read_across[c].end(), hi, e);
            }
        });
        for (const auto& cols : read_across)
            for (const int j : cols)
                across[static_cast<size_t>(j)] = 1;
    }
    interface_.clear();
    for (Index j = 0; j < n; ++j)
        if (across[static_cast<size_t>(j)]) interface_.push_back(static_cast<int>(j));
    parallel::set_zero(snap_, n);
    // Per block over the threads: the first entry of every row in or right of its own diagonal
    // block, and twin rows (a 2x2 block whose two rows have the same columns: a vertex of K, both
    // displacement rows couple to the same vertices; the sweep reads their columns and x once).
    diag_begin_.resize(static_cast<size_t>(n));
    twin_.assign(static_cast<size_t>(std::max<Index>(nb, 0)), 0);
    parallel::for_rows(
        static_cast<size_t>(std::max<Index>(nb, 0)), static_cast<size_t>(kMinRowsPerThread) / 2,
        [&](size_t I0, size_t I1) {
            for (size_t I = I0; I < I1; ++I) {
                const Index i0 = starts_[I], i1 = starts_[I + 1];
                for (Index i = i0; i < i1; ++i)
                    diag_begin_[static_cast<size_t>(i)] = static_cast<int>(
                        std::lower_bound(inner + outer[i], inner + outer[i + 1], i0) - inner);
                if (i1 - i0 != 2) continue;
                const int len = outer[i0 + 1] - outer[i0];
                twin_[I] =
                    outer[i0 + 2] - outer[i0 + 1] == len &&
                    std::equal(inner + outer[i0], inner + outer[i0 + 1], inner + outer[i0 + 1]);
            }
        });
    pattern_ = SparsityPattern(A);
    work_.resize(max_block_ * P);
}

std::vector<Index> BlockSOR::part_rows() const {
    std::vector<Index> rows;
    for (const Index I : part_block_)
        rows.push_back(starts_[static_cast<size_t>(I)]);
    return rows;
}

// One part's half-sweep over blocks [b0, b1) with scratch t (one block). The other parts'
// unknowns are read from snap_ (their values when the sweep began). With from_zero (in_order
// kernel only) x is zero on entry and only the already-visited own entries of each row count.
template <class Value>
void BlockSOR::sweep_part(const Value* av, const Value* dinv, const double* bp, double* xp,
                          Index b0, Index b1, bool forward, bool from_zero, double* t) const {
    const int* ao = A_->outerIndexPtr();
    const int* ai = A_->innerIndexPtr();
    const double* sp = snap_.data();
    const bool unrolled = params_.kernel == Kernel::unrolled;
    // The unrolled kernel's row: b_i - (own part) - (other parts before) - (other parts after).
    // An empty range's row_dot is +0.0 and x - (+0.0) == x, so skipping it changes no bit.
    auto unrolled_row = [&](Index i) {
        const auto r = static_cast<size_t>(i);
        const int ob = own_begin_[r], oe = own_end_[r];
        double v = bp[i] - row_dot(ai, av, xp, ob, oe);
        if (ao[i] != ob) v -= row_dot(ai, av, sp, ao[i], ob);
        if (oe != ao[i + 1]) v -= row_dot(ai, av, sp, oe, ao[i + 1]);
        return v;
    };
    for (Index step = b0; step < b1; ++step) {
        const Index blk = forward ? step : b1 - 1 - (step - b0);
        const Index s0 = starts_[blk], s1 = starts_[blk + 1], s = s1 - s0;
        if (unrolled && s == 2) {
            // A vertex's 2x2 block (most blocks), with the general path's operations in its order.
            double t0, t1;
            if (twin_[static_cast<size_t>(blk)]) {
                // Both rows in one pass over the first row's columns: the second row's values
                // are `len` entries on, and each row keeps row_dot's accumulators and order.
                const int len = ao[s0 + 1] - ao[s0];
                const int ob = own_begin_[static_cast<size_t>(s0)];
                const int oe = own_end_[static_cast<size_t>(s0)];
                double d0, d1;
                twin_row_dot(ai, av, len, xp, ob, oe, d0, d1);
                t0 = bp[s0] - d0;
                t1 = bp[s0 + 1] - d1;
                if (ao[s0] != ob) {
                    twin_row_dot(ai, av, len, sp, ao[s0], ob, d0, d1);
                    t0 -= d0;
                    t1 -= d1;
                }
                if (oe != ao[s0 + 1]) {
                    twin_row_dot(ai, av, len, sp, oe, ao[s0 + 1], d0, d1);
                    t0 -= d0;
                    t1 -= d1;
                }
            } else {
                t0 = unrolled_row(s0);
                t1 = unrolled_row(s0 + 1);
            }
            const Value* D = dinv + offset_[blk];
            double c0 = 0.0, c1 = 0.0;
            c0 += D[0] * t0;
            c0 += D[1] * t1;
            c1 += D[2] * t0;
            c1 += D[3] * t1;
            // post_ is 1 for the unrolled kernel (omega is in the inverses): 1 * c == c exactly,
            // and the multiplication would lengthen the chain from one vertex to the next.
            xp[s0] += c0;
            xp[s0 + 1] += c1;
            continue;
        }
        for (Index i = s0; i < s1; ++i) {
            const auto r = static_cast<size_t>(i);
            const int ob = own_begin_[r], oe = own_end_[r];
            if (unrolled) {
                t[i - s0] = unrolled_row(i);
                continue;
            }
            double acc = bp[i];
            if (!from_zero) {
                for (int p = ob; p < oe; ++p)
                    acc -= av[p] * xp[ai[p]];
                for (int p = ao[i]; p < ob; ++p)
                    acc -= av[p] * sp[ai[p]];
                for (int p = oe; p < ao[i + 1]; ++p)
                    acc -= av[p] * sp[ai[p]];
            } else if (forward) {
                for (int p = ob; p < diag_begin_[r]; ++p)
                    acc -= av[p] * xp[ai[p]];
            } else {
                for (int p = oe - 1; p >= ob && ai[p] >= s1; --p)
                    acc -= av[p] * xp[ai[p]];
            }
            t[i - s0] = acc;
        }
        const Value* D = dinv + offset_[blk];
        for (Index a = 0; a < s; ++a) {
            double c = 0.0;
            for (Index q = 0; q < s; ++q)
                c += D[a * s + q] * t[q];
            xp[s0 + a] += post_ * c;
        }
    }
}

void BlockSOR::half_sweep(const Vector& b, Vector& x, bool forward, bool from_zero,
                          bool count) const {
    const traffic::Pass pass(traffic::Kind::smoother,
                             count ? traffic::sweep_bytes(A_->rows(), A_->nonZeros(), n_blocks(),
                                                          inverse_entries(), value_size())
                                   : 0.0,
                             count ? 1 : 0);
    double* xp = x.data();
    double* sp = snap_.data();
    for (const int j : interface_) // empty with one part
        sp[j] = xp[j];
    const int P = parts();
    const bool zero = from_zero && params_.kernel == Kernel::in_order;
    // The parts are claimed by whichever threads of core/parallel are free: with a loaded core
    // the other thread sweeps both, and the map is the same.
    const bool single = params_.precision == Precision::float32;
    parallel::for_chunks(static_cast<size_t>(P), [&](size_t p) {
        double* t = work_.data() + static_cast<Index>(p) * max_block_;
        if (single)
            sweep_part(values32_.data(), dinv32_.data(), b.data(), xp, part_block_[p],
                       part_block_[p + 1], forward, zero, t);
        else
            sweep_part(A_->valuePtr(), dinv_.data(), b.data(), xp, part_block_[p],
                       part_block_[p + 1], forward, zero, t);
    });
}

void BlockSOR::sweep(const Vector& b, Vector& x, Sweep direction) const {
    MLC_CHECK(A_ != nullptr, "BlockSOR::sweep called before setup");
    check_size(b, A_->rows(), "BlockSOR::sweep", "b");
    check_size(x, A_->rows(), "BlockSOR::sweep", "x");
    half_sweep(b, x, direction != Sweep::backward, false);
    if (direction == Sweep::symmetric) half_sweep(b, x, false, false);
}

void BlockSOR::forward_from_zero(const Vector& b, Vector& x, Vector& res) const {
    MLC_CHECK(A_ != nullptr, "BlockSOR::forward_from_zero called before setup");
    check_size(b, A_->rows(), "BlockSOR::forward_from_zero", "b");
    const Index n = A_->rows();
    const traffic::Pass pass(traffic::Kind::smoother,
                             traffic::sweep_from_zero_bytes(n, A_->nonZeros(), n_blocks(),
                                                            inverse_entries(), value_size()),
                             2);
    const bool single = params_.precision == Precision::float32;
    if (params_.kernel == Kernel::in_order) {
        x.setZero(n);
        half_sweep(b, x, true, true, false);
        res.resize(n);
        const int* outer = A_->outerIndexPtr();
        const int* inner = A_->innerIndexPtr();
        auto residual = [&](const auto* val) {
            for (Index i = 0; i < n; ++i) {
                double acc = b[i];
                for (int p = outer[i]; p < outer[i + 1]; ++p)
                    acc -= val[p] * x[inner[p]];
                res[i] = acc;
            }
        };
        if (single)
            residual(values32_.data());
        else
            residual(A_->valuePtr());
        return;
    }
    x.resize(n);
    res.resize(n);
    if (single)
        forward_from_zero_unrolled(values32_.data(), dinv32_.data(), b.data(), x.data(),
                                   res.data());
    else
        forward_from_zero_unrolled(A_->valuePtr(), dinv_.data(), b.data(), x.data(), res.data());
}

template <class Value>
void BlockSOR::forward_from_zero_unrolled(const Value* val, const Value* dinv, const double* bp,
                                          double* xp, double* rp) const {
    const int* outer = A_->outerIndexPtr();
    const int* inner = A_->innerIndexPtr();
    const int* dbeg = diag_begin_.data();
    // Each part from zero with its own lower entries (the other parts' x count as 0, as they
    // are at the start of the sweep); then the whole residual with the final x: the diagonal
    // and upper entries, and the lower ones of other parts. One part: plain Gauss–Seidel.
    const int P = parts();
    parallel::for_chunks(static_cast<size_t>(P), [&](size_t p) {
        for (Index I = part_block_[p]; I < part_block_[p + 1]; ++I) {
            const Index s = starts_[static_cast<size_t>(I)],
                        bs = starts_[static_cast<size_t>(I) + 1] - s;
            if (twin_[static_cast<size_t>(I)]) { // both rows in one pass (see sweep_part)
                double d0, d1;
                twin_row_dot(inner, val, outer[s + 1] - outer[s], xp,
                             own_begin_[static_cast<size_t>(s)], dbeg[s], d0, d1);
                rp[s] = bp[s] - d0;
                rp[s + 1] = bp[s + 1] - d1;
            } else {
                for (Index i = s; i < s + bs; ++i)
                    rp[i] = bp[i] -
                            row_dot(inner, val, xp, own_begin_[static_cast<size_t>(i)], dbeg[i]);
            }
            const Value* d = dinv + offset_[static_cast<size_t>(I)];
            for (Index i = 0; i < bs; ++i) {
                double acc = 0.0;
                for (Index j = 0; j < bs; ++j)
                    acc += d[i * bs + j] * rp[s + j];
                xp[s + i] = acc;
            }
        }
    });
    // The blocks over the threads (each row's sums as row by row; twin rows in one pass).
    const auto nb = static_cast<size_t>(n_blocks());
    const size_t blocks_per_chunk = static_cast<size_t>(kMinRowsPerThread) / 2;
    parallel::for_rows(nb, blocks_per_chunk, [&](size_t I0, size_t I1) {
        for (size_t I = I0; I < I1; ++I) {
            const Index s = starts_[I], e = starts_[I + 1];
            if (twin_[I]) {
                const int len = outer[s + 1] - outer[s];
                double u0, u1, l0, l1;
                twin_row_dot(inner, val, len, xp, dbeg[s], outer[s + 1], u0, u1);
                twin_row_dot(inner, val, len, xp, outer[s], own_begin_[static_cast<size_t>(s)], l0,
                             l1);
                rp[s] -= u0 + l0;
                rp[s + 1] -= u1 + l1;
                continue;
            }
            for (auto i = static_cast<size_t>(s); i < static_cast<size_t>(e); ++i)
                rp[i] -= row_dot(inner, val, xp, dbeg[i], outer[i + 1]) +
                         row_dot(inner, val, xp, outer[i], own_begin_[i]);
        }
    });
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
    if (params_.parts != 1) os << ",parts=" << params_.parts;
    if (params_.kernel == Kernel::unrolled) os << ",unrolled";
    if (params_.precision == Precision::float32) os << ",single";
    os << ")";
    return os.str();
}

} // namespace mlc::smoothers
