// SPDX-License-Identifier: MIT
// T and R between two lattice-numbered levels through the lattice (solvers/lattice_transfer.hpp).
#include "solvers/lattice_transfer.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/parallel.hpp"
#include "core/traffic.hpp"

#include <algorithm>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace mlc::solvers {

namespace {

// Index of interior point (i, j) of a lattice of n subdivisions.
inline Index point(int n, int i, int j) {
    return smoothers::LatticeRows::point_index(n, i, j);
}

// Whether row r of A holds exactly `count` entries at columns cols[0..count) (increasing) with
// values vals[0..count).
bool row_is(const SparseMatrix& A, Index r, int count, const Index* cols, const double* vals) {
    const int* o = A.outerIndexPtr();
    const int b = o[r];
    if (o[r + 1] - b != count) return false;
    for (int k = 0; k < count; ++k)
        if (A.innerIndexPtr()[b + k] != cols[k] || A.valuePtr()[b + k] != vals[k]) return false;
    return true;
}

// The coarse points a structured fine point (i, j) takes its value from: one (i, j even) or the
// two ends of the coarse edge it halves; returns their count.
int parents(int i, int j, int (&I)[2], int (&J)[2]) {
    if (i % 2 == 0 && j % 2 == 0) {
        I[0] = i / 2;
        J[0] = j / 2;
        return 1;
    }
    if (j % 2 == 0) { // on a coarse row: ((i - 1)/2, j/2), ((i + 1)/2, j/2)
        I[0] = (i - 1) / 2, J[0] = j / 2, I[1] = (i + 1) / 2, J[1] = j / 2;
    } else if (i % 2 == 0) { // on a coarse column
        I[0] = i / 2, J[0] = (j - 1) / 2, I[1] = i / 2, J[1] = (j + 1) / 2;
    } else { // on a coarse diagonal
        I[0] = (i + 1) / 2, J[0] = (j - 1) / 2, I[1] = (i - 1) / 2, J[1] = (j + 1) / 2;
    }
    return 2;
}

// The structured fine points of a lattice of nf subdivisions: rows j = 2 .. nf - 3, in row j the
// points i = 2 .. nf - 2 - j; their parents are interior points of the coarse lattice.
template <class Fn> void for_structured_fine(int nf, Fn&& fn) {
    for (int j = 2; j <= nf - 3; ++j)
        for (int i = 2; i <= nf - 2 - j; ++i)
            fn(i, j);
}

// The two components of a point as one pair of lanes (SSE2, or two doubles elsewhere: the same
// operations lane by lane, the same bits).
#if defined(__SSE2__)
using Pair = __m128d;
inline Pair ld(const double* p) {
    return _mm_loadu_pd(p);
}
inline void st(double* p, Pair v) {
    _mm_storeu_pd(p, v);
}
inline Pair add(Pair a, Pair b) {
    return _mm_add_pd(a, b);
}
inline Pair mul(double v, Pair a) {
    return _mm_mul_pd(_mm_set1_pd(v), a);
}
inline Pair zero() {
    return _mm_setzero_pd();
}
#else
struct Pair {
    double a, b;
};
inline Pair ld(const double* p) {
    return {p[0], p[1]};
}
inline void st(double* p, Pair v) {
    p[0] = v.a;
    p[1] = v.b;
}
inline Pair add(Pair x, Pair y) {
    return {x.a + y.a, x.b + y.b};
}
inline Pair mul(double v, Pair x) {
    return {v * x.a, v * x.b};
}
inline Pair zero() {
    return {0.0, 0.0};
}
#endif

// Each lane summed as row_dot (core/csr.hpp) sums the row: a0 = 0 + v x0 (+ v x1), then
// (a0 + a1) + (a2 + a3) with a1 = a2 = a3 = 0, which leaves a0 as it is (a0 = 0 + p is never
// -0.0), so it is left out.
inline Pair dot1(Pair x) {
    return add(zero(), mul(1.0, x));
}
inline Pair dot2(Pair x0, Pair x1) {
    return add(add(zero(), mul(0.5, x0)), mul(0.5, x1));
}
template <bool Add> inline void put(double* y, Pair v) {
    st(y, Add ? add(ld(y), v) : v);
}

// T on the structured points of one macro: fine interior from row f, coarse from row c.
template <bool Add> void prolongate_macro(const double* xp, double* yp, Index f, Index c, int nf) {
    const int nc = nf / 2;
    for (int j = 2; j <= nf - 3; ++j) {
        // yr, xr, lo, hi: the first point (1, row) of a lattice row, so that point (i, row) is at
        // 2 (i - 1).
        double* yr = yp + (f + 2 * point(nf, 1, j));
        const int imax = nf - 2 - j;
        if (j % 2 == 0) {
            // Coarse row j/2: even i on its points, odd i halfway between two of them.
            const double* xr = xp + (c + 2 * point(nc, 1, j / 2));
            int i = 2;
            for (; i + 1 <= imax; i += 2) {
                put<Add>(yr + 2 * i - 2, dot1(ld(xr + i - 2)));
                put<Add>(yr + 2 * i, dot2(ld(xr + i - 2), ld(xr + i)));
            }
            if (i <= imax) put<Add>(yr + 2 * i - 2, dot1(ld(xr + i - 2)));
        } else {
            // Between coarse rows (j - 1)/2 and (j + 1)/2: even i on a column, odd i on a
            // diagonal ((i + 1)/2 below, (i - 1)/2 above).
            const double* lo = xp + (c + 2 * point(nc, 1, (j - 1) / 2));
            const double* hi = xp + (c + 2 * point(nc, 1, (j + 1) / 2));
            int i = 2;
            for (; i + 1 <= imax; i += 2) {
                put<Add>(yr + 2 * i - 2, dot2(ld(lo + i - 2), ld(hi + i - 2)));
                put<Add>(yr + 2 * i, dot2(ld(lo + i), ld(hi + i - 2)));
            }
            if (i <= imax) put<Add>(yr + 2 * i - 2, dot2(ld(lo + i - 2), ld(hi + i - 2)));
        }
    }
}

// R on the coarse interior points of one macro: R's row in column order, each lane summed as
// row_dot sums seven entries.
void restrict_macro(const double* xp, double* yp, Index f, Index c, int nc) {
    const int nf = 2 * nc;
    for (int J = 1; J <= nc - 2; ++J) {
        double* yr = yp + (c + 2 * point(nc, 1, J));
        // Fine rows 2J - 1, 2J and 2J + 1 around coarse row J (point (p, row) at 2 (p - 1)).
        const double* below = xp + (f + 2 * point(nf, 1, 2 * J - 1));
        const double* on = xp + (f + 2 * point(nf, 1, 2 * J));
        const double* above = xp + (f + 2 * point(nf, 1, 2 * J + 1));
        for (int I = 1; I <= nc - 1 - J; ++I) {
            const int i = 2 * I;
            Pair a0 = add(zero(), mul(0.5, ld(below + 2 * i - 2)));
            const Pair a1 = add(zero(), mul(0.5, ld(below + 2 * i)));
            const Pair a2 = add(zero(), mul(0.5, ld(on + 2 * i - 4)));
            const Pair a3 = add(zero(), mul(1.0, ld(on + 2 * i - 2)));
            a0 = add(a0, mul(0.5, ld(on + 2 * i)));
            a0 = add(a0, mul(0.5, ld(above + 2 * i - 4)));
            a0 = add(a0, mul(0.5, ld(above + 2 * i - 2)));
            st(yr + 2 * I - 2, add(add(a0, a1), add(a2, a3)));
        }
    }
}

constexpr double kHalf = 0.5;
constexpr double kOne = 1.0;

} // namespace

