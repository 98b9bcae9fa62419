// SPDX-License-Identifier: MIT
// ILU(k): symbolic levels of fill on the CSR pattern, then IKJ numeric elimination.
#include "smoothers/iluk.hpp"

#include "core/check.hpp"
#include "smoothers/matrix_checks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlc::smoothers {

void ILUKParams::validate() const {
    MLC_CHECK(fill_level >= 0, "ILUKParams::fill_level must be >= 0, found " << fill_level);
    MLC_CHECK(pivot_tol >= 0.0 && pivot_tol < 1.0,
              "ILUKParams::pivot_tol must be in [0, 1), found " << pivot_tol);
}

std::ostream& operator<<(std::ostream& os, const ILUKParams& p) {
    return os << "ILUKParams{fill_level=" << p.fill_level << ", pivot_tol=" << p.pivot_tol << "}";
}

ILUK::ILUK(ILUKParams params) : params_(params) {
    params_.validate();
}

void ILUK::setup(const SparseMatrix& A) {
    check_setup_matrix(A, "ILUK::setup");
    symbolic(A);
    numeric(A);
}

void ILUK::update_values(const SparseMatrix& A) {
    check_setup_matrix(A, "ILUK::update_values");
    if (!a_pattern_.matches(A)) symbolic(A);
    numeric(A);
}

// Row-wise symbolic ILU(k) (Saad, "Iterative Methods", sect. 10.3.3): the columns of row i are
// kept in a sorted linked list so that fill created by row k lands after k and is eliminated in
// turn; lev(i,j) = min(lev(i,j), lev(i,k) + lev(k,j) + 1).
void ILUK::symbolic(const SparseMatrix& A) {
    const int n = static_cast<int>(A.rows());
    const int K = params_.fill_level;
    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    n_ = n;
    a_pattern_ = SparsityPattern(A);

    ptr_.assign(1, 0);
    cols_.clear();
    diag_.assign(n, 0);
    std::vector<int> levels; // level of every stored entry of L\U
    cols_.reserve(A.nonZeros());
    levels.reserve(A.nonZeros());

    const int head = n; // list head node; n also marks the end of the list
    std::vector<int> next(n + 1, n);
    std::vector<int> lev(n, -1); // level of column j in the current row, -1 if absent
    auto insert_after = [&](int from, int j) {
        int prev = from;
        while (next[prev] < j)
            prev = next[prev];
        next[j] = next[prev];
        next[prev] = j;
    };

    for (int i = 0; i < n; ++i) {
        int prev = head;
        for (int p = ao[i]; p < ao[i + 1]; ++p) {
            const int c = ai[p];
            MLC_ASSERT(prev == head || c > prev, "ILUK: CSR columns must be sorted");
            next[prev] = c;
            lev[c] = 0;
            prev = c;
        }
        next[prev] = n;
        if (lev[i] < 0) { // missing diagonal: add it, a fill may make it nonzero
            insert_after(head, i);
            lev[i] = 0;
        }
        for (int k = next[head]; k < i; k = next[k]) {
            const int lik = lev[k];
            for (int q = diag_[k] + 1; q < ptr_[k + 1]; ++q) {
                const int nl = lik + levels[q] + 1;
                if (nl > K) continue;
                const int j = cols_[q];
                if (lev[j] < 0) {
                    insert_after(k, j);
                    lev[j] = nl;
                } else if (nl < lev[j]) {
                    lev[j] = nl;
                }
            }
        }
        for (int j = next[head]; j < n; j = next[j]) {
            if (j == i) diag_[i] = static_cast<int>(cols_.size());
            cols_.push_back(j);
            levels.push_back(lev[j]);
            lev[j] = -1;
        }
        next[head] = n;
        ptr_.push_back(static_cast<int>(cols_.size()));
    }

    // Map every stored entry of A to its place in L\U (both rows sorted: merge).
    a_to_lu_.resize(A.nonZeros());
    for (int i = 0; i < n; ++i) {
        int q = ptr_[i];
        for (int p = ao[i]; p < ao[i + 1]; ++p) {
            while (cols_[q] < ai[p])
                ++q;
            a_to_lu_[p] = q;
        }
    }
    vals_.assign(cols_.size(), 0.0);
    inv_pivot_.assign(n, 0.0);
    pos_.assign(n, -1);
    ++n_symbolic_;
}

