// SPDX-License-Identifier: MIT
// EBE preconditioner (Alart, Barboteu & Lebon 1997): element factors, colouring, C1/C4/C5.
#include "smoothers/ebe.hpp"

#include "core/check.hpp"
#include "smoothers/matrix_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>

namespace mlc::smoothers {

std::string_view to_string(EBEVariant v) {
    switch (v) {
    case EBEVariant::c1:
        return "c1";
    case EBEVariant::c4:
        return "c4";
    case EBEVariant::c5:
        return "c5";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, EBEVariant v) {
    return os << to_string(v);
}

EBEVariant parse_ebe_variant(std::string_view name) {
    for (EBEVariant v : {EBEVariant::c1, EBEVariant::c4, EBEVariant::c5})
        if (name == to_string(v)) return v;
    MLC_CHECK(false, "unknown EBE variant '" << name << "'; valid variants: c1, c4, c5");
    return EBEVariant::c1;
}

void EBEParams::validate() const {
    MLC_CHECK(zero_pivot_tol >= 0.0 && zero_pivot_tol < 1.0,
              "EBEParams::zero_pivot_tol must be in [0, 1), found " << zero_pivot_tol);
    MLC_CHECK(min_parallel_elements >= 1,
              "EBEParams::min_parallel_elements must be >= 1, found " << min_parallel_elements);
}

std::string_view to_string(UnitScaling u) {
    return u == UnitScaling::contact_unknowns ? "contact" : "multipliers";
}

std::ostream& operator<<(std::ostream& os, const EBEParams& p) {
    return os << "EBEParams{variant=" << p.variant << ", unit_scaling=" << to_string(p.unit_scaling)
              << ", zero_pivot_tol=" << p.zero_pivot_tol
              << ", parallel=" << (p.parallel ? "true" : "false")
              << ", min_parallel_elements=" << p.min_parallel_elements << "}";
}

EBE::EBE(const std::vector<ElementMatrix>& elements, EBEParams params)
    : elements_(elements), params_(params) {
    params_.validate();
}

namespace {

// LU without pivoting of the row-major n x n matrix a, in place (L unit lower, U upper). A pivot
// with |u_kk| <= tol is replaced by 1 (see the file comment of ebe.hpp). Returns the number of
// replaced pivots.
int factor_in_place(double* a, int n, double tol) {
    int replaced = 0;
    for (int k = 0; k < n; ++k) {
        double& piv = a[k * n + k];
        if (!(std::abs(piv) > tol)) {
            piv = 1.0;
            ++replaced;
        }
        const double inv = 1.0 / piv;
        for (int i = k + 1; i < n; ++i) {
            double& lik = a[i * n + k];
            if (lik == 0.0) continue;
            lik *= inv;
            for (int j = k + 1; j < n; ++j)
                a[i * n + j] -= lik * a[k * n + j];
        }
    }
    return replaced;
}

} // namespace

void EBE::setup(const SparseMatrix& A) {
    check_setup_matrix(A, "EBE::setup");
    params_.validate();
    n_ = A.rows();
    const auto n_el = static_cast<int>(elements_.size());

    // Contact unknowns and sorted element unknowns.
    contact_.assign(static_cast<size_t>(n_), 0);
    dof_start_.assign(1, 0);
    fac_start_.assign(1, 0);
    dofs_.clear();
    for (int e = 0; e < n_el; ++e) {
        const ElementMatrix& el = elements_[static_cast<size_t>(e)];
        const auto ne = static_cast<Index>(el.dofs.size());
        MLC_CHECK(ne >= 1 && ne <= max_element_dofs,
                  "EBE::setup: element " << e << " has " << ne << " unknowns, expected 1 to "
                                         << max_element_dofs);
        MLC_CHECK(el.A.rows() == ne && el.A.cols() == ne,
                  "EBE::setup: element " << e << " has " << ne << " unknowns but a " << el.A.rows()
                                         << " x " << el.A.cols() << " matrix");
        MLC_CHECK(el.A.allFinite(), "EBE::setup: element " << e << " has a non-finite entry");
        for (int d : el.dofs) {
            MLC_CHECK(d >= 0 && d < n_, "EBE::setup: element " << e << " refers to unknown " << d
                                                               << ", outside [0, " << n_ << ")");
            if (el.is_contact)
                contact_[static_cast<size_t>(d)] |= 1;
            else
                contact_[static_cast<size_t>(d)] |= 2;
        }
        std::vector<int> s(el.dofs);
        std::sort(s.begin(), s.end());
        MLC_CHECK(std::adjacent_find(s.begin(), s.end()) == s.end(),
                  "EBE::setup: element " << e << " lists an unknown twice");
        dofs_.insert(dofs_.end(), s.begin(), s.end());
        dof_start_.push_back(static_cast<int>(dofs_.size()));
        fac_start_.push_back(fac_start_.back() + static_cast<int>(ne * ne));
    }

    // Unit-scaled unknowns: every contact unknown (paper), or those of no elastic element (the
    // multipliers). W~: diag(A) elsewhere, 1 there.
    unit_.assign(static_cast<size_t>(n_), 0);
    for (Index i = 0; i < n_; ++i) {
        const char c = contact_[static_cast<size_t>(i)];
        unit_[static_cast<size_t>(i)] =
            params_.unit_scaling == UnitScaling::contact_unknowns ? (c & 1) != 0 : (c & 2) == 0;
    }
    w_.resize(n_);
    isw_.resize(n_);
    for (Index i = 0; i < n_; ++i) {
        if (unit_[static_cast<size_t>(i)]) {
            w_[i] = 1.0;
        } else {
            const double aii = A.coeff(i, i);
            MLC_CHECK(aii > 0.0, "EBE::setup: diagonal A(" << i << ", " << i << ") = " << aii
                                                           << " is not positive on an unknown "
                                                              "that is not unit-scaled; EBE "
                                                              "needs W = diag(A) > 0 there");
            w_[i] = aii;
        }
        isw_[i] = 1.0 / std::sqrt(w_[i]);
    }

    // Element factors in the increasing global order.
    fac_.assign(static_cast<size_t>(fac_start_.back()), 0.0);
    n_replaced_ = 0;
    for (int e = 0; e < n_el; ++e) {
        const ElementMatrix& el = elements_[static_cast<size_t>(e)];
        const int ne = static_cast<int>(el.dofs.size());
        const int* sd = dofs_.data() + dof_start_[static_cast<size_t>(e)];
        // Position of each sorted unknown in the element's own order.
        int pos[max_element_dofs];
        for (int a = 0; a < ne; ++a)
            pos[a] = static_cast<int>(std::find(el.dofs.begin(), el.dofs.end(), sd[a]) -
                                      el.dofs.begin());
        double* f = fac_.data() + fac_start_[static_cast<size_t>(e)];
        double scale = 0.0;
        for (int a = 0; a < ne; ++a)
            for (int b = 0; b < ne; ++b) {
                // J_e + W~^{-1/2} (A_e - W~_e) W~^{-1/2} (eqs. 28-30): J_e and W~_e vanish on
                // unit-scaled unknowns of a contact element; elastic elements keep J_e = I.
                double v = el.A(pos[a], pos[b]);
                if (a == b) {
                    const bool unit = unit_[static_cast<size_t>(sd[a])] != 0;
                    const double j = (el.is_contact && unit) ? 0.0 : 1.0;
                    v = j + (unit ? v : 0.0) * isw_[sd[a]] * isw_[sd[a]];
                } else {
                    v *= isw_[sd[a]] * isw_[sd[b]];
                }
                f[a * ne + b] = v;
                scale = std::max(scale, std::abs(v));
            }
        n_replaced_ += factor_in_place(f, ne, params_.zero_pivot_tol * scale);
    }

    colour_elements();
    if (params_.variant == EBEVariant::c1)
        pack_factors();
    else
        gather_global_factors();
}

void EBE::colour_elements() {
    // Greedy colouring: an element takes the lowest colour used by no element sharing one of
    // its unknowns (a bit mask of used colours per unknown; 64 colours are far more than a
    // triangle mesh with contact elements needs).
    const auto n_el = static_cast<int>(elements_.size());
    std::vector<std::uint64_t> used(static_cast<size_t>(n_), 0);
    std::vector<int> colour(static_cast<size_t>(n_el));
    int n_colours = 0;
    for (int e = 0; e < n_el; ++e) {
        std::uint64_t taken = 0;
        for (int p = dof_start_[static_cast<size_t>(e)]; p < dof_start_[static_cast<size_t>(e) + 1];
             ++p)
            taken |= used[static_cast<size_t>(dofs_[static_cast<size_t>(p)])];
        MLC_CHECK(~taken != 0, "EBE::setup: more than 64 colours needed (element "
                                   << e << "); an unknown is shared by too many elements");
        int c = 0;
        while (taken & (std::uint64_t{1} << c))
            ++c;
        colour[static_cast<size_t>(e)] = c;
        n_colours = std::max(n_colours, c + 1);
        for (int p = dof_start_[static_cast<size_t>(e)]; p < dof_start_[static_cast<size_t>(e) + 1];
             ++p)
            used[static_cast<size_t>(dofs_[static_cast<size_t>(p)])] |= std::uint64_t{1} << c;
    }
    order_.resize(static_cast<size_t>(n_el));
    std::iota(order_.begin(), order_.end(), 0);
    std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) {
        return colour[static_cast<size_t>(a)] < colour[static_cast<size_t>(b)];
    });
    colour_start_.assign(static_cast<size_t>(n_colours) + 1, 0);
    for (int e = 0; e < n_el; ++e)
        ++colour_start_[static_cast<size_t>(colour[static_cast<size_t>(e)]) + 1];
    std::partial_sum(colour_start_.begin(), colour_start_.end(), colour_start_.begin());
}

