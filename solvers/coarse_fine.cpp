// SPDX-License-Identifier: MIT
// Coarse/fine preconditioner (Alart & Lebon 1995, sect. 4.1, eqs. 17-25).
#include "solvers/coarse_fine.hpp"

#include "core/check.hpp"
#include "smoothers/matrix_checks.hpp"
#include "solvers/direct.hpp"
#include "solvers/krylov.hpp"

#include <algorithm>
#include <sstream>

namespace mlc::solvers {

std::string_view to_string(InnerSolve s) {
    switch (s) {
    case InnerSolve::lu:
        return "lu";
    case InnerSolve::cgs:
        return "cgs";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, InnerSolve s) {
    return os << to_string(s);
}

InnerSolve parse_inner_solve(std::string_view name) {
    if (name == "lu") return InnerSolve::lu;
    if (name == "cgs") return InnerSolve::cgs;
    MLC_CHECK(false, "unknown inner solver '" << name << "' for CF; valid: lu, cgs");
    return InnerSolve::lu;
}

void CoarseFineParams::validate() const {
    MLC_CHECK(inner_tol > 0.0 && inner_tol < 1.0,
              "CoarseFineParams::inner_tol must be in (0, 1), found " << inner_tol);
    MLC_CHECK(inner_max_iter >= 1,
              "CoarseFineParams::inner_max_iter must be >= 1, found " << inner_max_iter);
}

std::ostream& operator<<(std::ostream& os, const CoarseFineParams& p) {
    return os << "CoarseFineParams{inner=" << p.inner << ", inner_tol=" << p.inner_tol
              << ", inner_max_iter=" << p.inner_max_iter << "}";
}

void CoarseFineSplit::validate(Index n) const {
    const auto nc = static_cast<Index>(coarse_set.size());
    const auto nf = static_cast<Index>(fine_set.size());
    MLC_CHECK(nc + nf == n, "CoarseFineSplit: coarse_set (" << nc << ") and fine_set (" << nf
                                                            << ") do not add up to the " << n
                                                            << " unknowns of the matrix");
    MLC_CHECK(static_cast<Index>(coarse_dof.size()) == nc,
              "CoarseFineSplit: coarse_dof has " << coarse_dof.size() << " entries, expected " << nc
                                                 << " (one per coarse_set entry)");
    MLC_CHECK(nc > 0 && nf > 0, "CoarseFineSplit: both sets must be non-empty (coarse "
                                    << nc << ", fine " << nf << ")");
    std::vector<char> seen(static_cast<size_t>(n), 0);
    for (const auto* set : {&coarse_set, &fine_set})
        for (int i : *set) {
            MLC_CHECK(i >= 0 && i < n && !seen[static_cast<size_t>(i)],
                      "CoarseFineSplit: unknown " << i << " is out of range or listed twice");
            seen[static_cast<size_t>(i)] = 1;
        }
    std::vector<char> hit(static_cast<size_t>(std::max<Index>(n_coarse, 0)), 0);
    for (int d : coarse_dof) {
        MLC_CHECK(d >= 0 && d < n_coarse && !hit[static_cast<size_t>(d)],
                  "CoarseFineSplit: coarse unknown " << d << " is out of [0, " << n_coarse
                                                     << ") or matched twice");
        hit[static_cast<size_t>(d)] = 1;
    }
    for (const auto* s : {&restrict_scale, &prolong_scale})
        MLC_CHECK(s->empty() || static_cast<Index>(s->size()) == nc,
                  "CoarseFineSplit: a scale vector has " << s->size() << " entries, expected 0 or "
                                                         << nc);
    for (size_t k = 0; k < fine_block_starts.size(); ++k)
        MLC_CHECK((k == 0 ? fine_block_starts[0] == 0
                          : fine_block_starts[k] > fine_block_starts[k - 1]) &&
                      fine_block_starts[k] <= nf,
                  "CoarseFineSplit: fine_block_starts must increase from 0 within [0, "
                      << nf << "], found " << fine_block_starts[k] << " at position " << k);
}

// ---------------------------------------------------------------------------------------------
InnerCGS::InnerCGS(double rel_tol, int max_iter) : rel_tol_(rel_tol), max_iter_(max_iter) {
    MLC_CHECK(rel_tol > 0.0 && rel_tol < 1.0,
              "InnerCGS: rel_tol must be in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "InnerCGS: max_iter must be >= 1, found " << max_iter);
}

void InnerCGS::setup(const SparseMatrix& A) {
    MLC_CHECK(A.rows() == A.cols(),
              "InnerCGS::setup: expected a square matrix, found " << A.rows() << " x " << A.cols());
    A_ = &A;
}

void InnerCGS::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(A_ != nullptr, "InnerCGS::apply: call setup first");
    KrylovParams p;
    p.rel_tol = rel_tol_;
    p.max_iter = max_iter_;
    z.setZero(r.size());
    const SolveResult res = cgs(MatrixOperator(*A_), IdentityPreconditioner(), r, z, p);
    ++n_applies_;
    n_iterations_ += res.iterations;
}

std::string InnerCGS::name() const {
    std::ostringstream os;
    os << "cgs(tol=" << rel_tol_ << ")";
    return os.str();
}

// ---------------------------------------------------------------------------------------------
CoarseFinePreconditioner::CoarseFinePreconditioner(CoarseFineSplit split, CoarseSolve coarse_solve,
                                                   std::unique_ptr<Preconditioner> inner,
                                                   std::string label)
    : split_(std::move(split)), coarse_solve_(std::move(coarse_solve)), inner_(std::move(inner)),
      label_(std::move(label)) {
    MLC_CHECK(static_cast<bool>(coarse_solve_), "CoarseFinePreconditioner: no coarse solve given");
    MLC_CHECK(inner_ != nullptr, "CoarseFinePreconditioner: no inner solver given");
}

void CoarseFinePreconditioner::extract(const SparseMatrix& A) {
    // Position of every unknown in its set: >= 0 in fine_set, -1 - k for coarse_set[k].
    std::vector<int> where(static_cast<size_t>(n_));
    for (size_t k = 0; k < split_.fine_set.size(); ++k)
        where[static_cast<size_t>(split_.fine_set[k])] = static_cast<int>(k);
    for (size_t k = 0; k < split_.coarse_set.size(); ++k)
        where[static_cast<size_t>(split_.coarse_set[k])] = -1 - static_cast<int>(k);
    std::vector<Triplet> tff, tfc, tcf;
    auto rows_of = [&](const std::vector<int>& set, bool fine_rows) {
        for (size_t k = 0; k < set.size(); ++k)
            for (SparseMatrix::InnerIterator it(A, set[k]); it; ++it) {
                const int w = where[static_cast<size_t>(it.col())];
                const int row = static_cast<int>(k);
                if (fine_rows) {
                    if (w >= 0)
                        tff.emplace_back(row, w, it.value());
                    else
                        tfc.emplace_back(row, -1 - w, it.value());
                } else if (w >= 0) {
                    tcf.emplace_back(row, w, it.value());
                }
            }
    };
    rows_of(split_.fine_set, true);
    rows_of(split_.coarse_set, false);
    const auto nf = static_cast<Index>(split_.fine_set.size());
    const auto nc = static_cast<Index>(split_.coarse_set.size());
    A_ff_.resize(nf, nf);
    A_ff_.setFromTriplets(tff.begin(), tff.end());
    A_ff_.makeCompressed();
    A_fc_.resize(nf, nc);
    A_fc_.setFromTriplets(tfc.begin(), tfc.end());
    A_fc_.makeCompressed();
    A_cf_.resize(nc, nf);
    A_cf_.setFromTriplets(tcf.begin(), tcf.end());
    A_cf_.makeCompressed();
}

void CoarseFinePreconditioner::setup(const SparseMatrix& A) {
    smoothers::check_setup_matrix(A, "CoarseFinePreconditioner::setup");
    n_ = A.rows();
    split_.validate(n_);
    extract(A);
    inner_->setup(A_ff_);
    const auto nf = static_cast<Index>(split_.fine_set.size());
    const auto nc = static_cast<Index>(split_.coarse_set.size());
    rf_.resize(nf);
    tf_.resize(nf);
    zf_.resize(nf);
    wc_.resize(nc);
    zc_.resize(nc);
    rH_.resize(split_.n_coarse);
    zH_.resize(split_.n_coarse);
}

void CoarseFinePreconditioner::update_values(const SparseMatrix& A) {
    if (n_ != A.rows() || A_ff_.size() == 0) {
        setup(A);
        return;
    }
    smoothers::check_setup_matrix(A, "CoarseFinePreconditioner::update_values");
    extract(A);
    inner_->update_values(A_ff_);
}

void CoarseFinePreconditioner::apply(const Vector& r, Vector& z) const {
    smoothers::check_size(r, n_, "CoarseFinePreconditioner::apply", "r");
    const auto& fs = split_.fine_set;
    const auto& cs = split_.coarse_set;
    const auto& cd = split_.coarse_dof;
    const auto nf = static_cast<Index>(fs.size());
    const auto nc = static_cast<Index>(cs.size());
    // A_ff t_f = r_f.
    for (Index k = 0; k < nf; ++k)
        rf_[k] = r[fs[static_cast<size_t>(k)]];
    inner_->apply(rf_, tf_);
    // A_H z_H = restrict(r_c - A_cf t_f).
    wc_.noalias() = A_cf_ * tf_;
    rH_.setZero();
    for (Index k = 0; k < nc; ++k) {
        const auto ks = static_cast<size_t>(k);
        const double s = split_.restrict_scale.empty() ? 1.0 : split_.restrict_scale[ks];
        rH_[cd[ks]] = s * (r[cs[ks]] - wc_[k]);
    }
    coarse_solve_(rH_, zH_);
    MLC_CHECK(zH_.size() == split_.n_coarse, "CoarseFinePreconditioner::apply: the coarse solve "
                                             "returned a vector of size "
                                                 << zH_.size() << ", expected " << split_.n_coarse);
    for (Index k = 0; k < nc; ++k) {
        const auto ks = static_cast<size_t>(k);
        const double s = split_.prolong_scale.empty() ? 1.0 : split_.prolong_scale[ks];
        zc_[k] = s * zH_[cd[ks]];
    }
    // A_ff z_f = r_f - A_fc z_c.
    rf_.noalias() -= A_fc_ * zc_;
    inner_->apply(rf_, zf_);
    z.resize(n_);
    for (Index k = 0; k < nf; ++k)
        z[fs[static_cast<size_t>(k)]] = zf_[k];
    for (Index k = 0; k < nc; ++k)
        z[cs[static_cast<size_t>(k)]] = zc_[k];
}

std::string CoarseFinePreconditioner::name() const {
    return label_ + "(" + inner_->name() + ")";
}

std::unique_ptr<CoarseFinePreconditioner>
make_coarse_fine(CoarseFineSplit split, CoarseSolve coarse_solve, const CoarseFineParams& params) {
    params.validate();
    std::unique_ptr<Preconditioner> inner;
    if (params.inner == InnerSolve::lu)
        inner = std::make_unique<SparseLUPreconditioner>();
    else
        inner = std::make_unique<InnerCGS>(params.inner_tol, params.inner_max_iter);
    return std::make_unique<CoarseFinePreconditioner>(std::move(split), std::move(coarse_solve),
                                                      std::move(inner), "cf");
}

MultiplierScale parse_multiplier_scale(std::string_view name) {
    if (name == "q") return MultiplierScale::q;
    if (name == "none") return MultiplierScale::none;
    if (name == "qt") return MultiplierScale::qt;
    if (name == "qinv") return MultiplierScale::qinv;
    MLC_CHECK(false, "unknown multiplier scale '" << name << "'; valid: q, none, qt, qinv");
    return MultiplierScale::q;
}

} // namespace mlc::solvers