void ILUK::numeric(const SparseMatrix& A) {
    const int n = static_cast<int>(n_);
    std::fill(vals_.begin(), vals_.end(), 0.0);
    const double* av = A.valuePtr();
    for (Index e = 0; e < A.nonZeros(); ++e)
        vals_[a_to_lu_[e]] = av[e];

    for (int i = 0; i < n; ++i) {
        for (int p = ptr_[i]; p < ptr_[i + 1]; ++p)
            pos_[cols_[p]] = p;
        for (int p = ptr_[i]; p < diag_[i]; ++p) {
            const int k = cols_[p];
            const double lik = vals_[p] * inv_pivot_[k];
            vals_[p] = lik;
            if (lik == 0.0) continue;
            for (int q = diag_[k] + 1; q < ptr_[k + 1]; ++q) {
                const int at = pos_[cols_[q]];
                if (at >= 0) vals_[at] -= lik * vals_[q];
            }
        }
        for (int p = ptr_[i]; p < ptr_[i + 1]; ++p)
            pos_[cols_[p]] = -1;
        const double piv = vals_[diag_[i]];
        const double scale = row_max_abs(A, i);
        if (!std::isfinite(piv) || std::abs(piv) <= params_.pivot_tol * scale || piv == 0.0) {
            std::ostringstream os;
            os << "ILUK: zero pivot u_ii = " << piv << " in row " << i << " (max |a_ij| = " << scale
               << ", fill level " << params_.fill_level
               << "); order each contact node's multipliers after its displacements, raise the "
                  "fill level, or use a block smoother or LU";
            throw SolverBreakdown(os.str());
        }
        inv_pivot_[i] = 1.0 / piv;
    }
}

void ILUK::apply(const Vector& r, Vector& z) const {
    check_size(r, n_, "ILUK::apply", "r");
    if (&z != &r) z = r;
    double* x = z.data();
    for (Index i = 0; i < n_; ++i) {
        double s = x[i];
        for (int p = ptr_[i]; p < diag_[i]; ++p)
            s -= vals_[p] * x[cols_[p]];
        x[i] = s;
    }
    for (Index i = n_ - 1; i >= 0; --i) {
        double s = x[i];
        for (int p = diag_[i] + 1; p < ptr_[i + 1]; ++p)
            s -= vals_[p] * x[cols_[p]];
        x[i] = s * inv_pivot_[i];
    }
}

void ILUK::apply_transpose(const Vector& r, Vector& z) const {
    check_size(r, n_, "ILUK::apply_transpose", "r");
    if (&z != &r) z = r;
    double* x = z.data();
    for (Index i = 0; i < n_; ++i) { // U^T w = r, column sweep over the rows of U
        const double xi = x[i] * inv_pivot_[i];
        x[i] = xi;
        for (int p = diag_[i] + 1; p < ptr_[i + 1]; ++p)
            x[cols_[p]] -= vals_[p] * xi;
    }
    for (Index i = n_ - 1; i >= 0; --i) { // L^T z = w
        const double xi = x[i];
        for (int p = ptr_[i]; p < diag_[i]; ++p)
            x[cols_[p]] -= vals_[p] * xi;
    }
}

std::string ILUK::name() const {
    return "ilu(" + std::to_string(params_.fill_level) + ")";
}

SparseMatrix ILUK::factors() const {
    std::vector<Triplet> t;
    t.reserve(cols_.size());
    for (int i = 0; i < static_cast<int>(n_); ++i)
        for (int p = ptr_[i]; p < ptr_[i + 1]; ++p)
            t.emplace_back(i, cols_[p], vals_[p]);
    SparseMatrix F(n_, n_);
    F.setFromTriplets(t.begin(), t.end());
    return F;
}

} // namespace mlc::smoothers
