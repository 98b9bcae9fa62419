// SPDX-License-Identifier: MIT
#include "smoothers/lattice_gs.hpp"

#include "core/check.hpp"
#include "core/parallel.hpp"
#include "core/traffic.hpp"
#include "smoothers/lattice_gs_layout.hpp"
#include "smoothers/matrix_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace mlc::smoothers {

using namespace lattice;

namespace {

// A run of deep points of one lattice row, visited `count` points from first row r in steps of
// `step` rows (+2 eastwards, -2 westwards), each neighbour `len` (the row's length) points up and
// down. Per point x += omega D^{-1} (b - sum_s S_s x_s) over the seven 2x2 blocks, written as
//   x_new = c - G x_behind,  c = x + omega D^{-1} (b - sum over the six other blocks),
// with G = omega D^{-1} S_behind: the point visited just before (behind) enters last, so the
// chain from one point to the next is one 2x2 product and a subtraction, the rest of each point
// independent of it (the sweep is latency-bound otherwise). x_behind is kept in registers.
#if defined(__SSE2__)
// Two lanes (the point's two rows): a 2x2 block B times y is diag(B) y + offdiag(B) swap(y).
inline __m128d swap(__m128d y) {
    return _mm_shuffle_pd(y, y, 1);
}
inline __m128d block(__m128d d, __m128d o, __m128d y) {
    return _mm_add_pd(_mm_mul_pd(d, y), _mm_mul_pd(o, swap(y)));
}
// The ten packed blocks of a macro's stencil (kPacked on): slots 0-6, omega D^{-1} (7), G_east
// (8), G_west (9), each as its diagonal and off-diagonal pairs.
struct PackedStencil {
    __m128d d[10], o[10];
    explicit PackedStencil(const double* S) {
        for (int q = 0; q < 10; ++q) {
            d[q] = _mm_loadu_pd(S + kPacked + 4 * q);
            o[q] = _mm_loadu_pd(S + kPacked + 4 * q + 2);
        }
    }
    __m128d times(int q, __m128d y) const { return block(d[q], o[q], y); }
};
void deep_run(const double* __restrict S, const double* __restrict b, double* x, long r, long step,
              int count, long len) {
    const long nn = 2 * len, nw = 2 * len - 2, so = -2 * (len + 1), se = -2 * len;
    const PackedStencil P(S);
    const int ahead = step > 0 ? 1 : 2, behind = step > 0 ? 9 : 8; // east or west; G_west or G_east
    __m128d p = _mm_loadu_pd(x + r - step);
    for (int k = 0; k < count; ++k, r += step) {
        const double* y = x + r;
        const __m128d y0 = _mm_loadu_pd(y);
        const __m128d t = _mm_add_pd(P.times(0, y0), P.times(ahead, _mm_loadu_pd(y + step)));
        const __m128d u =
            _mm_add_pd(P.times(3, _mm_loadu_pd(y + nn)), P.times(4, _mm_loadu_pd(y + so)));
        const __m128d v =
            _mm_add_pd(P.times(5, _mm_loadu_pd(y + se)), P.times(6, _mm_loadu_pd(y + nw)));
        const __m128d a = _mm_sub_pd(_mm_loadu_pd(b + r), _mm_add_pd(_mm_add_pd(t, u), v));
        const __m128d c = _mm_add_pd(y0, P.times(7, a));
        p = _mm_sub_pd(c, P.times(behind, p));
        _mm_storeu_pd(x + r, p);
    }
}
// y = A x on a run of deep points (as deep_run's): the seven blocks, no dependency between points.
void deep_product(const double* __restrict S, const double* __restrict x, double* __restrict y,
                  long r, long step, int count, long len) {
    const long nn = 2 * len, nw = 2 * len - 2, so = -2 * (len + 1), se = -2 * len;
    const PackedStencil P(S);
    for (int k = 0; k < count; ++k, r += step) {
        const double* z = x + r;
        const __m128d t =
            _mm_add_pd(P.times(0, _mm_loadu_pd(z)), _mm_add_pd(P.times(1, _mm_loadu_pd(z + 2)),
                                                               P.times(2, _mm_loadu_pd(z - 2))));
        const __m128d u =
            _mm_add_pd(P.times(3, _mm_loadu_pd(z + nn)), P.times(4, _mm_loadu_pd(z + so)));
        const __m128d v =
            _mm_add_pd(P.times(5, _mm_loadu_pd(z + se)), P.times(6, _mm_loadu_pd(z + nw)));
        _mm_storeu_pd(y + r, _mm_add_pd(_mm_add_pd(t, u), v));
    }
}
#else
void deep_run(const double* __restrict S, const double* __restrict b, double* x, long r, long step,
              int count, long len) {
    const long nn = 2 * len, nw = 2 * len - 2, so = -2 * (len + 1), se = -2 * len;
    const double* __restrict Sa = step > 0 ? S + 4 : S + 8;  // ahead: east or west
    const double* __restrict G = step > 0 ? S + 36 : S + 32; // behind: west or east
    const double* __restrict D = S + 28;
    double p0 = x[r - step], p1 = x[r - step + 1];
    for (int k = 0; k < count; ++k, r += step) {
        const double* y = x + r;
        const double y0 = y[0], y1 = y[1];
        const double* ya = y + step;
        const double* yn = y + nn;
        const double* ys = y + so;
        const double* ye = y + se;
        const double* yw = y + nw;
        const double t0 = (S[0] * y0 + S[1] * y1) + (Sa[0] * ya[0] + Sa[1] * ya[1]);
        const double t1 = (S[2] * y0 + S[3] * y1) + (Sa[2] * ya[0] + Sa[3] * ya[1]);
        const double u0 = (S[12] * yn[0] + S[13] * yn[1]) + (S[16] * ys[0] + S[17] * ys[1]);
        const double u1 = (S[14] * yn[0] + S[15] * yn[1]) + (S[18] * ys[0] + S[19] * ys[1]);
        const double v0 = (S[20] * ye[0] + S[21] * ye[1]) + (S[24] * yw[0] + S[25] * yw[1]);
        const double v1 = (S[22] * ye[0] + S[23] * ye[1]) + (S[26] * yw[0] + S[27] * yw[1]);
        const double a0 = b[r] - ((t0 + u0) + v0), a1 = b[r + 1] - ((t1 + u1) + v1);
        const double c0 = y0 + (D[0] * a0 + D[1] * a1), c1 = y1 + (D[2] * a0 + D[3] * a1);
        const double n0 = c0 - (G[0] * p0 + G[1] * p1), n1 = c1 - (G[2] * p0 + G[3] * p1);
        x[r] = n0;
        x[r + 1] = n1;
        p0 = n0;
        p1 = n1;
    }
}
void deep_product(const double* __restrict S, const double* __restrict x, double* __restrict y,
                  long r, long step, int count, long len) {
    const long off[kSlots] = {0, 2, -2, 2 * len, -2 * (len + 1), -2 * len, 2 * len - 2};
    for (int k = 0; k < count; ++k, r += step) {
        double a0 = 0.0, a1 = 0.0;
        for (int q = 0; q < kSlots; ++q) {
            const double* B = S + 4 * q;
            const double* z = x + r + off[q];
            a0 += B[0] * z[0] + B[1] * z[1];
            a1 += B[2] * z[0] + B[3] * z[1];
        }
        y[r] = a0;
        y[r + 1] = a1;
    }
}
#endif

// One semi-deep point (its macro's stencil, its neighbours' first rows nb[s] by slot, nb[0] its
// own): x += omega D^{-1} (b - sum_s S_s x_nb[s]) with `Sweep`, y = sum_s S_s x_nb[s] without.
template <bool Sweep>
inline void semi_point(const double* __restrict S, const int* __restrict nb, const double* b,
                       const double* x_in, double* x_out) {
    const int r = nb[0];
    double a0 = 0.0, a1 = 0.0;
    for (int q = 0; q < kSlots; ++q) {
        const double* B = S + 4 * q;
        const double* z = x_in + nb[q];
        a0 += B[0] * z[0] + B[1] * z[1];
        a1 += B[2] * z[0] + B[3] * z[1];
    }
    if constexpr (Sweep) {
        const double* D = S + 28;
        const double r0 = b[r] - a0, r1 = b[r + 1] - a1;
        x_out[r] += D[0] * r0 + D[1] * r1;
        x_out[r + 1] += D[2] * r0 + D[3] * r1;
    } else {
        x_out[r] = a0;
        x_out[r + 1] = a1;
    }
}

// fn(i) for i in [i0, i1): ascending when Forward, else descending.
template <bool Forward, class Fn> inline void in_order(int i0, int i1, Fn&& fn) {
    if constexpr (Forward) {
        for (int i = i0; i < i1; ++i)
            fn(i);
    } else {
        for (int i = i1; i-- > i0;)
            fn(i);
    }
}

} // namespace