bool LatticeTransfer::applies(const smoothers::LatticeRows& fine,
                              const smoothers::LatticeRows& coarse) {
    if (fine.n != 2 * coarse.n || coarse.n < 1) return false;
    const long npf = smoothers::LatticeRows::interior_points(fine.n);
    const long npc = smoothers::LatticeRows::interior_points(coarse.n);
    if (npf == 0) return fine.first_row.empty() && coarse.first_row.empty();
    const long macros = fine.macros();
    return static_cast<long>(fine.first_row.size()) == macros * npf &&
           static_cast<long>(coarse.first_row.size()) == macros * npc;
}

LatticeTransfer::LatticeTransfer(const SparseMatrix& T, const SparseMatrix& R,
                                 const smoothers::LatticeRows& fine,
                                 const smoothers::LatticeRows& coarse)
    : T_(T), R_(R), nf_(fine.n), nc_(coarse.n) {
    MLC_CHECK(T.isCompressed() && R.isCompressed(), "LatticeTransfer: T and R must be compressed");
    MLC_CHECK(R.rows() == T.cols() && R.cols() == T.rows(),
              "LatticeTransfer: T is " << T.rows() << " x " << T.cols() << ", R " << R.rows()
                                       << " x " << R.cols());
    MLC_CHECK(applies(fine, coarse), "LatticeTransfer: the fine lattice has "
                                         << nf_ << " subdivisions and " << fine.first_row.size()
                                         << " interior points, the coarse one " << nc_ << " and "
                                         << coarse.first_row.size()
                                         << " (expected twice the subdivisions, the same macros)");
    const long npf = smoothers::LatticeRows::interior_points(nf_);
    const long npc = smoothers::LatticeRows::interior_points(nc_);
    const long macros = fine.macros();
    std::vector<char> t_done(static_cast<size_t>(T.rows()), 0);
    std::vector<char> r_done(static_cast<size_t>(R.rows()), 0);
    std::vector<Index> fb(static_cast<size_t>(macros), -1), cb(static_cast<size_t>(macros), -1);
    if (npc > 0) {
        parallel::for_rows(static_cast<size_t>(macros), 1, [&](size_t m0, size_t m1) {
            for (size_t m = m0; m < m1; ++m) {
                const Index f = fine.lattice_base(static_cast<long>(m));
                const Index c = coarse.lattice_base(static_cast<long>(m));
                if (f < 0 || c < 0 || f + 2 * npf > T.rows() || c + 2 * npc > R.rows()) continue;
                bool ok = true;
                for_structured_fine(nf_, [&](int i, int j) {
                    if (!ok) return;
                    int I[2], J[2];
                    const int count = parents(i, j, I, J);
                    for (int comp = 0; comp < 2 && ok; ++comp) {
                        Index cols[2];
                        for (int q = 0; q < count; ++q)
                            cols[q] = c + 2 * point(nc_, I[q], J[q]) + comp;
                        if (count == 2 && cols[1] < cols[0]) std::swap(cols[0], cols[1]);
                        const double half[2] = {kHalf, kHalf};
                        ok = row_is(T, f + 2 * point(nf_, i, j) + comp, count, cols,
                                    count == 1 ? &kOne : half);
                    }
                });
                static constexpr double rv[7] = {kHalf, kHalf, kHalf, kOne, kHalf, kHalf, kHalf};
                for (int J = 1; J <= nc_ - 2 && ok; ++J)
                    for (int I = 1; I <= nc_ - 1 - J && ok; ++I) {
                        const Index q0 = f + 2 * point(nf_, 2 * I, 2 * J - 1);
                        const Index q2 = f + 2 * point(nf_, 2 * I - 1, 2 * J);
                        const Index q5 = f + 2 * point(nf_, 2 * I - 1, 2 * J + 1);
                        for (int comp = 0; comp < 2 && ok; ++comp) {
                            const Index cols[7] = {q0 + comp,     q0 + 2 + comp, q2 + comp,
                                                   q2 + 2 + comp, q2 + 4 + comp, q5 + comp,
                                                   q5 + 2 + comp};
                            ok = row_is(R, c + 2 * point(nc_, I, J) + comp, 7, cols, rv);
                        }
                    }
                if (!ok) continue;
                fb[m] = f;
                cb[m] = c;
            }
        });
    }
    // Keep the macros whose rows no other kept macro holds (a lattice from levels::lattice_rows
    // never overlaps; two that did would write the same rows twice), in macro order.
    std::vector<char> f_taken(static_cast<size_t>(T.rows()), 0);
    std::vector<char> c_taken(static_cast<size_t>(R.rows()), 0);
    for (long m = 0; m < macros; ++m) {
        const Index f = fb[static_cast<size_t>(m)], c = cb[static_cast<size_t>(m)];
        if (f < 0) continue;
        bool free_rows = true;
        for (Index r = f; r < f + 2 * npf && free_rows; ++r)
            free_rows = !f_taken[static_cast<size_t>(r)];
        for (Index r = c; r < c + 2 * npc && free_rows; ++r)
            free_rows = !c_taken[static_cast<size_t>(r)];
        if (!free_rows) continue;
        std::fill(f_taken.begin() + f, f_taken.begin() + f + 2 * npf, 1);
        std::fill(c_taken.begin() + c, c_taken.begin() + c + 2 * npc, 1);
        fine_base_.push_back(f);
        coarse_base_.push_back(c);
    }
    parallel::for_rows(fine_base_.size(), 1, [&](size_t m0, size_t m1) {
        for (size_t m = m0; m < m1; ++m) {
            const Index f = fine_base_[m], c = coarse_base_[m];
            for_structured_fine(nf_, [&](int i, int j) {
                const Index r = f + 2 * point(nf_, i, j);
                t_done[static_cast<size_t>(r)] = t_done[static_cast<size_t>(r + 1)] = 1;
            });
            for (Index r = c; r < c + 2 * npc; ++r)
                r_done[static_cast<size_t>(r)] = 1;
        }
    });
    rest_t_.take(T, t_done);
    rest_r_.take(R, r_done);
    structured_t_ = T.rows() - static_cast<Index>(rest_t_.row.size());
    structured_r_ = R.rows() - static_cast<Index>(rest_r_.row.size());
    // Compulsory bytes: x read and y written once, and the remaining rows (12 bytes an entry,
    // their row and offset).
    bytes_t_ = 8.0 * static_cast<double>(T.rows() + T.cols() + rest_t_.row.size()) +
               12.0 * static_cast<double>(rest_t_.values.size());
    bytes_r_ = 8.0 * static_cast<double>(R.rows() + R.cols() + rest_r_.row.size()) +
               12.0 * static_cast<double>(rest_r_.values.size());
}

