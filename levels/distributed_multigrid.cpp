// SPDX-License-Identifier: MIT
// The distributed multigrid: the Newton systems of the distributed levels and their V-cycle.
#include "levels/distributed_multigrid.hpp"

#include "contact/element.hpp"
#include "core/check.hpp"
#include "core/timer.hpp"
#include "levels/krylov_system.hpp"
#include "levels/newton_system.hpp"
#include "levels/resources.hpp"
#include "smoothers/block_sor.hpp"
#include "smoothers/lattice_gs.hpp"
#include "solvers/factory.hpp"
#include "solvers/krylov.hpp"

#include <Eigen/SparseLU>

#include <algorithm>
#include <sstream>

namespace mlc::levels {

/// The Newton systems of the distributed levels and their multigrid (distributed_solve.hpp).
namespace {
/// The pattern of J's diagonal block, K's (`Kd`, compressed, sorted rows) merged row by row
/// with the contact entries of the owned rows (`centries`: (row, column), row -1 for a row
/// owned elsewhere, columns >= n in the off-diagonal block), into `J` (zero values, sorted
/// rows: the pattern setFromTriplets would give, without sorting K's entries again).
/// Returns the position in J of every entry of Kd, in Kd's order.
std::vector<int> merge_diagonal_pattern(const SparseMatrix& Kd,
                                        const std::vector<std::pair<int, int>>& centries,
                                        SparseMatrix& J) {
    const int n = static_cast<int>(Kd.rows());
    std::vector<std::pair<int, int>> dc;
    for (const auto& [r, c] : centries)
        if (r >= 0 && c < n) dc.emplace_back(r, c);
    std::sort(dc.begin(), dc.end());
    dc.erase(std::unique(dc.begin(), dc.end()), dc.end());
    const int* ko = Kd.outerIndexPtr();
    const int* ki = Kd.innerIndexPtr();
    J.resize(n, n);
    int* jo = J.outerIndexPtr();
    jo[0] = 0;
    size_t q = 0;
    for (int i = 0; i < n; ++i) {
        int count = ko[i + 1] - ko[i];
        for (; q < dc.size() && dc[q].first == i; ++q)
            count += !std::binary_search(ki + ko[i], ki + ko[i + 1], dc[q].second);
        jo[i + 1] = jo[i] + count;
    }
    J.resizeNonZeros(jo[n]);
    int* ji = J.innerIndexPtr();
    std::fill_n(J.valuePtr(), jo[n], 0.0);
    std::vector<int> kpos(static_cast<size_t>(ko[n]));
    q = 0;
    for (int i = 0; i < n; ++i) {
        int a = ko[i], out = jo[i];
        while (a < ko[i + 1] || (q < dc.size() && dc[q].first == i)) {
            const bool from_k = a < ko[i + 1];
            const bool from_c = q < dc.size() && dc[q].first == i;
            if (from_k && (!from_c || ki[a] <= dc[q].second)) {
                if (from_c && ki[a] == dc[q].second) ++q;
                kpos[static_cast<size_t>(a)] = out;
                ji[out++] = ki[a++];
            } else {
                ji[out++] = dc[q++].second;
            }
        }
        MLC_ASSERT(out == jo[i + 1], "merged row of the wrong length");
    }
    return kpos;
}
} // namespace

namespace detail {

/// The level and transfer types of the distributed levels in `dim` dimensions.
template <int dim> struct DistributedTypes;
template <> struct DistributedTypes<2> {
    using DLevel = DistributedLevel;
    using DTransfer = DistributedTransfer;
};
template <> struct DistributedTypes<3> {
    using DLevel = DistributedLevel3;
    using DTransfer = DistributedTransfer3;
};

/// The distributed multigrid in `dim` dimensions (DistributedMultigrid in 2D,
/// DistributedMultigrid3 in 3D). 2D: spec's Krylov method and preconditioner (mg, or a
/// preconditioner of each process's diagonal block), the lattice sweep, mg's precision, V-cycles.
/// 3D: mg with vertex-block Gauss-Seidel in double precision, V- or W-cycles, or a
/// preconditioner of the matrix alone on each process's diagonal block.
template <int dim> struct DistributedMultigridCore : solvers::VCycle {
    using DLevel = typename DistributedTypes<dim>::DLevel;
    using DTransfer = typename DistributedTypes<dim>::DTransfer;
    using LevelD = BasicLevel<dim>;
    using Status = StatusMatrix<dim>;

    /// `kp`: the Krylov parameters but the tolerance's forcing and comm (set by solve).
    DistributedMultigridCore(const std::vector<DLevel>& levels,
                             const std::vector<DTransfer>& transfers, const Communicator& comm,
                             LinearSolverSpec spec, solvers::KrylovParams kp,
                             solvers::MultigridParams mg)
        : levels_(levels), transfers_(transfers), comm_(comm), spec_(std::move(spec)), kp_(kp),
          mg_(mg), use_mg_(spec_.pc.name() == "mg"), use_ebe_(spec_.pc.entry->element_matrices),
          op_(levels.size()) {
        if constexpr (dim == 2) {
            MLC_CHECK(mg.cycles == 1,
                      "the distributed multigrid runs V-cycles only, found cycles = " << mg.cycles);
        } else if (!use_mg_) {
            // A preconditioner of each process's diagonal block (the matrix alone).
            const std::string why = spec_.pc.dimension_reason(3);
            MLC_CHECK(why.empty(), why);
            const std::string not_distributed = spec_.pc.distributed();
            MLC_CHECK(not_distributed.empty() && !spec_.pc.entry->level_aware,
                      spec_.pc.text()
                          << " has no form on each process's diagonal block of a 3D level"
                          << (not_distributed.empty() ? "" : ": " + not_distributed));
        } else {
            mg.validate();
            MLC_CHECK(mg.smoother == solvers::MultigridParams::Smoother::block,
                      "the 3D distributed multigrid smooths by vertex blocks only "
                      "(mg:smoother=lattice is 2D)");
            MLC_CHECK(mg.precision == Precision::float64,
                      "the 3D distributed multigrid runs in double precision only "
                      "(mg:precision=single is 2D)");
        }
        for (size_t k = 1; k < levels.size(); ++k) {
            build_jacobian(k);
            transfer_.emplace_back(*transfers[k - 1].T);
        }
    }

    /// Level p at its converged statuses: the gathered coarse solve (map built on first use).
    void set_coarse(const LevelD& Lp, const std::vector<Status>& M) {
        if (!use_mg_) return; // no coarse level without mg
        if (coarse_level_ != &Lp) {
            coarse_level_ = &Lp;
            coarse_asm_ = std::make_unique<BasicJacobianAssembler<dim>>(Lp);
            build_coarse_map(Lp);
            analyzed_ = false;
        }
        coarse_asm_->assemble(M);
        const SparseMatrixCol A = coarse_asm_->matrix();
        if (!analyzed_) {
            lu_.analyzePattern(A);
            analyzed_ = true;
        }
        lu_.factorize(A);
        MLC_CHECK(lu_.info() == Eigen::Success,
                  "the coarse Jacobian of level p is singular (sparse LU failed)");
    }

    /// J_k(M) assembled, its ParCSR values refreshed, the smoother set up on the diagonal block.
    void prepare(size_t k, const std::vector<Status>& M) {
        Op& o = op_[k];
        // Unchanged on every process (the refresh below is collective).
        const bool same = o.prepared && M.size() == o.last_M.size() &&
                          std::equal(M.begin(), M.end(), o.last_M.begin());
        if (comm_.min(same ? 1 : 0) == 1) return;
        // J = K + the contact tangents, in place in J's blocks (hypre's matrix reads them there).
        // The owned rows of J: the tangents of this process's elements and of the ghost elements
        // (other processes' contact nodes reaching owned vertices), whose columns may be other
        // processes' unknowns (the off-diagonal block).
        const DLevel& L = levels_[k];
        const size_t n_el = L.local.contacts.size() + L.local.ghost_contacts.size();
        MLC_CHECK(M.size() == n_el, "internal error: " << M.size() << " status matrices for "
                                                       << n_el << " contact elements");
        double* v = o.blocks->diag.valuePtr();
        std::fill(v, v + o.blocks->diag.nonZeros(), 0.0);
        const double* kv = L.K_blocks->diag.valuePtr();
        for (size_t q = 0; q < o.kpos.size(); ++q)
            v[o.kpos[q]] += kv[q];
        double* vo = o.blocks->offd.valuePtr();
        if (o.kopos.empty()) {
            // The off-diagonal block is K's (no contact coupling across the cuts): copied once.
            if (!o.prepared)
                std::copy_n(L.K_blocks->offd.valuePtr(), L.K_blocks->offd.nonZeros(), vo);
        } else {
            std::fill(vo, vo + o.blocks->offd.nonZeros(), 0.0);
            const double* kov = L.K_blocks->offd.valuePtr();
            for (size_t q = 0; q < o.kopos.size(); ++q)
                vo[o.kopos[q]] += kov[q];
        }
        size_t c = 0;
        auto add = [&](int, int, double value) {
            const Entry& p = o.cpos[c++];
            if (p.block == 0)
                v[p.pos] += value;
            else if (p.block == 1)
                vo[p.pos] += value;
        };
        for (size_t e = 0; e < L.local.contacts.size(); ++e)
            contact::for_each_tangent_entry(L.local.contacts[e], M[e], L.local.dofs,
                                            L.local.lambda_dof[e], add);
        for (size_t e = 0; e < L.local.ghost_contacts.size(); ++e)
            contact::for_each_tangent_entry(L.local.ghost_contacts[e],
                                            M[L.local.contacts.size() + e], L.local.dofs,
                                            L.local.ghost_lambda_dof[e], add);
        if (!use_mg_) {
            if constexpr (dim == 2)
                if (use_ebe_) refresh_block_elements(k, M);
            if (!o.block_pc) {
                // EBE (2D): built from the process's elements restricted to its owned unknowns.
                solvers::LevelData d;
                d.has_multipliers = !L.local.contacts.empty();
                d.elements = [&o]() { return &o.elements; };
                o.block_pc = solvers::make_preconditioner(spec_.pc, use_ebe_ ? &d : nullptr);
                o.block_pc->setup(o.blocks->diag);
            } else {
                o.block_pc->update_values(o.blocks->diag);
            }
            o.last_M = M;
            o.prepared = true;
            return;
        }
        if (!o.smoother && !o.lattice) {
            make_smoother(k);
        } else if (o.lattice) {
            o.lattice->update_values(o.blocks->diag);
        } else {
            o.smoother->update_values(o.blocks->diag);
        }
        o.last_M = M;
        o.prepared = true;
    }

    /// The smoother of level k's diagonal block, set up: mg:smoother=lattice's sweep on a level
    /// with lattice rows of at least solvers::kMinLatticeSubdivisions subdivisions (as on one
    /// process), else vertex-block Gauss-Seidel in mg's precision. One threaded part: each
    /// process sweeps its block in one piece.
    void make_smoother(size_t k) {
        Op& o = op_[k];
        const DLevel& L = levels_[k];
        std::vector<int> vertex_of(static_cast<size_t>(L.n_owned));
        for (Index i = 0; i < L.n_owned; ++i)
            vertex_of[static_cast<size_t>(i)] = L.local.dofs.vertex_of(i);
        std::vector<Index> starts = solvers::vertex_block_starts(vertex_of);
        if constexpr (dim == 2) {
            const auto& rows = L.local.lattice;
            if (mg_.smoother == solvers::MultigridParams::Smoother::lattice && rows &&
                rows->n >= solvers::kMinLatticeSubdivisions) {
                o.lattice = std::make_unique<smoothers::LatticeGS>(
                    std::move(starts), *rows,
                    smoothers::LatticeGSParams{.omega = mg_.omega, .parts = 1});
                o.lattice->setup(o.blocks->diag);
                return;
            }
        }
        o.smoother = std::make_unique<smoothers::BlockSOR>(
            smoothers::BlockSORParams{.omega = mg_.omega,
                                      .block_size = dim,
                                      .block_starts = std::move(starts),
                                      .parts = 1,
                                      .kernel = smoothers::Kernel::unrolled,
                                      .precision = mg_.precision});
        o.smoother->setup(o.blocks->diag);
    }

    SolveResult solve(size_t k, const std::vector<Status>& M, const Vector& b, Vector& dx,
                      double forcing) {
        const double t0 = wall_seconds();
        prepare(k, M);
        const double t1 = wall_seconds();
        solvers::KrylovParams kp = kp_;
        kp.rel_tol = std::max(forcing, kp_.rel_tol);
        kp.comm = &comm_;
        const Cycle cycle(*this, k);
        const BlockPc block(*this, k);
        const Preconditioner& pc = use_mg_ ? static_cast<const Preconditioner&>(cycle) : block;
        // With the lattice sweep, the Krylov product's diagonal block by its structured kernel
        // (as one process multiplies by its finest level's lattice smoother).
        const Op& o = op_[k];
        const LatticeProduct lattice_product(o);
        const LinearOperator& A =
            o.lattice ? static_cast<const LinearOperator&>(lattice_product) : *o.J;
        SolveResult r = solvers::solve(spec_.krylov, A, pc, b, dx, kp);
        r.setup_seconds = t1 - t0;
        r.solve_seconds = wall_seconds() - t1;
        return r;
    }

    /// EBE on the diagonal block: the elastic element matrices of every local triangle
    /// restricted to the owned unknowns (so that they sum to the diagonal block of K; the
    /// triangles cut by the partition contribute their owned rows and columns), then the contact
    /// elements (all at owned vertices) at the statuses M. EBE colours them within the process.
    void refresh_block_elements(size_t k, const std::vector<Status>& M) requires(dim == 2) {
        Op& o = op_[k];
        const DLevel& D = levels_[k];
        if (o.elements.empty()) {
            o.elements = elastic_element_matrices(D.local);
            restrict_elements(o.elements, D.n_owned);
            o.n_elastic = o.elements.size();
            o.elements.resize(o.n_elastic + D.local.contacts.size());
        }
        for (size_t e = 0; e < D.local.contacts.size(); ++e) {
            smoothers::ElementMatrix& el = o.elements[o.n_elastic + e];
            contact_element_matrix(D.local, e, M[e], el);
            for ([[maybe_unused]] const int d : el.dofs)
                MLC_ASSERT(d < D.n_owned, "a contact element outside the owned unknowns");
        }
    }

    std::string name() const {
        std::ostringstream os;
        if (!use_mg_)
            return std::string(solvers::to_string(spec_.krylov)) + " + " + spec_.pc.text() +
                   " on each process's diagonal block";
        os << spec_.krylov << " + distributed mg(pre=" << mg_.pre_sweeps
           << ",post=" << mg_.post_sweeps << ",omega=" << mg_.omega;
        if (mg_.precision == Precision::float32) os << ",precision=single";
        if (mg_.smoother == solvers::MultigridParams::Smoother::lattice) os << ",smoother=lattice";
        if (mg_.cycles == 2) os << ",cycles=2";
        os << ")";
        return os.str();
    }

    struct Entry {
        int pos = 0;
        int block = -1;
    };

    /// One distributed level: its operator (the owned rows of J), the smoother of its diagonal
    /// block (Jacobi across the cuts: the other processes' unknowns held at their values, which
    /// hypre's halo exchange brings) and the cycle's work vectors.
    struct Op final : solvers::CycleOperator, solvers::CycleSmoother {
        /// J's owned rows (the one copy of J: hypre's J and the smoother read them in place).
        std::unique_ptr<solvers::RowBlocks> blocks;
        std::vector<int> kpos; ///< position in blocks->diag of every entry of K's diagonal block
        /// Position of every contact tangent entry, in visiting order (owned elements, then
        /// ghost elements): block 0 diag, 1 offd, -1 a row owned elsewhere (not stored).
        std::vector<Entry> cpos;
        /// Position in blocks->offd of every entry of K's off-diagonal block; empty when J's
        /// off-diagonal block is K's (no contact entry in it).
        std::vector<int> kopos;
        std::unique_ptr<solvers::ParMatrix> J;
        /// The smoother of the diagonal block: the lattice sweep where the level has lattice
        /// rows and mg:smoother=lattice asks for it, else vertex-block Gauss-Seidel.
        std::unique_ptr<smoothers::BlockSOR> smoother;
        std::unique_ptr<smoothers::LatticeGS> lattice;
        std::unique_ptr<Preconditioner> block_pc; ///< without mg: spec.pc on the diagonal block
        /// ebe: the elements of the diagonal block (elastic, restricted; then contact), which
        /// block_pc borrows.
        std::vector<smoothers::ElementMatrix> elements;
        size_t n_elastic = 0;
        std::vector<Status> last_M;
        bool prepared = false;
        mutable Vector res, t, rc, ec, d, ghost;
        mutable Vector rw, ew; ///< the W-cycle's work vectors of the level below

        /// y -= A_offd z (the halo exchange of z).
        void minus_offdiagonal(const Vector& z, Vector& y) const {
            J->ghost_values(z, ghost);
            J->subtract_offdiagonal(ghost, y);
        }
        void residual(const Vector& r, const Vector& z, Vector& out) const override {
            J->apply(z, t);
            out = r - t;
        }
        void forward_from_zero(const Vector& r, Vector& z, Vector& out) const override {
            if (lattice)
                lattice->forward_from_zero(r, z, out); // out = r - A_diag z
            else
                smoother->forward_from_zero(r, z, out);
            minus_offdiagonal(z, out);
        }
        void smooth(const Vector& r, Vector& z, smoothers::Sweep direction,
                    int count) const override {
            for (int s = 0; s < count; ++s) {
                d = r;
                minus_offdiagonal(z, d);
                if (lattice)
                    lattice->smooth(d, z, direction, 1);
                else
                    smoother->sweep(d, z, direction);
            }
        }
    };

    /// J with its diagonal block multiplied by the lattice smoother's structured kernel.
    class LatticeProduct final : public LinearOperator {
    public:
        explicit LatticeProduct(const Op& o) : o_(o) {}
        Index rows() const override { return o_.J->rows(); }
        Index cols() const override { return o_.J->cols(); }
        void apply(const Vector& x, Vector& y) const override {
            o_.J->apply(x, y, smoothers::LatticeOperator(*o_.lattice));
        }

    private:
        const Op& o_;
    };

    /// The transfer from the level below: T a ParCSR matrix, R = T^T.
    struct Transfer final : solvers::CycleTransfer {
        explicit Transfer(const solvers::ParMatrix& prolongation) : T(prolongation) {}
        const solvers::ParMatrix& T;
        mutable Vector t;
        void restrict_residual(const Vector& res, Vector& rc) const override {
            T.apply_transpose(res, rc);
        }
        void prolongate(const Vector& e, Vector& z, bool add) const override {
            T.apply(e, t);
            if (!add) z.setZero(t.size());
            z += t;
        }
    };

    /// Without mg: the preconditioner of each process's diagonal block (Jacobi across the cuts).
    class BlockPc final : public Preconditioner {
    public:
        BlockPc(const DistributedMultigridCore& s, size_t k) : s_(s), k_(k) {}
        void setup(const SparseMatrix&) override {}
        void apply(const Vector& r, Vector& z) const override { s_.op_[k_].block_pc->apply(r, z); }
        std::string name() const override { return s_.name(); }

    private:
        const DistributedMultigridCore& s_;
        size_t k_;
    };

    /// One V-cycle from level k as a Preconditioner.
    class Cycle final : public Preconditioner {
    public:
        Cycle(const DistributedMultigridCore& s, size_t k) : s_(s), k_(k) {}
        void setup(const SparseMatrix&) override {}
        void apply(const Vector& r, Vector& z) const override {
            s_.cycle(static_cast<int>(k_), r, z);
        }
        std::string name() const override { return s_.name(); }

    private:
        const DistributedMultigridCore& s_;
        size_t k_;
    };

    void build_jacobian(size_t k) {
        const DLevel& D = levels_[k];
        const solvers::RowBlocks& Kb = *D.K_blocks;
        const LevelD& L = D.local;
        const int n = static_cast<int>(D.n_owned);
        Op& o = op_[k];
        o.blocks = std::make_unique<solvers::RowBlocks>();
        solvers::RowBlocks& B = *o.blocks;
        B.first_row = Kb.first_row;
        B.first_col = Kb.first_col;
        // The contact entries of the owned rows: (row, local column) in visiting order, -1 rows
        // for those owned elsewhere.
        std::vector<std::pair<int, int>> centries;
        const Status I = Status::Identity();
        auto visit = [&](int row, int col, double) {
            centries.emplace_back(row < n ? row : -1, col);
        };
        for (size_t e = 0; e < L.contacts.size(); ++e)
            contact::for_each_tangent_entry(L.contacts[e], I, L.dofs, L.lambda_dof[e], visit);
        for (size_t e = 0; e < L.ghost_contacts.size(); ++e)
            contact::for_each_tangent_entry(L.ghost_contacts[e], I, L.dofs, L.ghost_lambda_dof[e],
                                            visit);
        // Off-diagonal columns: K's and the contact couplings to other processes' unknowns.
        std::vector<std::int64_t> col_map = Kb.col_map;
        for (auto [r, c] : centries)
            if (r >= 0 && c >= n) col_map.push_back(D.global_dof[static_cast<size_t>(c)]);
        std::sort(col_map.begin(), col_map.end());
        col_map.erase(std::unique(col_map.begin(), col_map.end()), col_map.end());
        const bool offd_grows = col_map.size() != Kb.col_map.size() ||
                                std::any_of(centries.begin(), centries.end(), [&](auto rc) {
                                    return rc.first >= 0 && rc.second >= n;
                                });
        auto offd_col = [&](std::int64_t g) {
            const auto it = std::lower_bound(col_map.begin(), col_map.end(), g);
            MLC_ASSERT(it != col_map.end() && *it == g, "an off-diagonal column is not mapped");
            return static_cast<int>(it - col_map.begin());
        };
        o.kpos = merge_diagonal_pattern(Kb.diag, centries, B.diag);
        if (!offd_grows) {
            B.offd = Kb.offd;
            B.col_map = Kb.col_map;
        } else {
            std::vector<Eigen::Triplet<double>> trip;
            for (int i = 0; i < n; ++i)
                for (SparseMatrix::InnerIterator it(Kb.offd, i); it; ++it)
                    trip.emplace_back(i, offd_col(Kb.col_map[static_cast<size_t>(it.col())]), 0.0);
            for (auto [r, c] : centries)
                if (r >= 0 && c >= n)
                    trip.emplace_back(r, offd_col(D.global_dof[static_cast<size_t>(c)]), 0.0);
            B.offd.resize(n, static_cast<Index>(col_map.size()));
            B.offd.setFromTriplets(trip.begin(), trip.end());
            B.offd.makeCompressed();
            B.col_map = col_map;
        }
        auto position = [](const SparseMatrix& A, int row, int col) {
            const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[row];
            const int* end = A.innerIndexPtr() + A.outerIndexPtr()[row + 1];
            const int* it = std::lower_bound(begin, end, col);
            MLC_ASSERT(it != end && *it == col, "Jacobian pattern misses an entry");
            return static_cast<int>(it - A.innerIndexPtr());
        };
        if (offd_grows)
            for (int i = 0; i < n; ++i)
                for (SparseMatrix::InnerIterator it(Kb.offd, i); it; ++it)
                    o.kopos.push_back(
                        position(B.offd, i, offd_col(Kb.col_map[static_cast<size_t>(it.col())])));
        o.cpos.reserve(centries.size());
        for (auto [r, c] : centries)
            if (r < 0)
                o.cpos.push_back({0, -1});
            else if (c < n)
                o.cpos.push_back({position(B.diag, r, c), 0});
            else
                o.cpos.push_back(
                    {position(B.offd, r, offd_col(D.global_dof[static_cast<size_t>(c)])), 1});
        o.J = std::make_unique<solvers::ParMatrix>(comm_, B);
    }

    void build_coarse_map(const LevelD& Lp) {
        const DLevel& D = levels_[0];
        std::vector<std::int64_t> mine(static_cast<size_t>(D.n_owned), -1);
        const auto& dofs = D.local.dofs;
        for (int v = 0; v < D.local.mesh.n_vertices(); ++v) {
            const auto& loc = D.part.vertex_location[static_cast<size_t>(v)];
            using Kind = typename std::remove_cvref_t<decltype(loc)>::Kind;
            MLC_CHECK(loc.kind == Kind::vertex,
                      "internal error: a vertex of level p's part is not a level-p vertex");
            for (int c = 0; c < dim; ++c) {
                const int d = dofs.u_dof(v, c);
                if (d >= 0 && d < D.n_owned)
                    mine[static_cast<size_t>(d)] = Lp.dofs.u_dof(loc.id, c);
            }
            const int e = dofs.extra_dof(v);
            for (int q = 0; e >= 0 && q < D.n_extra[static_cast<size_t>(v)]; ++q)
                if (e + q < D.n_owned)
                    mine[static_cast<size_t>(e + q)] = Lp.dofs.extra_dof(loc.id) + q;
        }
        coarse_map_ = comm_.allgather(std::span<const std::int64_t>(mine));
        MLC_CHECK(static_cast<Index>(coarse_map_.size()) == Lp.n_unknowns(),
                  "internal error: level p has " << Lp.n_unknowns() << " unknowns, its parts "
                                                 << coarse_map_.size());
        std::vector<char> seen(coarse_map_.size(), 0);
        for (const auto s : coarse_map_) {
            MLC_CHECK(s >= 0 && s < Lp.n_unknowns() && !seen[static_cast<size_t>(s)],
                      "internal error: the parts of level p do not number its unknowns once");
            seen[static_cast<size_t>(s)] = 1;
        }
        coarse_rhs_.resize(Lp.n_unknowns());
    }

    solvers::CycleLevel cycle_level(int k) const override {
        const Op& o = op_[static_cast<size_t>(k)];
        return {o,
                o,
                transfer_[static_cast<size_t>(k) - 1],
                mg_.pre_sweeps,
                mg_.post_sweeps,
                o.res,
                o.rc,
                o.ec,
                mg_.cycles,
                &o.rw,
                &o.ew};
    }

    /// The gathered coarse solve: the residual gathered on every process, solved by the LU of
    /// level p, this process's entries kept.
    void coarse_solve(const Vector& r, Vector& z) const override {
        const auto full = comm_.allgather(std::span<const double>(r.data(), r.size()));
        for (size_t g = 0; g < full.size(); ++g)
            coarse_rhs_[coarse_map_[g]] = full[g];
        const Vector zs = lu_.solve(coarse_rhs_);
        const DLevel& D = levels_[0];
        z.resize(D.n_owned);
        for (Index i = 0; i < D.n_owned; ++i)
            z[i] = zs[coarse_map_[static_cast<size_t>(D.first_dof + i)]];
    }

    const std::vector<DLevel>& levels_;
    const std::vector<DTransfer>& transfers_;
    const Communicator& comm_;
    LinearSolverSpec spec_; ///< 2D: the Krylov method and preconditioner; 3D: gmres + mg
    solvers::KrylovParams kp_;
    solvers::MultigridParams mg_;
    bool use_mg_ = true;   ///< else spec_.pc on each process's diagonal block
    bool use_ebe_ = false; ///< spec_.pc is ebe (on each process's diagonal block)
    std::vector<Op> op_;
    std::vector<Transfer> transfer_; ///< transfer_[k - 1]: level k - 1 -> k
    const LevelD* coarse_level_ = nullptr;
    std::unique_ptr<BasicJacobianAssembler<dim>> coarse_asm_;
    Eigen::SparseLU<SparseMatrixCol> lu_;
    bool analyzed_ = false;
    std::vector<std::int64_t> coarse_map_;
    mutable Vector coarse_rhs_;
};

} // namespace detail

/// The 2D multigrid.
struct DistributedMultigrid::Impl final : detail::DistributedMultigridCore<2> {
    using DistributedMultigridCore::DistributedMultigridCore;
};

/// The 3D multigrid.
struct DistributedMultigrid3::Impl final : detail::DistributedMultigridCore<3> {
    using DistributedMultigridCore::DistributedMultigridCore;
};

namespace {
/// The 3D multigrid's spec: GMRES preconditioned by mg.
LinearSolverSpec gmres_mg_spec() {
    LinearSolverSpec s;
    s.method = solvers::Method::krylov;
    s.krylov = solvers::Krylov::gmres;
    s.pc = solvers::parse_pc("mg");
    return s;
}
} // namespace

DistributedMultigrid::DistributedMultigrid(const std::vector<DistributedLevel>& levels,
                                           const std::vector<DistributedTransfer>& transfers,
                                           const Communicator& comm, LinearSolverSpec spec,
                                           solvers::MultigridParams mg)
    : impl_(std::make_unique<Impl>(levels, transfers, comm, spec, spec.krylov_params(), mg)) {}
DistributedMultigrid::~DistributedMultigrid() = default;
void DistributedMultigrid::set_coarse(const Level& level_p, const std::vector<Eigen::Matrix2d>& M) {
    impl_->set_coarse(level_p, M);
}
void DistributedMultigrid::prepare(size_t k, const std::vector<Eigen::Matrix2d>& M) {
    impl_->prepare(k, M);
}
SolveResult DistributedMultigrid::solve(size_t k, const std::vector<Eigen::Matrix2d>& M,
                                        const Vector& b, Vector& dx, double forcing) {
    return impl_->solve(k, M, b, dx, forcing);
}
const solvers::ParMatrix& DistributedMultigrid::matrix(size_t k) const {
    MLC_CHECK(k >= 1 && k < impl_->op_.size() && impl_->op_[k].prepared,
              "DistributedMultigrid::matrix: level " << k << " is not prepared");
    return *impl_->op_[k].J;
}
std::unique_ptr<Preconditioner> DistributedMultigrid::preconditioner(size_t k) const {
    MLC_CHECK(k >= 1 && k < impl_->op_.size(),
              "DistributedMultigrid::preconditioner: no level " << k);
    return std::make_unique<Impl::Cycle>(*impl_, k);
}
std::string DistributedMultigrid::name() const {
    return impl_->name();
}

DistributedMultigrid3::DistributedMultigrid3(const std::vector<DistributedLevel3>& levels,
                                             const std::vector<DistributedTransfer3>& transfers,
                                             const Communicator& comm, solvers::KrylovParams krylov,
                                             solvers::MultigridParams mg)
    : impl_(std::make_unique<Impl>(levels, transfers, comm, gmres_mg_spec(), krylov, mg)) {}
DistributedMultigrid3::DistributedMultigrid3(const std::vector<DistributedLevel3>& levels,
                                             const std::vector<DistributedTransfer3>& transfers,
                                             const Communicator& comm, const LinearSolverSpec& spec,
                                             solvers::KrylovParams krylov,
                                             solvers::MultigridParams mg)
    : impl_(std::make_unique<Impl>(levels, transfers, comm, spec, krylov, mg)) {}
DistributedMultigrid3::~DistributedMultigrid3() = default;
void DistributedMultigrid3::set_coarse(const Level3& level_p,
                                       const std::vector<Eigen::Matrix3d>& M) {
    impl_->set_coarse(level_p, M);
}
void DistributedMultigrid3::prepare(size_t k, const std::vector<Eigen::Matrix3d>& M) {
    impl_->prepare(k, M);
}
SolveResult DistributedMultigrid3::solve(size_t k, const std::vector<Eigen::Matrix3d>& M,
                                         const Vector& b, Vector& dx, double forcing) {
    return impl_->solve(k, M, b, dx, forcing);
}
const solvers::ParMatrix& DistributedMultigrid3::matrix(size_t k) const {
    MLC_CHECK(k >= 1 && k < impl_->op_.size() && impl_->op_[k].prepared,
              "DistributedMultigrid3::matrix: level " << k << " is not prepared");
    return *impl_->op_[k].J;
}
std::unique_ptr<Preconditioner> DistributedMultigrid3::preconditioner(size_t k) const {
    MLC_CHECK(k >= 1 && k < impl_->op_.size(),
              "DistributedMultigrid3::preconditioner: no level " << k);
    return std::make_unique<Impl::Cycle>(*impl_, k);
}
std::string DistributedMultigrid3::name() const {
    return impl_->name();
}

} // namespace mlc::levels