void EBE::gather_global_factors() {
    std::vector<Triplet> te, tf;
    Vector d = Vector::Zero(n_);
    for (size_t e = 0; e < elements_.size(); ++e) {
        const int ne = dof_start_[e + 1] - dof_start_[e];
        const int* sd = dofs_.data() + dof_start_[e];
        const double* f = fac_.data() + fac_start_[e];
        for (int a = 0; a < ne; ++a) {
            d[sd[a]] += f[a * ne + a];
            for (int b = 0; b < a; ++b)
                if (f[a * ne + b] != 0.0) te.emplace_back(sd[a], sd[b], f[a * ne + b]);
            for (int b = a + 1; b < ne; ++b)
                if (f[a * ne + b] != 0.0) tf.emplace_back(sd[a], sd[b], f[a * ne + b]);
        }
    }
    E_.resize(n_, n_);
    E_.setFromTriplets(te.begin(), te.end());
    E_.makeCompressed();
    F_.resize(n_, n_);
    F_.setFromTriplets(tf.begin(), tf.end());
    F_.makeCompressed();
    d_inv_.resize(n_);
    for (Index i = 0; i < n_; ++i) {
        // C5: the scaled diagonal of A (= 1) on unknowns of no contact element (eq. 31).
        double di = d[i];
        if (params_.variant == EBEVariant::c5 && !unit_[static_cast<size_t>(i)]) di = 1.0;
        if (di == 0.0) {
            std::ostringstream os;
            os << "EBE::setup: zero diagonal in the gathered factor D at unknown " << i
               << " (an unknown of no element?)";
            throw SolverBreakdown(os.str());
        }
        d_inv_[i] = 1.0 / di;
    }
}

