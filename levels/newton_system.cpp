// SPDX-License-Identifier: MIT
// Newton system solvers: assembled (SparseLU or iterative) and condensed on the contact set.
#include "levels/newton_system.hpp"

#include "core/check.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "levels/krylov_system.hpp"
#include "solvers/cholesky.hpp"
#include "solvers/direct.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>

namespace mlc::levels {

// ---------------------------------------------------------------------------------------------
template <int dim>
BasicJacobianAssembler<dim>::BasicJacobianAssembler(const BasicLevel<dim>& level) : level_(level) {
    // J's pattern is K's plus the contact tangent entries: each row of J is K's row merged with
    // that row's contact columns, written straight into CSR (triplets and setFromTriplets took
    // 16 bytes per entry, a column-major copy and a sort: about 1 s and 0.8 GB at level 6).
    const SparseMatrix& K = level.elastic.K;
    const Index n = level.n_unknowns();
    MLC_ASSERT(K.isCompressed() && K.rows() <= n, "K must be compressed, at most n rows");
    std::vector<std::pair<int, int>> centries;
    const StatusMatrix<dim> I = StatusMatrix<dim>::Identity();
    for (size_t e = 0; e < level.contacts.size(); ++e)
        contact::for_each_tangent_entry(
            level.contacts[e], I, level.dofs, level.lambda_dof[e],
            [&](int row, int col, double) { centries.emplace_back(row, col); });
    std::vector<std::pair<int, int>> extra = centries;
    std::sort(extra.begin(), extra.end());
    extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
    const int* ko = K.outerIndexPtr();
    const int* ki = K.innerIndexPtr();
    const Index kr = K.rows();
    auto in_k = [&](int row, int col) {
        if (row >= kr) return false;
        return std::binary_search(ki + ko[row], ki + ko[row + 1], col);
    };
    extra.erase(std::remove_if(extra.begin(), extra.end(),
                               [&](const auto& rc) { return in_k(rc.first, rc.second); }),
                extra.end());
    // Rows with new columns; every other row is K's row at a shifted offset.
    J_.resize(n, n);
    int* jo = J_.outerIndexPtr();
    jo[0] = 0;
    size_t x = 0;
    for (Index i = 0; i < n; ++i) {
        int cnt = i < kr ? ko[i + 1] - ko[i] : 0;
        const size_t x0 = x;
        while (x < extra.size() && extra[x].first == i)
            ++x;
        cnt += static_cast<int>(x - x0);
        if (x > x0) merged_rows_.push_back(static_cast<int>(i));
        jo[i + 1] = jo[i] + cnt;
    }
    J_.resizeNonZeros(jo[n]);
    int* ji = J_.innerIndexPtr();
    double* jv = J_.valuePtr();
    const double* kv = K.valuePtr();
    parallel::for_rows(static_cast<size_t>(n), 4096, [&](size_t b, size_t e) {
        std::fill(jv + jo[b], jv + jo[e], 0.0);
        for (size_t i = b; i < std::min(e, static_cast<size_t>(kr)); ++i) {
            std::copy(ki + ko[i], ki + ko[i + 1], ji + jo[i]);
            std::copy(kv + ko[i], kv + ko[i + 1], jv + jo[i]);
        }
    });
    x = 0;
    for (int i : merged_rows_) {
        kpos_start_.push_back(kpos_.size());
        while (extra[x].first < i)
            ++x;
        const int* kb = i < kr ? ki + ko[i] : nullptr;
        const int* ke = i < kr ? ki + ko[i + 1] : nullptr;
        int* out = ji + jo[i];
        size_t xe = x;
        while (xe < extra.size() && extra[xe].first == i)
            ++xe;
        for (size_t y = x; kb != ke || y < xe;) {
            if (y == xe || (kb != ke && *kb < extra[y].second)) {
                kpos_.push_back(static_cast<int>(out - ji));
                *out++ = *kb++;
            } else {
                *out++ = extra[y++].second;
            }
        }
        x = xe;
    }
    // J starts as K: the merged rows get K's values at their merged positions.
    for (int i : merged_rows_)
        reset_row(i);
    auto position = [&](int row, int col) {
        const int* begin = ji + jo[row];
        const int* end = ji + jo[row + 1];
        const int* it = std::lower_bound(begin, end, col);
        MLC_ASSERT(it != end && *it == col, "Jacobian pattern misses an entry");
        return static_cast<int>(it - ji);
    };
    cpos_.reserve(centries.size());
    for (auto [r, c] : centries) {
        cpos_.push_back(position(r, c));
        contact_rows_.push_back(r);
    }
    std::sort(contact_rows_.begin(), contact_rows_.end());
    contact_rows_.erase(std::unique(contact_rows_.begin(), contact_rows_.end()),
                        contact_rows_.end());
}

template <int dim> void BasicJacobianAssembler<dim>::reset_row(int i) {
    // Row i of J back to K's row i (zero in the columns only contact has).
    const SparseMatrix& K = level_.elastic.K;
    const int* ko = K.outerIndexPtr();
    const double* kv = K.valuePtr();
    double* v = J_.valuePtr();
    const int* jo = J_.outerIndexPtr();
    const bool has_k = i < K.rows();
    const auto m = std::lower_bound(merged_rows_.begin(), merged_rows_.end(), i);
    if (m == merged_rows_.end() || *m != i) {
        if (has_k) std::copy(kv + ko[i], kv + ko[i + 1], v + jo[i]);
        return;
    }
    std::fill(v + jo[i], v + jo[i + 1], 0.0);
    if (!has_k) return;
    const int* kp = kpos_.data() + kpos_start_[static_cast<size_t>(m - merged_rows_.begin())];
    for (int p = ko[i]; p < ko[i + 1]; ++p)
        v[*kp++] = kv[p];
}

template <int dim>
void BasicJacobianAssembler<dim>::assemble(const std::vector<StatusMatrix<dim>>& M) {
    // J holds K plus the last tangents: the rows holding contact entries go back to K's.
    double* v = J_.valuePtr();
    for (int i : contact_rows_)
        reset_row(i);
    size_t c = 0;
    for (size_t e = 0; e < level_.contacts.size(); ++e)
        contact::for_each_tangent_entry(level_.contacts[e], M[e], level_.dofs, level_.lambda_dof[e],
                                        [&](int, int, double value) { v[cpos_[c++]] += value; });
}

template class BasicJacobianAssembler<2>;
template class BasicJacobianAssembler<3>;

// ---------------------------------------------------------------------------------------------
namespace {

// solvers::SparseLUPreconditioner as a LinearSolver: analysis on the first call, refactorization
// only afterwards while J's pattern is unchanged (it is fixed per level).
class SparseLUSolver final : public LinearSolver {
public:
    SolveResult solve(const SparseMatrix& J, const Vector& b, Vector& x) override {
        SolveResult res;
        const double t0 = wall_seconds();
        if (first_)
            lu_.setup(J);
        else
            lu_.update_values(J);
        first_ = false;
        const double t1 = wall_seconds();
        lu_.apply(b, x);
        res.setup_seconds = t1 - t0;
        res.solve_seconds = wall_seconds() - t1;
        res.converged = true;
        res.reason = StopReason::converged;
        res.initial_residual = b.norm();
        res.final_residual = (b - J * x).norm();
        res.relative_residual =
            res.initial_residual > 0 ? res.final_residual / res.initial_residual : 0.0;
        return res;
    }
    std::string name() const override { return lu_.name(); }

private:
    solvers::SparseLUPreconditioner lu_;
    bool first_ = true;
};

template <int dim> class AssembledSystemSolver final : public BasicNewtonSystemSolver<dim> {
public:
    using Matrix = StatusMatrix<dim>;
    AssembledSystemSolver(const BasicLevel<dim>& level, std::unique_ptr<LinearSolver> solver)
        : jac_(level), solver_(std::move(solver)) {
        MLC_CHECK(solver_ != nullptr, "no linear solver given");
    }
    using BasicNewtonSystemSolver<dim>::solve;
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double) override {
        const double t0 = wall_seconds();
        jac_.assemble(M);
        const double assembly = wall_seconds() - t0;
        if (dx.size() != b.size()) dx = Vector::Zero(b.size());
        SolveResult r = solver_->solve(jac_.matrix(), b, dx);
        r.assembly_seconds = assembly;
        r.setup_seconds += assembly;
        return r;
    }
    std::string name() const override { return solver_->name(); }

private:
    BasicJacobianAssembler<dim> jac_;
    std::unique_ptr<LinearSolver> solver_;
};

template <int dim> class SchurSystemSolver final : public BasicNewtonSystemSolver<dim> {
public:
    using Matrix = StatusMatrix<dim>;
    using Point = Eigen::Matrix<double, dim, 1>;
    explicit SchurSystemSolver(const BasicLevel<dim>& level) : level_(level) {
        const double t0 = wall_seconds();
        const auto& dofs = level.dofs;
        const Index n = level.n_unknowns();
        // Compact numbering of the displacement unknowns.
        u_of_dof_.assign(static_cast<size_t>(n), -1);
        for (Index i = 0; i < n; ++i)
            if (dofs.is_displacement(i)) {
                u_of_dof_[static_cast<size_t>(i)] = static_cast<int>(dof_of_u_.size());
                dof_of_u_.push_back(static_cast<int>(i));
            }
        const Index nu = static_cast<Index>(dof_of_u_.size());
        // Contact components: offsets and B (m x nu).
        std::vector<Triplet> bt;
        for (const auto& e : level.contacts) {
            comp_.push_back(m_);
            const int me = e.n_multipliers();
            for (int q = 0; q < me; ++q) {
                // The frame's direction of component q: the tangents, then the normal.
                const Point g = (me == dim && q < dim - 1) ? Point(e.t.col(q)) : e.n;
                for (int j = 0; j < e.n_nodes(); ++j)
                    for (int a = 0; a < dim; ++a) {
                        const int d = dofs.u_dof(e.vertex[static_cast<size_t>(j)], a);
                        if (d >= 0)
                            bt.emplace_back(m_ + q, u_of_dof_[static_cast<size_t>(d)],
                                            e.weight[static_cast<size_t>(j)] * g[a]);
                    }
                rdiag_.push_back(e.r);
            }
            m_ += me;
        }
        B_.resize(m_, nu);
        B_.setFromTriplets(bt.begin(), bt.end());
        // K0 = K_uu + B^T diag(r) B, factored with the unknowns B touches ("c") ordered last and
        // the others by nested dissection. Then P K0 P^T = L L^T with L = [L_ii 0; L_ci L_cc] and,
        // as B only touches c, S = B K0^{-1} B^T = X^T X with X = L_cc^{-1} B_c^T: the
        // factorization gives S without a solve per contact component.
        // The temporaries below are freed as soon as the next one is built (the peak memory of
        // this solver on small levels is theirs as much as the factor's).
        SparseMatrixCol K0(nu, nu);
        {
            std::vector<Triplet> kt;
            const SparseMatrix& K = level.elastic.K;
            kt.reserve(static_cast<size_t>(K.nonZeros()));
            for (int i = 0; i < K.outerSize(); ++i)
                for (SparseMatrix::InnerIterator it(K, i); it; ++it)
                    kt.emplace_back(u_of_dof_[static_cast<size_t>(i)],
                                    u_of_dof_[static_cast<size_t>(it.col())], it.value());
            K0.setFromTriplets(kt.begin(), kt.end());
        }
        Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(rdiag_.data(), m_);
        K0 += SparseMatrixCol(B_.transpose() * r.asDiagonal() * B_);
        std::vector<char> is_c(static_cast<size_t>(nu), 0);
        for (int i = 0; i < B_.outerSize(); ++i)
            for (SparseMatrix::InnerIterator it(B_, i); it; ++it)
                is_c[static_cast<size_t>(it.col())] = 1;
        std::vector<int> interior, local(static_cast<size_t>(nu), -1);
        for (Index k = 0; k < nu; ++k)
            if (!is_c[static_cast<size_t>(k)]) {
                local[static_cast<size_t>(k)] = static_cast<int>(interior.size());
                interior.push_back(static_cast<int>(k));
            }
        const Index ni = static_cast<Index>(interior.size());
        std::vector<int> order;
        {
            std::vector<Triplet> it_trip;
            for (int j = 0; j < K0.outerSize(); ++j)
                for (SparseMatrixCol::InnerIterator it(K0, j); it; ++it)
                    if (local[static_cast<size_t>(it.row())] >= 0 &&
                        local[static_cast<size_t>(j)] >= 0)
                        it_trip.emplace_back(local[static_cast<size_t>(it.row())],
                                             local[static_cast<size_t>(j)], it.value());
            SparseMatrixCol Aii(ni, ni);
            Aii.setFromTriplets(it_trip.begin(), it_trip.end());
            std::vector<Triplet>().swap(it_trip);
            order = solvers::SparseCholesky::fill_reducing_order(Aii);
        }
        newpos_.assign(static_cast<size_t>(nu), -1);
        for (Index k = 0; k < ni; ++k)
            newpos_[static_cast<size_t>(
                interior[static_cast<size_t>(order[static_cast<size_t>(k)])])] =
                static_cast<int>(k);
        Index next = ni;
        for (Index k = 0; k < nu; ++k)
            if (is_c[static_cast<size_t>(k)])
                newpos_[static_cast<size_t>(k)] = static_cast<int>(next++);
        const Index nc = nu - ni;
        {
            // The lower triangle of the permuted K0 only (all the factorization reads).
            SparseMatrixCol K0p(nu, nu);
            {
                std::vector<Triplet> pt;
                pt.reserve(static_cast<size_t>(K0.nonZeros() / 2 + nu));
                for (int j = 0; j < K0.outerSize(); ++j)
                    for (SparseMatrixCol::InnerIterator it(K0, j); it; ++it) {
                        const int pr = newpos_[static_cast<size_t>(it.row())];
                        const int pc = newpos_[static_cast<size_t>(j)];
                        if (pr >= pc) pt.emplace_back(pr, pc, it.value());
                    }
                // Frees it (assigning an empty matrix keeps the storage).
                SparseMatrixCol().swap(K0);
                K0p.setFromTriplets(pt.begin(), pt.end());
            }
            try {
                chol_.factor(K0p);
            } catch (const InvalidInput& e) {
                throw InvalidInput(
                    std::string("the elastic operator regularized by the contact penalty "
                                "is singular: some rigid-body motion is held neither by "
                                "supports nor by the contact candidates (add a support, "
                                "or widen the contact region); ") +
                    e.what());
            }
        }
        const Eigen::MatrixXd Lcc = chol_.trailing_block(nc);
        Eigen::MatrixXd X = Eigen::MatrixXd::Zero(nc, m_);
        for (int i = 0; i < B_.outerSize(); ++i)
            for (SparseMatrix::InnerIterator it(B_, i); it; ++it)
                X(newpos_[static_cast<size_t>(it.col())] - ni, i) = it.value();
        {
            // The set-up's large dense products: worth Eigen's threads.
            const parallel::EigenThreadsScope eigen_threads;
            Lcc.triangularView<Eigen::Lower>().solveInPlace(X);
            S_.noalias() = X.transpose() * X;
        }
        // From here on displacement vectors live in the factor's (permuted) numbering.
        std::vector<Triplet> bp;
        for (int i = 0; i < B_.outerSize(); ++i)
            for (SparseMatrix::InnerIterator it(B_, i); it; ++it)
                bp.emplace_back(i, newpos_[static_cast<size_t>(it.col())], it.value());
        B_.setZero();
        B_.setFromTriplets(bp.begin(), bp.end());
        setup_seconds_ = wall_seconds() - t0;
        bu_.resize(nu);
        du_.resize(nu);
        sys_.resize(m_, m_);
        rhs_.resize(m_);
        bl_.resize(m_);
    }

    using BasicNewtonSystemSolver<dim>::solve;
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double) override {
        const double t0 = wall_seconds();
        const BasicLevel<dim>& L = level_;
        const Index nu = static_cast<Index>(dof_of_u_.size());
        for (Index k = 0; k < nu; ++k)
            bu_[newpos_[static_cast<size_t>(k)]] = b[dof_of_u_[static_cast<size_t>(k)]];
        chol_.solve(bu_, du_);
        const Eigen::VectorXd w = B_ * du_;
        if constexpr (dim == 3) {
            // 3D slip's M is no projector (M^2 != M): the general reduction.
            for (size_t e = 0; e < L.contacts.size(); ++e)
                if ((M[e] * M[e] - M[e]).norm() > 1e-12 * (1.0 + M[e].norm()))
                    return solve_general(M, b, w, dx, t0);
        }
        // Reduced system on the contact components (M is a projector, M^2 = M, so the 2m x 2m
        // system [I + S D1, S D2; D2, D3] of the header collapses): with y = r (M - I) z + M dl,
        //   (S - (I - M) / r) y = w - M b_lambda,  z = w - S y,  dl = y + r (z - b_lambda).
        sys_ = S_;
        for (size_t e = 0; e < L.contacts.size(); ++e) {
            const auto& el = L.contacts[e];
            const int me = el.n_multipliers(), c = comp_[e], q0 = me == dim ? 0 : dim - 1;
            const Eigen::MatrixXd Me = M[e].block(q0, q0, me, me);
            sys_.block(c, c, me, me) -= (Eigen::MatrixXd::Identity(me, me) - Me) / el.r;
            for (int q = 0; q < me; ++q)
                bl_[c + q] = b[L.lambda_dof[e] + q];
            rhs_.segment(c, me) = w.segment(c, me) - Me * bl_.segment(c, me);
        }
        lu_.compute(sys_);
        const Eigen::VectorXd y = lu_.solve(rhs_);
        const Eigen::VectorXd z = w - S_ * y;
        bu_ -= B_.transpose() * y;
        chol_.solve(bu_, du_);
        return finish(b, dx, t0, [&](size_t e, int q) {
            return y[comp_[e] + q] + L.contacts[e].r * (z[comp_[e] + q] - bl_[comp_[e] + q]);
        });
    }
    std::string name() const override { return "schur"; }

private:
    /// The reduction for any M (3D slip): with y = r (M - I) z + M dl and z = B du = w - S y,
    ///   [I + r (M - I) S,  -M         ] [y ]   [r (M - I) w]
    ///   [-M S,             (M - I) / r] [dl] = [b_l - M w  ],
    /// a dense system of twice the contact components, then du = K0^{-1} (b_u - B^T y).
    SolveResult solve_general(const std::vector<Matrix>& M, const Vector& b,
                              const Eigen::VectorXd& w, Vector& dx, double t0) {
        const BasicLevel<dim>& L = level_;
        Eigen::MatrixXd Mb = Eigen::MatrixXd::Zero(m_, m_), Mr = Eigen::MatrixXd::Zero(m_, m_);
        Eigen::MatrixXd A22 = Eigen::MatrixXd::Zero(m_, m_);
        for (size_t e = 0; e < L.contacts.size(); ++e) {
            const auto& el = L.contacts[e];
            const int me = el.n_multipliers(), c = comp_[e], q0 = me == dim ? 0 : dim - 1;
            const Eigen::MatrixXd Me = M[e].block(q0, q0, me, me);
            const Eigen::MatrixXd Ie = Eigen::MatrixXd::Identity(me, me);
            Mb.block(c, c, me, me) = Me;
            Mr.block(c, c, me, me) = el.r * (Me - Ie);
            A22.block(c, c, me, me) = (Me - Ie) / el.r;
            for (int q = 0; q < me; ++q)
                bl_[c + q] = b[L.lambda_dof[e] + q];
        }
        // Mb and Mr are block diagonal (one block per element): their products with S are
        // formed block row by block row, O(m^2) rather than a dense O(m^3) product.
        Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * m_, 2 * m_);
        for (size_t e = 0; e < L.contacts.size(); ++e) {
            const int me = L.contacts[e].n_multipliers(), c = comp_[e];
            A.block(c, 0, me, m_).noalias() = Mr.block(c, c, me, me) * S_.middleRows(c, me);
            A.block(m_ + c, 0, me, m_).noalias() = -Mb.block(c, c, me, me) * S_.middleRows(c, me);
        }
        A.topLeftCorner(m_, m_).diagonal().array() += 1.0;
        A.topRightCorner(m_, m_) = -Mb;
        A.bottomRightCorner(m_, m_) = A22;
        Eigen::VectorXd rhs(2 * m_);
        rhs.head(m_) = Mr * w;
        rhs.tail(m_) = bl_ - Mb * w;
        const Eigen::VectorXd sol = Eigen::PartialPivLU<Eigen::MatrixXd>(A).solve(rhs);
        const Eigen::VectorXd y = sol.head(m_);
        bu_ -= B_.transpose() * y;
        chol_.solve(bu_, du_);
        return finish(b, dx, t0, [&](size_t e, int q) { return sol[m_ + comp_[e] + q]; });
    }

    /// dx from du_ (the factor's numbering) and the multiplier increments `dl(e, q)`, and the
    /// solve's result (started at t0).
    template <class Dl>
    SolveResult finish(const Vector& b, Vector& dx, double t0, Dl&& dl) {
        const BasicLevel<dim>& L = level_;
        const Index nu = static_cast<Index>(dof_of_u_.size());
        dx.setZero(b.size());
        for (Index k = 0; k < nu; ++k)
            dx[dof_of_u_[static_cast<size_t>(k)]] = du_[newpos_[static_cast<size_t>(k)]];
        for (size_t e = 0; e < L.contacts.size(); ++e)
            for (int q = 0; q < L.contacts[e].n_multipliers(); ++q)
                dx[L.lambda_dof[e] + q] = dl(e, q);
        SolveResult res;
        res.converged = dx.allFinite();
        res.reason = res.converged ? StopReason::converged : StopReason::breakdown;
        if (!res.converged) res.message = "the condensed contact system is singular";
        res.setup_seconds = first_ ? setup_seconds_ : 0.0;
        first_ = false;
        res.solve_seconds = wall_seconds() - t0;
        res.initial_residual = b.norm();
        return res;
    }

    const BasicLevel<dim>& level_;
    std::vector<int> u_of_dof_, dof_of_u_;
    std::vector<int> newpos_;   ///< compact displacement index -> position in the factor
    std::vector<int> comp_;     ///< first contact component of each element
    std::vector<double> rdiag_; ///< r per component
    Index m_ = 0;               ///< number of contact components
    SparseMatrix B_;
    solvers::SparseCholesky chol_;
    Eigen::MatrixXd S_, sys_;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
    Eigen::VectorXd bu_, du_, rhs_, bl_;
    double setup_seconds_ = 0.0;
    bool first_ = true;
};

} // namespace