LatticeGS::LatticeGS(std::vector<Index> block_starts, LatticeRows lattice, LatticeGSParams params)
    : block_starts_in_(std::move(block_starts)), lattice_(std::move(lattice)), params_(params) {
    MLC_CHECK(params_.omega > 0.0 && params_.omega < 2.0,
              "lattice smoother: omega must be in (0, 2), found " << params_.omega);
    MLC_CHECK(params_.parts >= 0, "lattice smoother: parts must be >= 0, found " << params_.parts);
    MLC_CHECK(lattice_.n >= 1 && lattice_.n < kLenCodes,
              "lattice smoother: n must be in [1, " << kLenCodes << "), found " << lattice_.n);
    const long np = LatticeRows::interior_points(lattice_.n);
    MLC_CHECK(np == 0 ? lattice_.first_row.empty()
                      : lattice_.first_row.size() % static_cast<size_t>(np) == 0,
              "lattice smoother: " << lattice_.first_row.size()
                                   << " lattice rows are not a whole number of macros of " << np
                                   << " interior points");
}

std::string LatticeGS::name() const {
    std::ostringstream os;
    os << "lattice-gs(omega=" << params_.omega << ",parts=" << parts() << ")";
    return os.str();
}

void LatticeGS::setup(const SparseMatrix& A) {
    check_setup_matrix(A, "lattice smoother");
    derive(A);
    load_rows(A);
}

