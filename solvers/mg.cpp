// SPDX-License-Identifier: MIT
// Geometric multigrid V-cycle with a vertex-block Gauss–Seidel smoother, and PCG.
#include "solvers/mg.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "smoothers/matrix_checks.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlc::solvers {

namespace {
constexpr Index kMaxBlock = 16; // largest diagonal block of the smoother (a vertex has <= 4)

int max_threads() {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

} // namespace

// ---------------------------------------------------------------------------------------------
BlockGaussSeidel::BlockGaussSeidel(std::vector<Index> block_starts, double omega, int parts)
    : starts_(std::move(block_starts)), omega_(omega), parts_requested_(parts) {
    MLC_CHECK(omega > 0.0 && omega < 2.0,
              "BlockGaussSeidel: omega must be in (0, 2), found " << omega);
    MLC_CHECK(parts >= 0, "BlockGaussSeidel: parts must be >= 0, found " << parts);
}

void BlockGaussSeidel::split_parts() {
    const SparseMatrix& A = *A_;
    const Index n = A.rows();
    const Index nb = static_cast<Index>(starts_.size()) - 1;
    const Index want = parts_requested_ > 0 ? parts_requested_ : max_threads();
    const Index P =
        std::clamp<Index>(std::min(want, n / kMinRowsPerPart), 1, std::max<Index>(nb, 1));
    part_block_.assign(1, 0);
    const int* outer = A.outerIndexPtr();
    const double per_part = static_cast<double>(A.nonZeros()) / static_cast<double>(P);
    for (Index I = 0, p = 1; I < nb && p < P; ++I)
        if (static_cast<double>(outer[starts_[static_cast<size_t>(I) + 1]]) >= per_part * p) {
            part_block_.push_back(I + 1);
            ++p;
        }
    part_block_.push_back(nb);
    // Own-part entry range of every row, and the columns read across a cut.
    const int* inner = A.innerIndexPtr();
    own_begin_.resize(static_cast<size_t>(n));
    own_end_.resize(static_cast<size_t>(n));
    std::vector<char> across(static_cast<size_t>(n), 0);
    for (size_t p = 0; p + 1 < part_block_.size(); ++p) {
        const Index r0 = starts_[static_cast<size_t>(part_block_[p])];
        const Index r1 = starts_[static_cast<size_t>(part_block_[p + 1])];
        for (Index i = r0; i < r1; ++i) {
            const int* b = inner + outer[i];
            const int* e = inner + outer[i + 1];
            const int* lo = std::lower_bound(b, e, static_cast<int>(r0));
            const int* hi = std::lower_bound(lo, e, static_cast<int>(r1));
            own_begin_[static_cast<size_t>(i)] = static_cast<int>(lo - inner);
            own_end_[static_cast<size_t>(i)] = static_cast<int>(hi - inner);
            for (const int* c = b; c < lo; ++c)
                across[static_cast<size_t>(*c)] = 1;
            for (const int* c = hi; c < e; ++c)
                across[static_cast<size_t>(*c)] = 1;
        }
    }
    interface_.clear();
    for (Index j = 0; j < n; ++j)
        if (across[static_cast<size_t>(j)]) interface_.push_back(static_cast<int>(j));
    snap_.setZero(n);
}

void BlockGaussSeidel::setup(const SparseMatrix& A) {
    smoothers::check_setup_matrix(A, "BlockGaussSeidel::setup");
    const Index n = A.rows();
    if (starts_.empty()) {
        for (Index i = 0; i < n; i += 2)
            starts_.push_back(i);
    }
    if (starts_.back() != n) starts_.push_back(n);
    MLC_CHECK(starts_.front() == 0, "BlockGaussSeidel: block starts must begin at 0");
    offset_.assign(starts_.size(), 0);
    Index total = 0;
    for (size_t I = 0; I + 1 < starts_.size(); ++I) {
        const Index b = starts_[I + 1] - starts_[I];
        MLC_CHECK(b >= 1 && b <= kMaxBlock,
                  "BlockGaussSeidel: block " << I << " has " << b << " rows (valid 1.." << kMaxBlock
                                             << ", increasing starts within the matrix)");
        offset_[I] = total;
        total += b * b;
    }
    dinv_.assign(static_cast<size_t>(total), 0.0);
    A_ = &A;
    split_parts();
    find_diagonal_starts();
    nonzeros_ = A.nonZeros();
    invert_blocks();
}

void BlockGaussSeidel::find_diagonal_starts() {
    const SparseMatrix& A = *A_;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    diag_begin_.resize(static_cast<size_t>(A.rows()));
    for (size_t I = 0; I + 1 < starts_.size(); ++I)
        for (Index i = starts_[I]; i < starts_[I + 1]; ++i)
            diag_begin_[static_cast<size_t>(i)] = static_cast<int>(
                std::lower_bound(inner + outer[i], inner + outer[i + 1], starts_[I]) - inner);
}

void BlockGaussSeidel::forward_from_zero(const Vector& b, Vector& x, Vector& res) const {
    MLC_CHECK(A_ != nullptr, "BlockGaussSeidel: call setup first");
    const Index n = A_->rows();
    x.resize(n);
    res.resize(n);
    const int* outer = A_->outerIndexPtr();
    const int* inner = A_->innerIndexPtr();
    const double* val = A_->valuePtr();
    const int* dbeg = diag_begin_.data();
    double* xp = x.data();
    double* rp = res.data();
    const double* bp = b.data();
    // Each part from zero with its own lower entries (the other parts' x count as 0, as they
    // are at the start of the sweep); then the whole residual with the final x: the diagonal
    // and upper entries, and the lower ones of other parts. One part: plain Gauss–Seidel.
    const int P = parts();
#pragma omp parallel for num_threads(P) schedule(static, 1) if (P > 1)
    for (int p = 0; p < P; ++p) {
        for (Index I = part_block_[static_cast<size_t>(p)];
             I < part_block_[static_cast<size_t>(p) + 1]; ++I) {
            const Index s = starts_[static_cast<size_t>(I)],
                        bs = starts_[static_cast<size_t>(I) + 1] - s;
            for (Index i = s; i < s + bs; ++i)
                rp[i] =
                    bp[i] - row_dot(inner, val, xp, own_begin_[static_cast<size_t>(i)], dbeg[i]);
            const double* d = dinv_.data() + offset_[static_cast<size_t>(I)];
            for (Index i = 0; i < bs; ++i) {
                double acc = 0.0;
                for (Index j = 0; j < bs; ++j)
                    acc += d[i * bs + j] * rp[s + j];
                xp[s + i] = acc;
            }
        }
    }
#pragma omp parallel for num_threads(P) schedule(static) if (P > 1)
    for (Index i = 0; i < n; ++i)
        rp[i] -= row_dot(inner, val, xp, dbeg[i], outer[i + 1]) +
                 row_dot(inner, val, xp, outer[i], own_begin_[static_cast<size_t>(i)]);
}

void BlockGaussSeidel::update_values(const SparseMatrix& A) {
    if (A_ == nullptr) {
        setup(A);
        return;
    }
    MLC_CHECK(A.rows() == starts_.back(), "BlockGaussSeidel::update_values: the matrix has "
                                              << A.rows() << " rows, the blocks cover "
                                              << starts_.back() << " (call setup)");
    // The matrix of the last setup, refreshed in place (as JacobianAssembler does): its pattern,
    // parts and diagonal positions stand; any other matrix has them derived anew.
    const bool same_pattern = &A == A_ && A.nonZeros() == nonzeros_;
    A_ = &A;
    if (!same_pattern) {
        split_parts();
        find_diagonal_starts();
        nonzeros_ = A.nonZeros();
    }
    invert_blocks();
}

void BlockGaussSeidel::invert_blocks() {
    const SparseMatrix& A = *A_;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    Eigen::MatrixXd D;
    for (size_t I = 0; I + 1 < starts_.size(); ++I) {
        const Index s = starts_[I], b = starts_[I + 1] - s;
        D.setZero(b, b);
        double scale = 0.0;
        for (Index i = 0; i < b; ++i)
            for (int k = outer[s + i]; k < outer[s + i + 1]; ++k) {
                const Index j = inner[k] - s;
                if (j >= 0 && j < b) D(i, j) = val[k];
                scale = std::max(scale, std::abs(val[k]));
            }
        double* out = dinv_.data() + offset_[I];
        if (b == 2) {
            // Closed form (the common vertex block without multipliers).
            const double det = D(0, 0) * D(1, 1) - D(0, 1) * D(1, 0);
            const double dscale = std::abs(D(0, 0) * D(1, 1)) + std::abs(D(0, 1) * D(1, 0));
            MLC_CHECK(dscale > 0.0 && std::abs(det) > 1e-14 * dscale,
                      "BlockGaussSeidel: diagonal block " << I << " (rows " << s << ".." << s + 1
                                                          << ") is singular");
            const double f = omega_ / det;
            out[0] = f * D(1, 1);
            out[1] = -f * D(0, 1);
            out[2] = -f * D(1, 0);
            out[3] = f * D(0, 0);
            continue;
        }
        Eigen::FullPivLU<Eigen::MatrixXd> lu(D);
        lu.setThreshold(1e-14);
        MLC_CHECK(scale > 0.0 && lu.isInvertible(), "BlockGaussSeidel: diagonal block "
                                                        << I << " (rows " << s << ".." << s + b - 1
                                                        << ") is singular");
        const Eigen::MatrixXd inv = omega_ * lu.inverse();
        for (Index i = 0; i < b; ++i)
            for (Index j = 0; j < b; ++j)
                out[i * b + j] = inv(i, j);
    }
}

void BlockGaussSeidel::sweep_part(const double* bp, double* xp, Index b0, Index b1,
                                  bool forward) const {
    const int* outer = A_->outerIndexPtr();
    const int* inner = A_->innerIndexPtr();
    const double* val = A_->valuePtr();
    const double* sp = snap_.data();
    double res[kMaxBlock];
    for (Index step = b0; step < b1; ++step) {
        const auto I = static_cast<size_t>(forward ? step : b1 - 1 - (step - b0));
        const Index s = starts_[I], bs = starts_[I + 1] - s;
        for (Index i = 0; i < bs; ++i) {
            const auto r = static_cast<size_t>(s + i);
            res[i] = bp[s + i] - row_dot(inner, val, xp, own_begin_[r], own_end_[r]) -
                     row_dot(inner, val, sp, outer[s + i], own_begin_[r]) -
                     row_dot(inner, val, sp, own_end_[r], outer[s + i + 1]);
        }
        const double* d = dinv_.data() + offset_[I];
        for (Index i = 0; i < bs; ++i) {
            double acc = 0.0;
            for (Index j = 0; j < bs; ++j)
                acc += d[i * bs + j] * res[j];
            xp[s + i] += acc;
        }
    }
}

void BlockGaussSeidel::sweep(const Vector& b, Vector& x, bool forward) const {
    MLC_CHECK(A_ != nullptr, "BlockGaussSeidel: call setup first");
    double* xp = x.data();
    double* sp = snap_.data();
    for (const int j : interface_) // empty with one part
        sp[j] = xp[j];
    const int P = parts();
#pragma omp parallel for num_threads(P) schedule(static, 1) if (P > 1)
    for (int p = 0; p < P; ++p)
        sweep_part(b.data(), xp, part_block_[static_cast<size_t>(p)],
                   part_block_[static_cast<size_t>(p) + 1], forward);
}

void BlockGaussSeidel::apply(const Vector& r, Vector& z) const {
    z.setZero(r.size());
    sweep(r, z, true);
}

std::string BlockGaussSeidel::name() const {
    std::ostringstream os;
    os << "bgs(omega=" << omega_ << ")";
    return os.str();
}

// ---------------------------------------------------------------------------------------------
void MultigridParams::validate() const {
    MLC_CHECK(pre_sweeps >= 0, "mg: pre must be >= 0, found " << pre_sweeps);
    MLC_CHECK(post_sweeps >= 0, "mg: post must be >= 0, found " << post_sweeps);
    MLC_CHECK(pre_sweeps + post_sweeps >= 1, "mg: pre + post must be >= 1 (no smoothing at all)");
    MLC_CHECK(omega > 0.0 && omega < 2.0, "mg: omega must be in (0, 2), found " << omega);
}

std::ostream& operator<<(std::ostream& os, const MultigridParams& p) {
    return os << "MultigridParams{pre=" << p.pre_sweeps << ", post=" << p.post_sweeps
              << ", omega=" << p.omega << "}";
}

MultigridCycle::MultigridCycle(const SparseMatrix& T, const SparseMatrix& R, CoarseSolve coarse,
                               std::vector<Index> block_starts, MultigridParams params)
    : T_(T), R_(R), coarse_(std::move(coarse)), smoother_(std::move(block_starts), params.omega),
      params_(params) {
    params_.validate();
    MLC_CHECK(R.rows() == T.cols() && R.cols() == T.rows(),
              "MultigridCycle: R is " << R.rows() << " x " << R.cols() << ", T is " << T.rows()
                                      << " x " << T.cols() << " (R must be coarse x fine)");
}

void MultigridCycle::setup(const SparseMatrix& A) {
    MLC_CHECK(A.rows() == T_.rows(), "MultigridCycle::setup: the matrix has "
                                         << A.rows() << " rows, the prolongation " << T_.rows());
    A_ = &A;
    smoother_.setup(A);
    res_.resize(A.rows());
    rc_.resize(R_.rows());
    ec_.resize(R_.rows());
}

void MultigridCycle::update_values(const SparseMatrix& A) {
    if (A_ == nullptr || res_.size() != A.rows()) {
        setup(A);
        return;
    }
    A_ = &A;
    smoother_.update_values(A);
}

void MultigridCycle::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(A_ != nullptr, "MultigridCycle: call setup first");
    smoothers::check_size(r, A_->rows(), "MultigridCycle::apply", "r");
    MLC_CHECK(static_cast<bool>(coarse_), "MultigridCycle: no coarse solve set");
    if (params_.pre_sweeps == 0) {
        z.setZero(r.size());
        res_ = r;
    } else {
        smoother_.forward_from_zero(r, z, res_);
        for (int k = 1; k < params_.pre_sweeps; ++k)
            smoother_.sweep(r, z, true);
        if (params_.pre_sweeps > 1) {
            res_ = r;
            res_.noalias() -= *A_ * z;
        }
    }
    csr_multiply(R_, res_, rc_);
    coarse_(rc_, ec_);
    csr_multiply(T_, ec_, z, true);
    for (int k = 0; k < params_.post_sweeps; ++k)
        smoother_.sweep(r, z, false);
}