void LatticeTransfer::Rest::take(const SparseMatrix& A, const std::vector<char>& done) {
    // Over the threads in chunks of rows: count, then copy each chunk's rows to its offsets.
    const int* o = A.outerIndexPtr();
    const parallel::RowChunks rc =
        parallel::row_chunks(static_cast<size_t>(A.rows()), size_t{1} << 14);
    std::vector<size_t> rows(rc.count + 1, 0), entries(rc.count + 1, 0);
    parallel::for_chunks(rc.count, [&](size_t c) {
        for (size_t r = rc.begin(c); r < rc.end(c); ++r)
            if (!done[r]) {
                ++rows[c + 1];
                entries[c + 1] += static_cast<size_t>(o[r + 1] - o[r]);
            }
    });
    for (size_t c = 0; c < rc.count; ++c) {
        rows[c + 1] += rows[c];
        entries[c + 1] += entries[c];
    }
    row.resize(rows[rc.count]);
    outer.resize(rows[rc.count] + 1);
    inner.resize(entries[rc.count]);
    values.resize(entries[rc.count]);
    outer[0] = 0;
    parallel::for_chunks(rc.count, [&](size_t c) {
        size_t k = rows[c], e = entries[c];
        for (size_t r = rc.begin(c); r < rc.end(c); ++r) {
            if (done[r]) continue;
            row[k] = static_cast<int>(r);
            for (int q = o[r]; q < o[r + 1]; ++q, ++e) {
                inner[e] = A.innerIndexPtr()[q];
                values[e] = A.valuePtr()[q];
            }
            outer[++k] = static_cast<int>(e);
        }
    });
}