void LatticeGS::update_values(const SparseMatrix& A) {
    if (A_ == nullptr || A.rows() != n_ || A.cols() != n_ || !same_pattern(A) ||
        !deep_rows_match(A)) {
        setup(A);
        return;
    }
    load_rows(A);
}

// A's pattern is the last setup's: the same row pointers, every row-swept entry's column at its
// position, and every deep row's columns at its lattice neighbours' rows (every row is one or
// the other, so no copy of the column indices is kept).
bool LatticeGS::same_pattern(const SparseMatrix& A) const {
    if (!A.isCompressed() || A.nonZeros() != nnz_) return false;
    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    if (!std::equal(outer_.begin(), outer_.end(), ao)) return false;
    const size_t ne = ccol_.size();
    const size_t bad = parallel::first_flagged(ne, 1 << 16, [&](size_t e0, size_t e1) {
        for (size_t e = e0; e < e1; ++e)
            if (ai[csrc_[e]] != ccol_[e]) return e;
        return e1;
    });
    if (bad != ne) return false;
    // Column pair q of rows r and r + 1 is (c, c + 1) in both (their lengths are the setup's:
    // outer_ matched).
    auto pair_at = [&](int r, int q, long c) {
        return ai[ao[r] + 2 * q] == c && ai[ao[r] + 2 * q + 1] == c + 1 &&
               ai[ao[r + 1] + 2 * q] == c && ai[ao[r + 1] + 2 * q + 1] == c + 1;
    };
    const size_t nd = deep_row_.size();
    const size_t bad_deep = parallel::first_flagged(nd, 4096, [&](size_t d0, size_t d1) {
        for (size_t d = d0; d < d1; ++d) {
            const int r = deep_row_[d];
            const long len = deep_len_[d];
            const long off[kSlots] = {0, 2, -2, 2 * len, -2 * (len + 1), -2 * len, 2 * len - 2};
            for (int q = 0; q < kSlots; ++q)
                if (!pair_at(r, q, r + off[deep_slots_[d * kSlots + static_cast<size_t>(q)]]))
                    return d;
        }
        return d1;
    });
    if (bad_deep != nd) return false;
    const size_t ns = semi_macro_.size();
    const size_t bad_semi = parallel::first_flagged(ns, 4096, [&](size_t k0, size_t k1) {
        for (size_t k = k0; k < k1; ++k) {
            const int* nbr = semi_nbr_.data() + k * kSlots;
            for (int q = 0; q < kSlots; ++q)
                if (!pair_at(nbr[0], q, nbr[semi_slots_[k * kSlots + static_cast<size_t>(q)]]))
                    return k;
        }
        return k1;
    });
    return bad_semi == ns;
}

