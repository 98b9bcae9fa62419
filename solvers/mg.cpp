// SPDX-License-Identifier: MIT
// Geometric multigrid V-cycle with a vertex-block Gauss–Seidel smoother, and PCG.
#include "solvers/mg.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/timer.hpp"
#include "smoothers/matrix_checks.hpp"
#include "solvers/direct.hpp"
#include "solvers/lattice_transfer.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace mlc::solvers {

// ---------------------------------------------------------------------------------------------
void MultigridParams::validate() const {
    MLC_CHECK(pre_sweeps >= 0, "mg: pre must be >= 0, found " << pre_sweeps);
    MLC_CHECK(post_sweeps >= 0, "mg: post must be >= 0, found " << post_sweeps);
    MLC_CHECK(pre_sweeps + post_sweeps >= 1, "mg: pre + post must be >= 1 (no smoothing at all)");
    MLC_CHECK(omega > 0.0 && omega < 2.0, "mg: omega must be in (0, 2), found " << omega);
    MLC_CHECK(cycles == 1 || cycles == 2,
              "mg: cycles must be 1 (V-cycle) or 2 (W-cycle), found " << cycles);
    MLC_CHECK(smoother == Smoother::block || precision == Precision::float64,
              "mg: smoother=lattice keeps double data; precision=single is for smoother=block");
}

std::string cycle_text(const MultigridParams& p) {
    return std::string(p.cycles == 2 ? "W(" : "V(") + std::to_string(p.pre_sweeps) + "," +
           std::to_string(p.post_sweeps) + ")";
}

std::ostream& operator<<(std::ostream& os, const MultigridParams& p) {
    return os << "MultigridParams{pre=" << p.pre_sweeps << ", post=" << p.post_sweeps
              << ", omega=" << p.omega << ", precision=" << to_string(p.precision) << ", smoother="
              << (p.smoother == MultigridParams::Smoother::lattice ? "lattice" : "block")
              << (p.cycles == 2 ? ", cycles=2" : "") << "}";
}

namespace {
// The cycle's smoother: vertex-block Gauss–Seidel in threaded parts with the unrolled kernel
// (params validated first, so that a bad omega is reported as the multigrid's).
smoothers::BlockSORParams smoother_params(const MultigridParams& params,
                                          std::vector<Index> block_starts) {
    params.validate();
    return {.omega = params.omega,
            .block_size = 2,
            .block_starts = std::move(block_starts),
            .parts = 0,
            .kernel = smoothers::Kernel::unrolled,
            .precision = params.precision};
}
} // namespace

// One level: on level 0 the coarse solve; above it the transfer from the level below, the
// smoother and the work vectors of the cycle.
struct Multigrid::Level final : CycleOperator, CycleSmoother, CycleTransfer {
    Level(const MultigridLevelData& d, const MultigridParams& p)
        : T(d.T), R(d.R), T_storage(d.T_storage), R_storage(d.R_storage), lattice_rows(d.lattice),
          params(p), smoother(smoother_params(p, d.block_starts)) {
        if (T && p.smoother == MultigridParams::Smoother::lattice && d.lattice &&
            d.lattice->n >= kMinLatticeSubdivisions)
            lattice = std::make_unique<smoothers::LatticeGS>(
                d.block_starts, *d.lattice, smoothers::LatticeGSParams{.omega = p.omega});
        if (T && p.precision == Precision::float32) {
            round_values(*T, T32, "mg:precision=single (prolongation)");
            round_values(*R, R32, "mg:precision=single (restriction)");
        }
    }
    const SparseMatrix* T = nullptr;
    const SparseMatrix* R = nullptr;
    std::shared_ptr<const SparseMatrix> T_storage, R_storage;   // owned transfers, or null
    std::shared_ptr<const smoothers::LatticeRows> lattice_rows; // the level's lattice, or null
    parallel::UninitializedVector<float> T32, R32; // float32: T's and R's values, rounded
    MultigridParams params;
    smoothers::BlockSOR smoother;                  // levels >= 1
    std::unique_ptr<smoothers::LatticeGS> lattice; // mg:smoother=lattice: used instead
    // mg:smoother=lattice with the level below numbered by lattices too: T and R through the
    // lattice (the same values as csr_multiply).
    std::unique_ptr<LatticeTransfer> lattice_transfer;
    void link_lattice_transfer(const Level& below) {
        if (lattice && below.lattice_rows && lattice_rows && !lattice_rows->first_row.empty() &&
            LatticeTransfer::applies(*lattice_rows, *below.lattice_rows))
            lattice_transfer =
                std::make_unique<LatticeTransfer>(*T, *R, *lattice_rows, *below.lattice_rows);
    }
    std::unique_ptr<Preconditioner> coarse; // level 0
    bool coarse_replaced = false;           // level 0: set_coarse_solver was called
    const SparseMatrix* A = nullptr;        // the operator (borrowed, or `owned`)
    SparseMatrix owned;                     // Galerkin operator
    mutable Vector res, rc, ec;             // levels >= 1
    mutable Vector rw, ew;                  // levels >= 2 of a W-cycle: the second coarse cycle