template <bool Add> void LatticeTransfer::Rest::apply(const double* x, double* y) const {
    parallel::for_rows(row.size(), static_cast<size_t>(kMinRowsPerThread), [&](size_t b, size_t e) {
        for (size_t k = b; k < e; ++k) {
            const double v = row_dot(inner.data(), values.data(), x, outer[k], outer[k + 1]);
            if (Add)
                y[row[k]] += v;
            else
                y[row[k]] = v;
        }
    });
}

void LatticeTransfer::prolongate(const Vector& x, Vector& y, bool add) const {
    MLC_CHECK(x.size() == T_.cols() && (!add || y.size() == T_.rows()),
              "LatticeTransfer::prolongate: T is " << T_.rows() << " x " << T_.cols() << ", x has "
                                                   << x.size() << ", y has " << y.size());
    if (!add) y.resize(T_.rows());
    const traffic::Pass pass(traffic::Kind::structured,
                             bytes_t_ + (add ? 8.0 * static_cast<double>(T_.rows()) : 0.0));
    const double* xp = x.data();
    double* yp = y.data();
    parallel::for_rows(fine_base_.size(), 1, [&](size_t m0, size_t m1) {
        for (size_t m = m0; m < m1; ++m)
            if (add)
                prolongate_macro<true>(xp, yp, fine_base_[m], coarse_base_[m], nf_);
            else
                prolongate_macro<false>(xp, yp, fine_base_[m], coarse_base_[m], nf_);
    });
    if (add)
        rest_t_.apply<true>(xp, yp);
    else
        rest_t_.apply<false>(xp, yp);
}

void LatticeTransfer::restrict_residual(const Vector& x, Vector& y) const {
    MLC_CHECK(x.size() == R_.cols(), "LatticeTransfer::restrict_residual: R is "
                                         << R_.rows() << " x " << R_.cols() << ", x has "
                                         << x.size());
    y.resize(R_.rows());
    const traffic::Pass pass(traffic::Kind::structured, bytes_r_);
    const double* xp = x.data();
    double* yp = y.data();
    parallel::for_rows(fine_base_.size(), 1, [&](size_t m0, size_t m1) {
        for (size_t m = m0; m < m1; ++m)
            restrict_macro(xp, yp, fine_base_[m], coarse_base_[m], nc_);
    });
    rest_r_.apply<false>(xp, yp);
}

} // namespace mlc::solvers