namespace {

// Packed element factors (see EBE::pack_factors): strict lower part of L row by row, a = 1..n-1,
// b < a at lo[a (a - 1) / 2 + b]; strict upper part of U row by row from the last, a = n-2..0,
// b > a at up[(n - 2 - a)(n - 1 - a) / 2 + b - a - 1]; ip[a] = 1 / u_aa. Each pass then streams
// through one array.
constexpr int lo_at(int a, int b) {
    return a * (a - 1) / 2 + b;
}
constexpr int up_at(int n, int a, int b) {
    return (n - 2 - a) * (n - 1 - a) / 2 + b - a - 1;
}

// Element kernels on x (the element's entries of z, in sorted order). N > 0 fixes the size at
// compile time (unrolled for the common 3, 4 and 6); N = 0 uses ne.
struct LowerSolve { // x <- L^{-1} x
    template <int N>
    void run(const double* lo, const double*, const double*, int ne, double* x) const {
        const int n = N > 0 ? N : ne;
        for (int a = 1; a < n; ++a) {
            double s = x[a];
            for (int b = 0; b < a; ++b)
                s -= lo[lo_at(a, b)] * x[b];
            x[a] = s;
        }
    }
};
struct UpperSolve { // x <- U^{-1} x
    template <int N>
    void run(const double*, const double* up, const double* ip, int ne, double* x) const {
        const int n = N > 0 ? N : ne;
        x[n - 1] *= ip[n - 1];
        for (int a = n - 2; a >= 0; --a) {
            double s = x[a];
            for (int b = a + 1; b < n; ++b)
                s -= up[up_at(n, a, b)] * x[b];
            x[a] = s * ip[a];
        }
    }
};
struct UpperTransposeSolve { // x <- U^{-T} x (lower triangular)
    template <int N>
    void run(const double*, const double* up, const double* ip, int ne, double* x) const {
        const int n = N > 0 ? N : ne;
        for (int a = 0; a < n; ++a) {
            double s = x[a];
            for (int b = 0; b < a; ++b)
                s -= up[up_at(n, b, a)] * x[b];
            x[a] = s * ip[a];
        }
    }
};
struct LowerTransposeSolve { // x <- L^{-T} x (unit upper triangular)
    template <int N>
    void run(const double* lo, const double*, const double*, int ne, double* x) const {
        const int n = N > 0 ? N : ne;
        for (int a = n - 2; a >= 0; --a) {
            double s = x[a];
            for (int b = a + 1; b < n; ++b)
                s -= lo[lo_at(b, a)] * x[b];
            x[a] = s;
        }
    }
};

} // namespace