    bool single() const { return params.precision == Precision::float32; }

    // res = r - A z (with the smoother's float32 values under precision=single).
    void residual(const Vector& r, const Vector& z, Vector& out) const override {
        if (single()) {
            csr_residual(csr_arrays(*A, smoother.values32()), r, z, out, traffic::Kind::matvec);
            return;
        }
        const traffic::Pass pass(traffic::Kind::matvec,
                                 traffic::csr_bytes(A->rows(), A->cols(), A->nonZeros(), true));
        csr_residual_in_order(*A, r, z, out);
    }
    void forward_from_zero(const Vector& r, Vector& z, Vector& out) const override {
        if (lattice)
            lattice->forward_from_zero(r, z, out);
        else
            smoother.forward_from_zero(r, z, out);
    }
    void smooth(const Vector& r, Vector& z, smoothers::Sweep direction, int count) const override {
        if (lattice) {
            lattice->smooth(r, z, direction, count);
            return;
        }
        for (int s = 0; s < count; ++s)
            smoother.sweep(r, z, direction);
    }
    void restrict_residual(const Vector& x, Vector& y) const override {
        if (single())
            csr_multiply(csr_arrays(*R, R32.data()), x, y, false, traffic::Kind::transfer);
        else if (lattice_transfer)
            lattice_transfer->restrict_residual(x, y);
        else
            csr_multiply(*R, x, y, false, traffic::Kind::transfer);
    }
    void prolongate(const Vector& e, Vector& z, bool add) const override {
        if (single())
            csr_multiply(csr_arrays(*T, T32.data()), e, z, add, traffic::Kind::transfer);
        else if (lattice_transfer)
            lattice_transfer->prolongate(e, z, add);
        else
            csr_multiply(*T, e, z, add, traffic::Kind::transfer);
    }

    // Full setup (`full`) or a refresh reusing the structure; the first call is always full.
    void set(const SparseMatrix& M, bool full) {
        if (!T) { // level 0
            const bool first = A == nullptr;
            A = &M;
            if (coarse_replaced) return;
            if (full || first)
                coarse->setup(M);
            else
                coarse->update_values(M);
            return;
        }
        MLC_CHECK(M.rows() == T->rows(), "Multigrid: the operator has "
                                             << M.rows() << " rows, the prolongation "
                                             << T->rows());
        if (full || A == nullptr || res.size() != M.rows()) {
            A = &M;
            if (lattice)
                lattice->setup(M);
            else
                smoother.setup(M);
            res.resize(M.rows());
            rc.resize(R->rows());
            ec.resize(R->rows());
        } else {
            A = &M;
            if (lattice)
                lattice->update_values(M);
            else
                smoother.update_values(M);
        }
    }
};

Multigrid::Multigrid(std::vector<MultigridLevelData> levels, MultigridParams params,
                     CoarseOperators coarse_operators)
    : coarse_operators_(coarse_operators) {
    params.validate();
    MLC_CHECK(levels.size() >= 2,
              "Multigrid: " << levels.size() << " level(s) given, at least two needed");
    for (size_t k = 0; k < levels.size(); ++k) {
        const MultigridLevelData& d = levels[k];
        if (k == 0) {
            MLC_CHECK(d.T == nullptr && d.R == nullptr,
                      "Multigrid: the coarsest level has no level below (T and R must be null)");
        } else {
            MLC_CHECK(d.T != nullptr && d.R != nullptr,
                      "Multigrid: level " << k << " needs T and R");
            MLC_CHECK(d.R->rows() == d.T->cols() && d.R->cols() == d.T->rows(),
                      "Multigrid: level " << k << ": R is " << d.R->rows() << " x " << d.R->cols()
                                          << ", T is " << d.T->rows() << " x " << d.T->cols()
                                          << " (R must be coarse x fine)");
            if (k >= 2)
                MLC_CHECK(d.T->cols() == levels[k - 1].T->rows(),
                          "Multigrid: level " << k << "'s prolongation has " << d.T->cols()
                                              << " columns, level " << k - 1 << " "
                                              << levels[k - 1].T->rows() << " rows");
        }
        auto L = std::make_shared<Level>(d, params);
        if (k == 0) L->coarse = std::make_unique<SparseLUPreconditioner>();
        if (k > 0) L->link_lattice_transfer(*levels_.back());
        levels_.push_back(std::move(L));
    }
}