std::string MultigridCycle::name() const {
    std::ostringstream os;
    os << "mg(pre=" << params_.pre_sweeps << ",post=" << params_.post_sweeps
       << ",omega=" << params_.omega << ")";
    return os.str();
}

// ---------------------------------------------------------------------------------------------
// ---------------------------------------------------------------------------------------------
SolveResult pcg(const SparseMatrix& A, const Preconditioner& M, const Vector& b, Vector& x,
                double rel_tol, int max_iter) {
    MLC_CHECK(rel_tol > 0.0 && rel_tol < 1.0, "pcg: rel_tol must be in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "pcg: max_iter must be >= 1, found " << max_iter);
    MLC_CHECK(A.rows() == A.cols() && b.size() == A.rows(),
              "pcg: A is " << A.rows() << " x " << A.cols() << ", b has " << b.size());
    const double t0 = wall_seconds();
    if (x.size() != b.size()) x = Vector::Zero(b.size());
    SolveResult res;
    Vector r = b;
    r.noalias() -= A * x;
    Vector z(b.size()), p(b.size()), q(b.size());
    const MatrixOperator Aop(A, MatVec::unrolled);
    const double bnorm = b.norm();
    const double target = rel_tol * (bnorm > 0 ? bnorm : r.norm());
    res.initial_residual = r.norm();
    double rnorm = res.initial_residual;
    double rz = 0.0;
    int it = 0;
    while (rnorm > target && it < max_iter) {
        M.apply(r, z);
        const double rz_new = r.dot(z);
        if (it == 0)
            p = z;
        else
            p = z + (rz_new / rz) * p;
        rz = rz_new;
        Aop.apply(p, q);
        const double pq = p.dot(q);
        if (!(pq > 0.0) || !std::isfinite(pq)) {
            res.reason = StopReason::breakdown;
            res.message = "p^T A p is not positive";
            break;
        }
        const double alpha = rz / pq;
        x += alpha * p;
        r -= alpha * q;
        rnorm = r.norm();
        ++it;
    }
    r = b;
    r.noalias() -= A * x;
    res.iterations = it;
    res.final_residual = r.norm();
    res.relative_residual = res.final_residual / (bnorm > 0 ? bnorm : res.initial_residual);
    res.converged = res.reason != StopReason::breakdown && rnorm <= target;
    if (res.converged) res.reason = StopReason::converged;
    if (it > 0 && res.initial_residual > 0)
        res.average_rate = std::pow(res.final_residual / res.initial_residual, 1.0 / it);
    res.solve_seconds = wall_seconds() - t0;
    return res;
}

std::vector<Index> vertex_block_starts(const std::vector<int>& vertex_of_dof) {
    std::vector<Index> starts;
    for (size_t i = 0; i < vertex_of_dof.size(); ++i)
        if (i == 0 || vertex_of_dof[i] != vertex_of_dof[i - 1])
            starts.push_back(static_cast<Index>(i));
    return starts;
}

} // namespace mlc::solvers