void LatticeGS::load_rows(const SparseMatrix& A) {
    A_ = &A;
    const double* av = A.valuePtr();
    const size_t ne = ccol_.size();
    parallel::for_rows(ne, 1 << 16, [&](size_t e0, size_t e1) {
        for (size_t e = e0; e < e1; ++e)
            cval_[e] = av[csrc_[e]];
    });
    const double omega = params_.omega, tol = params_.singular_tol;
    parallel::for_rows(cb_row_.size(), 4096, [&](size_t c0, size_t c1) {
        Eigen::MatrixXd D;
        for (size_t c = c0; c < c1; ++c) {
            const int s0 = cb_row_[c];
            const int s = cb_size_[c];
            D.setZero(s, s);
            for (int k = 0; k < s; ++k) {
                const size_t cr = static_cast<size_t>(cb_crow_[c] + k);
                for (int e = crow_ptr_[cr]; e < crow_own_end_[cr]; ++e) {
                    const int col = ccol_[static_cast<size_t>(e)];
                    if (col >= s0 && col < s0 + s) D(k, col - s0) = cval_[static_cast<size_t>(e)];
                }
            }
            invert_block_unrolled(D, cb_block_[c], s0, omega, tol,
                                  BlockInverseMap(cinv_.data() + cb_inv_[c], s, s));
        }
    });
}

bool LatticeGS::deep_rows_match(const SparseMatrix& A) const {
    const int* ao = A.outerIndexPtr();
    const double* av = A.valuePtr();
    const size_t nd = deep_row_.size();
    std::vector<double> tol(stencils_.size() / kStencil);
    for (size_t m = 0; m < tol.size(); ++m) {
        double mx = 0.0;
        for (int e = 0; e < 28; ++e)
            mx = std::max(mx, std::abs(stencils_[m * kStencil + static_cast<size_t>(e)]));
        tol[m] = params_.stencil_tol * mx;
    }
    // Rows r and r + 1 hold macro m's stencil, their column pairs in the given slots.
    auto holds_stencil = [&](int r, size_t m, const std::uint8_t* slots) {
        const double* S = stencils_.data() + m * kStencil;
        const double t = tol[m];
        const double* v0 = av + ao[r];
        const double* v1 = av + ao[r + 1];
        for (int q = 0; q < kSlots; ++q) {
            const double* B = S + 4 * slots[q];
            if (!(std::abs(v0[2 * q] - B[0]) <= t && std::abs(v0[2 * q + 1] - B[1]) <= t &&
                  std::abs(v1[2 * q] - B[2]) <= t && std::abs(v1[2 * q + 1] - B[3]) <= t))
                return false;
        }
        return true;
    };
    const size_t bad = parallel::first_flagged(nd, 4096, [&](size_t d0, size_t d1) {
        for (size_t d = d0; d < d1; ++d)
            if (!holds_stencil(deep_row_[d], static_cast<size_t>(deep_macro_[d]),
                               deep_slots_.data() + d * kSlots))
                return d;
        return d1;
    });
    if (bad != nd) return false;
    const size_t ns = semi_macro_.size();
    const size_t bad_semi = parallel::first_flagged(ns, 4096, [&](size_t k0, size_t k1) {
        for (size_t k = k0; k < k1; ++k)
            if (!holds_stencil(semi_nbr_[k * kSlots], static_cast<size_t>(semi_macro_[k]),
                               semi_slots_.data() + k * kSlots))
                return k;
        return k1;
    });
    return bad_semi == ns;
}