void EBE::pack_factors() {
    // The factors in colour order, so that every pass reads its arrays front to back.
    const size_t n_el = order_.size();
    pk_dof_start_.assign(1, 0);
    pk_tri_start_.assign(1, 0);
    pk_dofs_.clear();
    pk_ip_.clear();
    pk_lo_.clear();
    pk_up_.clear();
    for (size_t k = 0; k < n_el; ++k) {
        const auto e = static_cast<size_t>(order_[k]);
        const int n = dof_start_[e + 1] - dof_start_[e];
        const double* f = fac_.data() + fac_start_[e];
        for (int a = 0; a < n; ++a) {
            pk_dofs_.push_back(dofs_[static_cast<size_t>(dof_start_[e] + a)]);
            pk_ip_.push_back(1.0 / f[a * n + a]);
        }
        const size_t lo0 = pk_lo_.size();
        const auto ntri = static_cast<size_t>(n * (n - 1) / 2);
        pk_lo_.resize(lo0 + ntri);
        pk_up_.resize(lo0 + ntri);
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                if (b < a) pk_lo_[lo0 + static_cast<size_t>(lo_at(a, b))] = f[a * n + b];
                if (b > a) pk_up_[lo0 + static_cast<size_t>(up_at(n, a, b))] = f[a * n + b];
            }
        pk_dof_start_.push_back(static_cast<int>(pk_dofs_.size()));
        pk_tri_start_.push_back(static_cast<int>(pk_lo_.size()));
    }
}

// GCC's SLP vectorizer turns the element triangular solves into 16-byte loads of pairs of x
// entries just stored one by one, which defeats store-to-load forwarding and made the pass 3-4
// times slower; scalar code keeps x in registers.
#if defined(__GNUC__) && !defined(__clang__)
#define MLC_EBE_SCALAR __attribute__((optimize("no-tree-slp-vectorize", "no-tree-vectorize")))
#else
#define MLC_EBE_SCALAR
#endif

template <class Kernel>
MLC_EBE_SCALAR void EBE::element_pass(Vector& z, bool reverse, const Kernel& kernel) const {
    // Colour by colour (reversed for the backward passes); the elements of one colour share no
    // unknown, so their factors commute and run in parallel.
    const int nc = n_colours();
    const bool par = params_.parallel;
    const int min_par = params_.min_parallel_elements;
    double* zp = z.data();
    const int* ds = pk_dof_start_.data();
    const int* ts = pk_tri_start_.data();
    const int* dofs = pk_dofs_.data();
    const double* lo = pk_lo_.data();
    const double* up = pk_up_.data();
    const double* ip = pk_ip_.data();
    for (int ci = 0; ci < nc; ++ci) {
        const auto c = static_cast<size_t>(reverse ? nc - 1 - ci : ci);
        const int k0 = colour_start_[c];
        const int k1 = colour_start_[c + 1];
#pragma omp parallel for schedule(static) if (par && k1 - k0 >= min_par)
        for (int k = k0; k < k1; ++k) {
            const int d0 = ds[k];
            const int ne = ds[k + 1] - d0;
            const int* sd = dofs + d0;
            double x[max_element_dofs];
            for (int a = 0; a < ne; ++a)
                x[a] = zp[sd[a]];
            const double* l = lo + ts[k];
            const double* u = up + ts[k];
            const double* p = ip + d0;
            switch (ne) {
            case 3:
                kernel.template run<3>(l, u, p, ne, x);
                break;
            case 4:
                kernel.template run<4>(l, u, p, ne, x);
                break;
            case 6:
                kernel.template run<6>(l, u, p, ne, x);
                break;
            default:
                kernel.template run<0>(l, u, p, ne, x);
            }
            for (int a = 0; a < ne; ++a)
                zp[sd[a]] = x[a];
        }
    }
}