std::unique_ptr<Multigrid> Multigrid::above(const Multigrid& below, MultigridLevelData top,
                                            MultigridParams params) {
    params.validate();
    MLC_CHECK(top.T != nullptr && top.R != nullptr,
              "Multigrid::above: the new level needs T and R");
    const Level& under = *below.levels_.back();
    const Index under_rows = under.T ? under.T->rows() : (under.A ? under.A->rows() : -1);
    MLC_CHECK(top.R->rows() == top.T->cols() && top.R->cols() == top.T->rows() &&
                  (under_rows < 0 || top.T->cols() == under_rows),
              "Multigrid::above: T is " << top.T->rows() << " x " << top.T->cols() << ", R is "
                                        << top.R->rows() << " x " << top.R->cols()
                                        << ", the level below has " << under_rows << " rows");
    MLC_CHECK(below.coarse_operators_ == CoarseOperators::rediscretized,
              "Multigrid::above: only rediscretized multigrids share their levels");
    std::unique_ptr<Multigrid> mg(new Multigrid());
    mg->levels_ = below.levels_;
    auto L = std::make_shared<Level>(top, params);
    L->link_lattice_transfer(under);
    mg->levels_.push_back(std::move(L));
    return mg;
}

void Multigrid::set_operator(int k, const SparseMatrix& A) {
    MLC_CHECK(k >= 0 && k + 1 < n_levels(), "Multigrid::set_operator: level "
                                                << k << " is not below the finest ("
                                                << n_levels() - 1 << "); use setup for it");
    MLC_CHECK(coarse_operators_ == CoarseOperators::rediscretized,
              "Multigrid::set_operator: the coarse operators are Galerkin products");
    levels_[static_cast<size_t>(k)]->set(A, false);
}

void Multigrid::set_coarse_solver(std::unique_ptr<Preconditioner> coarse) {
    MLC_CHECK(coarse != nullptr, "Multigrid::set_coarse_solver: null solver");
    Level& L0 = *levels_.front();
    L0.coarse = std::move(coarse);
    L0.coarse_replaced = true;
}

void Multigrid::set_galerkin_operators(const SparseMatrix& A) {
    // A_{k-1} = R_k A_k T_k from the finest down; then the levels set up from level 0 up.
    if (galerkin_values_.empty()) {
        // Once: is R = T^T on every level (then update_values may refresh incrementally)?
        galerkin_symmetric_ = true;
        for (size_t k = levels_.size() - 1; k >= 1 && galerkin_symmetric_; --k) {
            const Level& L = *levels_[k];
            const SparseMatrix Tt = L.T->transpose();
            galerkin_symmetric_ = Tt.nonZeros() == L.R->nonZeros() && (Tt - *L.R).norm() == 0.0;
        }
    }
    galerkin_values_.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
    const SparseMatrix* Ak = &A;
    for (size_t k = levels_.size() - 1; k >= 1; --k) {
        const Level& L = *levels_[k];
        Level& below = *levels_[k - 1];
        const SparseMatrix RA = *L.R * (*Ak);
        below.owned = RA * *L.T;
        below.owned.makeCompressed();
        Ak = &below.owned;
    }
    for (size_t k = 0; k + 1 < levels_.size(); ++k)
        levels_[k]->set(levels_[k]->owned, true);
}

void Multigrid::setup(const SparseMatrix& A) {
    if (coarse_operators_ == CoarseOperators::galerkin) set_galerkin_operators(A);
    levels_.back()->set(A, true);
}

namespace {
/// One changed entry of an operator: row, column, change.
struct Change {
    Index i, j;
    double d;
};
} // namespace