long LatticeGS::run_step(int i0, int i1) const {
    return i1 - i0 > 1
               ? visit_row_[static_cast<size_t>(i0) + 1] - visit_row_[static_cast<size_t>(i0)]
               : 2;
}

template <bool Forward> void LatticeGS::sweep_part(int p, const double* b, double* x) const {
    const double* snap = snap_.data();
    const double* val = cval_.data();
    const int* col = ccol_.data();
    auto block = [&](int c) {
        const int s0 = cb_row_[static_cast<size_t>(c)];
        const int cr = cb_crow_[static_cast<size_t>(c)];
        const double* D = cinv_.data() + cb_inv_[static_cast<size_t>(c)];
        if (cb_twin_[static_cast<size_t>(c)]) {
            const int e0 = crow_ptr_[static_cast<size_t>(cr)];
            const int len = crow_ptr_[static_cast<size_t>(cr) + 1] - e0;
            const int oe = crow_own_end_[static_cast<size_t>(cr)];
            double a0, a1;
            twin_row_dot(col, val, len, x, e0, oe, a0, a1);
            for (int e = oe; e < e0 + len; ++e) {
                a0 += val[e] * snap[col[e]];
                a1 += val[e + len] * snap[col[e]];
            }
            const double r0 = b[s0] - a0, r1 = b[s0 + 1] - a1;
            x[s0] += D[0] * r0 + D[1] * r1;
            x[s0 + 1] += D[2] * r0 + D[3] * r1;
            return;
        }
        const int s = cb_size_[static_cast<size_t>(c)];
        double res[4];
        for (int k = 0; k < s; ++k) {
            const size_t r = static_cast<size_t>(cr + k);
            const int e0 = crow_ptr_[r], e1 = crow_ptr_[r + 1], oe = crow_own_end_[r];
            double a = row_dot(col, val, x, e0, oe);
            for (int e = oe; e < e1; ++e)
                a += val[e] * snap[col[e]];
            res[k] = b[s0 + k] - a;
        }
        for (int k = 0; k < s; ++k) {
            double d = 0.0;
            for (int l = 0; l < s; ++l)
                d += D[k * s + l] * res[l];
            x[s0 + k] += d;
        }
    };
    const int k0 = part_item_[static_cast<size_t>(p)], k1 = part_item_[static_cast<size_t>(p) + 1];
    auto item = [&](int k) {
        const int i0 = item_begin_[static_cast<size_t>(k)];
        const int i1 = item_begin_[static_cast<size_t>(k) + 1];
        const int code = visit_code_[static_cast<size_t>(i0)];
        if (code <= kSemiMax) { // semi-deep points
            in_order<Forward>(i0, i1, [&](int i) {
                const size_t e = static_cast<size_t>(visit_code_[static_cast<size_t>(i)] - kSemi);
                semi_point<true>(stencils_.data() + static_cast<size_t>(semi_macro_[e]) * kStencil,
                                 semi_nbr_.data() + e * kSlots, b, x, x);
            });
            return;
        }
        if (code < 0) { // blocks swept by their rows
            in_order<Forward>(i0, i1,
                              [&](int i) { block(-1 - visit_code_[static_cast<size_t>(i)]); });
            return;
        }
        // A run of deep points along one lattice row.
        const long step = run_step(i0, i1);
        const double* S = stencils_.data() + static_cast<size_t>(code / kLenCodes) * kStencil;
        if constexpr (Forward)
            deep_run(S, b, x, visit_row_[static_cast<size_t>(i0)], step, i1 - i0, code % kLenCodes);
        else
            deep_run(S, b, x, visit_row_[static_cast<size_t>(i1) - 1], -step, i1 - i0,
                     code % kLenCodes);
    };
    in_order<Forward>(k0, k1, item);
}

void LatticeGS::half_sweep(const double* b, double* x, bool forward) const {
    // Compulsory bytes: the row-swept blocks' values, columns, positions and inverses, the visit
    // entries, b read and x read and written.
    const double bytes =
        12.0 * static_cast<double>(ccol_.size()) + 8.0 * static_cast<double>(cinv_.size()) +
        8.0 * static_cast<double>(visit_row_.size()) + 4.0 * static_cast<double>(semi_nbr_.size()) +
        24.0 * static_cast<double>(n_);
    const traffic::Pass pass(traffic::Kind::structured, bytes);
    for (int c : interface_)
        snap_[c] = x[c];
    parallel::for_chunks(static_cast<size_t>(parts()), [&](size_t p) {
        if (forward)
            sweep_part<true>(static_cast<int>(p), b, x);
        else
            sweep_part<false>(static_cast<int>(p), b, x);
    });
}