void EBE::apply(const Vector& r, Vector& z) const {
    check_size(r, n_, "EBE::apply", "r");
    z.resize(n_);
    z = r.cwiseProduct(isw_);
    if (params_.variant == EBEVariant::c1) {
        element_pass(z, false, LowerSolve{}); // z <- L_e^{-1} z in element order
        element_pass(z, true, UpperSolve{});  // z <- U_e^{-1} z in reverse order
    } else {
        // (I + E) y = z forward, then (D + F) z = y backward, in place.
        const int* eo = E_.outerIndexPtr();
        const int* ei = E_.innerIndexPtr();
        const double* ev = E_.valuePtr();
        for (Index i = 0; i < n_; ++i) {
            double s = z[i];
            for (int p = eo[i]; p < eo[i + 1]; ++p)
                s -= ev[p] * z[ei[p]];
            z[i] = s;
        }
        const int* fo = F_.outerIndexPtr();
        const int* fi = F_.innerIndexPtr();
        const double* fv = F_.valuePtr();
        for (Index i = n_ - 1; i >= 0; --i) {
            double s = z[i];
            for (int p = fo[i]; p < fo[i + 1]; ++p)
                s -= fv[p] * z[fi[p]];
            z[i] = s * d_inv_[i];
        }
    }
    z.array() *= isw_.array();
}

void EBE::apply_transpose(const Vector& r, Vector& z) const {
    // C^{-T} = W~^{-1/2} (factors transposed, in reverse order) W~^{-1/2}.
    check_size(r, n_, "EBE::apply_transpose", "r");
    z.resize(n_);
    z = r.cwiseProduct(isw_);
    if (params_.variant == EBEVariant::c1) {
        // C1^T = W~^{1/2} (U_1^T ... U_N^T)(L_N^T ... L_1^T) W~^{1/2}: first U_e^{-T} in element
        // order, then L_e^{-T} in reverse order.
        element_pass(z, false, UpperTransposeSolve{});
        element_pass(z, true, LowerTransposeSolve{});
    } else {
        // (D + F)^T y = z (lower: column sweep over the rows of F), then (I + E)^T z = y (upper).
        const int* fo = F_.outerIndexPtr();
        const int* fi = F_.innerIndexPtr();
        const double* fv = F_.valuePtr();
        for (Index i = 0; i < n_; ++i) {
            z[i] *= d_inv_[i];
            const double zi = z[i];
            for (int p = fo[i]; p < fo[i + 1]; ++p)
                z[fi[p]] -= fv[p] * zi;
        }
        const int* eo = E_.outerIndexPtr();
        const int* ei = E_.innerIndexPtr();
        const double* ev = E_.valuePtr();
        for (Index i = n_ - 1; i >= 0; --i) {
            const double zi = z[i];
            for (int p = eo[i]; p < eo[i + 1]; ++p)
                z[ei[p]] -= ev[p] * zi;
        }
    }
    z.array() *= isw_.array();
}

std::string EBE::name() const {
    std::string s = "ebe(" + std::string(to_string(params_.variant));
    if (params_.unit_scaling != UnitScaling::contact_unknowns)
        s += ",unit=" + std::string(to_string(params_.unit_scaling));
    return s + ")";
}

Eigen::MatrixXd EBE::element_factors(int e, std::vector<int>& sorted_dofs) const {
    MLC_CHECK(e >= 0 && e + 1 < static_cast<int>(dof_start_.size()),
              "EBE::element_factors: element " << e << " out of range (call setup first)");
    const auto es = static_cast<size_t>(e);
    const int ne = dof_start_[es + 1] - dof_start_[es];
    sorted_dofs.assign(dofs_.begin() + dof_start_[es], dofs_.begin() + dof_start_[es + 1]);
    Eigen::MatrixXd f(ne, ne);
    for (int a = 0; a < ne; ++a)
        for (int b = 0; b < ne; ++b)
            f(a, b) = fac_[static_cast<size_t>(fac_start_[es] + a * ne + b)];
    return f;
}

} // namespace mlc::smoothers