// Adds R_k (A_k - A_k,last) T_k into each coarse operator, finest down; false (the caller forms
// the products) when R is not T^T, A's pattern is not the one of the last products, more than a
// tenth of its entries changed, or a coarse entry is missing from the stored pattern.
bool Multigrid::refresh_galerkin_operators(const SparseMatrix& A) {
    if (!galerkin_symmetric_ || A.nonZeros() != static_cast<Index>(galerkin_values_.size()) ||
        !A.isCompressed())
        return false;
    for (size_t k = 0; k + 1 < levels_.size(); ++k)
        if (!levels_[k]->A) return false;
    std::vector<Change> d;
    const double* v = A.valuePtr();
    for (Index i = 0; i < A.outerSize(); ++i)
        for (Index p = A.outerIndexPtr()[i]; p < A.outerIndexPtr()[i + 1]; ++p)
            if (v[p] != galerkin_values_[static_cast<size_t>(p)]) {
                d.push_back(
                    {i, A.innerIndexPtr()[p], v[p] - galerkin_values_[static_cast<size_t>(p)]});
                if (d.size() * 10 > galerkin_values_.size()) return false;
            }
    // Level by level: D_{k-1} = T_k^T D_k T_k, added into the stored coarse operator (whose
    // pattern holds it: the pattern of R A T contains that of R D T when D's is within A's).
    std::vector<std::vector<Change>> per_level(levels_.size());
    per_level.back() = std::move(d);
    for (size_t k = levels_.size() - 1; k >= 1; --k) {
        const SparseMatrix& T = *levels_[k]->T;
        std::vector<Change> c;
        for (const Change& e : per_level[k])
            for (SparseMatrix::InnerIterator a(T, e.i); a; ++a)
                for (SparseMatrix::InnerIterator b(T, e.j); b; ++b)
                    c.push_back({a.col(), b.col(), a.value() * e.d * b.value()});
        std::sort(c.begin(), c.end(), [](const Change& x, const Change& y) {
            return x.i != y.i ? x.i < y.i : x.j < y.j;
        });
        std::vector<Change> merged;
        for (const Change& e : c)
            if (!merged.empty() && merged.back().i == e.i && merged.back().j == e.j)
                merged.back().d += e.d;
            else
                merged.push_back(e);
        // Check first that every entry exists (no insertion into a compressed matrix).
        SparseMatrix& B = levels_[k - 1]->owned;
        std::vector<Index> where(merged.size());
        for (size_t q = 0; q < merged.size(); ++q) {
            const int* b = B.innerIndexPtr() + B.outerIndexPtr()[merged[q].i];
            const int* e = B.innerIndexPtr() + B.outerIndexPtr()[merged[q].i + 1];
            const int* f = std::lower_bound(b, e, static_cast<int>(merged[q].j));
            if (f == e || *f != merged[q].j) return false;
            where[q] = f - B.innerIndexPtr();
        }
        for (size_t q = 0; q < merged.size(); ++q)
            B.valuePtr()[where[q]] += merged[q].d;
        per_level[k - 1] = std::move(merged);
    }
    galerkin_values_.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
    for (size_t k = 0; k + 1 < levels_.size(); ++k)
        levels_[k]->set(levels_[k]->owned, false);
    ++galerkin_refreshes_;
    return true;
}

void Multigrid::update_values(const SparseMatrix& A) {
    if (coarse_operators_ == CoarseOperators::galerkin && !refresh_galerkin_operators(A))
        set_galerkin_operators(A);
    levels_.back()->set(A, false);
}

CycleLevel Multigrid::cycle_level(int k) const {
    const Level& L = *levels_[static_cast<size_t>(k)];
    MLC_CHECK(L.A != nullptr, "Multigrid: the operator of level " << k << " is not set");
    return {L,     L,    L,    L.params.pre_sweeps, L.params.post_sweeps,
            L.res, L.rc, L.ec, L.params.cycles,     &L.rw,
            &L.ew};
}

void Multigrid::coarse_solve(const Vector& r, Vector& z) const {
    const Level& L = *levels_.front();
    MLC_CHECK(L.A != nullptr || L.coarse_replaced, "Multigrid: the coarsest operator is not set");
    const traffic::Pass pass(traffic::Kind::coarse, 0.0);
    L.coarse->apply(r, z);
}

void Multigrid::apply(const Vector& r, Vector& z) const {
    const Level& top = *levels_.back();
    MLC_CHECK(top.A != nullptr, "Multigrid: call setup first");
    smoothers::check_size(r, top.A->rows(), "Multigrid::apply", "r");
    VCycle::cycle(n_levels() - 1, r, z);
}

const SparseMatrix* Multigrid::finest_operator() const {
    return levels_.back()->A;
}

std::unique_ptr<LinearOperator> Multigrid::krylov_operator(const SparseMatrix& A) const {
    if (const smoothers::LatticeGS* lattice = finest_lattice())
        return std::make_unique<smoothers::LatticeOperator>(*lattice);
    return std::make_unique<MatrixOperator>(A, MatVec::unrolled);
}