std::unique_ptr<LinearSolver> make_sparse_lu_solver() {
    return std::make_unique<SparseLUSolver>();
}

std::unique_ptr<NewtonSystemSolver>
make_assembled_system_solver(const Level& level, std::unique_ptr<LinearSolver> solver) {
    return std::make_unique<AssembledSystemSolver<2>>(level, std::move(solver));
}

std::unique_ptr<NewtonSystemSolver3>
make_assembled_system_solver(const Level3& level, std::unique_ptr<LinearSolver> solver) {
    return std::make_unique<AssembledSystemSolver<3>>(level, std::move(solver));
}

std::unique_ptr<NewtonSystemSolver> make_schur_system_solver(const Level& level) {
    return std::make_unique<SchurSystemSolver<2>>(level);
}

std::unique_ptr<NewtonSystemSolver3> make_schur_system_solver(const Level3& level) {
    return std::make_unique<SchurSystemSolver<3>>(level);
}

void LinearSolverSpec::validate() const {
    MLC_CHECK(method != solvers::Method::krylov || pc.entry != nullptr,
              "a Krylov solve without a preconditioner spec");
    MLC_CHECK(rel_tol > 0 && rel_tol < 1, "linear rel_tol must lie in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "linear max_iter must be >= 1, found " << max_iter);
    MLC_CHECK(restart >= 1, "GMRES restart must be >= 1, found " << restart);
}

solvers::KrylovParams LinearSolverSpec::krylov_params() const {
    solvers::KrylovParams kp;
    kp.rel_tol = rel_tol;
    kp.max_iter = max_iter;
    kp.restart = restart;
    kp.give_up_budget = give_up_budget;
    kp.validate();
    return kp;
}

std::ostream& operator<<(std::ostream& os, const LinearSolverSpec& s) {
    if (s.method != solvers::Method::krylov) return os << s.method;
    return os << s.krylov << " + " << s.pc << " (rel_tol " << s.rel_tol << ", max_iter "
              << s.max_iter << ")";
}

std::unique_ptr<NewtonSystemSolver> make_newton_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const LevelBelow* below) {
    spec.validate();
    if (spec.method == solvers::Method::schur) return make_schur_system_solver(level);
    if (spec.method == solvers::Method::lu)
        return make_assembled_system_solver(level, make_sparse_lu_solver());
    return make_krylov_system_solver(level, spec, below);
}

} // namespace mlc::levels