void LatticeGS::smooth(const Vector& b, Vector& x, Sweep direction, int count) const {
    MLC_CHECK(A_ != nullptr, "lattice smoother: call setup first");
    check_size(b, n_, "LatticeGS::smooth", "b");
    check_size(x, n_, "LatticeGS::smooth", "x");
    MLC_CHECK(direction != Sweep::symmetric, "lattice smoother: sweeps are forward or backward");
    for (int s = 0; s < count; ++s)
        half_sweep(b.data(), x.data(), direction == Sweep::forward);
}

void LatticeGS::forward_from_zero(const Vector& b, Vector& x, Vector& res) const {
    parallel::set_zero(x, n_);
    smooth(b, x, Sweep::forward, 1);
    csr_residual(csr_arrays(*A_, A_->valuePtr()), b, x, res, traffic::Kind::smoother);
}

void LatticeGS::multiply(const Vector& x, Vector& y) const {
    MLC_CHECK(A_ != nullptr, "lattice smoother: call setup first");
    check_size(x, n_, "LatticeGS::multiply", "x");
    if (y.size() != n_) y.resize(n_);
    // Compulsory bytes: the row-swept rows' values and columns and row offsets, the visit
    // entries, x read and y written.
    const traffic::Pass pass(
        traffic::Kind::structured,
        12.0 * static_cast<double>(ccol_.size()) + 4.0 * static_cast<double>(crow_ptr_.size()) +
            8.0 * static_cast<double>(visit_row_.size()) +
            4.0 * static_cast<double>(semi_nbr_.size()) + 16.0 * static_cast<double>(n_));
    const double* xv = x.data();
    double* yv = y.data();
    const double* val = cval_.data();
    const int* col = ccol_.data();
    parallel::for_chunks(static_cast<size_t>(parts()), [&](size_t p) {
        for (int k = part_item_[p]; k < part_item_[p + 1]; ++k) {
            const int i0 = item_begin_[static_cast<size_t>(k)];
            const int i1 = item_begin_[static_cast<size_t>(k) + 1];
            const int code = visit_code_[static_cast<size_t>(i0)];
            if (code <= kSemiMax) {
                for (int i = i0; i < i1; ++i) {
                    const size_t s =
                        static_cast<size_t>(visit_code_[static_cast<size_t>(i)] - kSemi);
                    semi_point<false>(stencils_.data() +
                                          static_cast<size_t>(semi_macro_[s]) * kStencil,
                                      semi_nbr_.data() + s * kSlots, nullptr, xv, yv);
                }
                continue;
            }
            if (code < 0) {
                for (int i = i0; i < i1; ++i) {
                    const size_t c = static_cast<size_t>(-1 - visit_code_[static_cast<size_t>(i)]);
                    for (int q = 0; q < cb_size_[c]; ++q) {
                        const size_t cr = static_cast<size_t>(cb_crow_[c] + q);
                        yv[cb_row_[c] + q] =
                            row_dot(col, val, xv, crow_ptr_[cr], crow_ptr_[cr + 1]);
                    }
                }
                continue;
            }
            const long step = run_step(i0, i1);
            deep_product(stencils_.data() + static_cast<size_t>(code / kLenCodes) * kStencil, xv,
                         yv, visit_row_[static_cast<size_t>(i0)], step, i1 - i0, code % kLenCodes);
        }
    });
}

std::vector<Index> LatticeGS::sweep_order_blocks(int part) const {
    std::vector<Index> out;
    for (int i = part_visit_[static_cast<size_t>(part)];
         i < part_visit_[static_cast<size_t>(part) + 1]; ++i)
        out.push_back(visit_row_[static_cast<size_t>(i)]);
    return out;
}

} // namespace mlc::smoothers