const smoothers::LatticeGS* Multigrid::finest_lattice() const {
    const Level& top = *levels_.back();
    return top.A != nullptr ? top.lattice.get() : nullptr;
}

std::string Multigrid::name() const {
    const MultigridParams& p = levels_.back()->params;
    std::ostringstream os;
    os << "mg(pre=" << p.pre_sweeps << ",post=" << p.post_sweeps << ",omega=" << p.omega;
    if (p.cycles == 2) os << ",cycle=W";
    if (p.precision == Precision::float32) os << ",precision=single";
    if (p.smoother == MultigridParams::Smoother::lattice) os << ",smoother=lattice";
    os << ")";
    return os.str();
}

MultigridReport Multigrid::report() const {
    MultigridReport r;
    double nnz = 0, rows = 0;
    for (size_t k = 0; k < levels_.size(); ++k) {
        const Level& L = *levels_[k];
        MultigridLevelReport row;
        row.level = static_cast<int>(k);
        row.rows = L.A ? L.A->rows() : (L.T ? L.T->rows() : 0);
        row.nonzeros = L.A ? L.A->nonZeros() : 0;
        row.solve = k == 0      ? L.coarse->name()
                    : L.lattice ? "smoother (lattice, " + std::to_string(L.lattice->deep_points()) +
                                      " deep and " + std::to_string(L.lattice->semi_deep_points()) +
                                      " semi-deep points)"
                                : "smoother";
        nnz += static_cast<double>(row.nonzeros);
        rows += static_cast<double>(row.rows);
        r.levels.push_back(row);
    }
    const auto& top = r.levels.back();
    r.operator_complexity = top.nonzeros > 0 ? nnz / static_cast<double>(top.nonzeros) : 0.0;
    r.grid_complexity = top.rows > 0 ? rows / static_cast<double>(top.rows) : 0.0;
    const MultigridParams& p = levels_.back()->params;
    std::ostringstream cyc;
    cyc << cycle_text(p) << ", omega = " << p.omega;
    r.cycle = cyc.str();
    std::ostringstream sm;
    sm << "vertex-block Gauss-Seidel, forward before / backward after, " << smoothers::kHybridParts
       << " threaded parts";
    if (p.precision == Precision::float32)
        sm << ", single-precision matrices, block inverses and transfers";
    if (p.smoother == MultigridParams::Smoother::lattice)
        sm << "; structured kernels on the macro triangles' interiors (smoother=lattice) on the "
              "levels marked lattice";
    if (std::any_of(levels_.begin(), levels_.end(),
                    [](const auto& L) { return L->lattice_transfer != nullptr; }))
        sm << "; between two such levels the transfers through the lattice too";
    r.smoother = sm.str();
    const Level& L0 = *levels_.front();
    r.coarse_solver =
        L0.coarse_replaced ? L0.coarse->name() + " (the coarse LU was singular)" : "sparse LU";
    const bool aggregates = levels_.size() >= 2 && levels_[1]->T_storage != nullptr;
    r.coarse_operators = coarse_operators_ != CoarseOperators::galerkin ? "rediscretized"
                         : aggregates ? "Galerkin (R A T) on vertex aggregates"
                                      : "Galerkin (R A T)";
    return r;
}

std::ostream& operator<<(std::ostream& os, const MultigridReport& r) {
    os << "multigrid  " << r.levels.size() << " levels, " << r.cycle << ", coarse operators "
       << r.coarse_operators << "\n";
    os << "  level        rows     nonzeros  solve\n";
    for (auto it = r.levels.rbegin(); it != r.levels.rend(); ++it)
        os << "  " << std::setw(5) << it->level << "  " << std::setw(10) << it->rows << "  "
           << std::setw(11) << it->nonzeros << "  " << it->solve << "\n";
    os << "  operator complexity " << std::fixed << std::setprecision(3) << r.operator_complexity
       << ", grid complexity " << r.grid_complexity << std::defaultfloat << "\n";
    os << "  smoother " << r.smoother << "; coarse solve " << r.coarse_solver << "\n";
    return os;
}

// ---------------------------------------------------------------------------------------------
// ---------------------------------------------------------------------------------------------

std::vector<Index> vertex_block_starts(const std::vector<int>& vertex_of_dof) {
    std::vector<Index> starts;
    for (size_t i = 0; i < vertex_of_dof.size(); ++i)
        if (i == 0 || vertex_of_dof[i] != vertex_of_dof[i - 1])
            starts.push_back(static_cast<Index>(i));
    return starts;
}

} // namespace mlc::solvers
