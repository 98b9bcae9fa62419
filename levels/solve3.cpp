// SPDX-License-Identifier: MIT
// 3D contact runs: load steps over the tetrahedral hierarchy, coarse to fine.
#include "levels/solve3.hpp"

#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace mlc::levels {

int status_code3(contact::Status s) {
    switch (s) {
    case contact::Status::gap:
        return 0;
    case contact::Status::stick:
        return 1;
    default:
        return 2; // slip (and the 2D slip statuses, which a 3D level never has)
    }
}

const char* to_string(Method3 m) {
    switch (m) {
    case Method3::schur:
        return "schur";
    case Method3::lu:
        return "lu";
    case Method3::mg:
        return "gmres + mg";
    case Method3::krylov:
        return "krylov";
    }
    return "?";
}

LinearSolverSpec gmres_spec3() {
    LinearSolverSpec k;
    k.method = solvers::Method::krylov;
    k.krylov = solvers::Krylov::gmres;
    return k;
}

double LevelStep3::agreement() const {
    if (!predicted || final_statuses.empty()) return 1.0;
    int same = 0;
    for (int a = 0; a < 3; ++a)
        same += confusion[static_cast<size_t>(a)][static_cast<size_t>(a)];
    return static_cast<double>(same) / static_cast<double>(final_statuses.size());
}

double estimate_contact3_bytes(const std::vector<ElasticLevelSize3>& sizes, Method3 level0,
                               Method3 upper) {
    MLC_CHECK(!sizes.empty(), "estimate_contact3_bytes: no level");
    const ElasticMemory3 elastic = estimate_elastic3_memory(sizes);
    double bytes = elastic.mg_peak();
    for (const auto& s : sizes)
        bytes += 24.0 * s.k_nonzeros;
    const auto& top = sizes.back();
    bytes += 51.0 * 8.0 * (top.unknowns + top.multipliers);
    auto schur = [](const ElasticLevelSize3& s) {
        return 48.0 * s.multipliers * s.multipliers + estimate_direct3_bytes(s);
    };
    // Sparse LU of the whole Jacobian (Eigen's SparseLU, COLAMD ordering): its fill grows about
    // as the square of the unknowns on the 3D levels, far faster than a Cholesky factor of K
    // (calibrated on block3d's levels 2 and 3: docs/results/contact3d.md#results-contact3d-lu-memory).
    auto lu = [](const ElasticLevelSize3& s) {
        constexpr double kBytes3 = 3.64e9, kUnknowns3 = 58080, kExponent = 2.06;
        const double n = std::max(s.unknowns + s.multipliers, 1.0);
        return std::max(2.0 * estimate_direct3_bytes(s),
                        kBytes3 * std::pow(n / kUnknowns3, kExponent));
    };
    if (level0 == Method3::schur) bytes += schur(sizes.front());
    if (level0 == Method3::lu) bytes += lu(sizes.front());
    if (upper == Method3::schur && sizes.size() > 1) bytes += schur(top);
    if (upper == Method3::lu && sizes.size() > 1) bytes += lu(top);
    return bytes;
}

namespace {

void check_fits(const std::vector<ElasticLevelSize3>& sizes, Method3 level0, Method3 upper,
                const MemoryLimit& limit) {
    const double bytes = estimate_contact3_bytes(sizes, level0, upper);
    const auto& top = sizes.back();
    const double gib = 1024.0 * 1024.0 * 1024.0;
    MLC_CHECK(limit.bytes <= 0 || bytes <= limit.bytes,
              "the run does not fit in memory: level " << top.level << " has "
                  << static_cast<long long>(top.unknowns) << " displacement unknowns and "
                  << static_cast<long long>(top.multipliers) << " contact multipliers, and the run "
                  << "is estimated at " << bytes / gib << " GiB against the " << limit.bytes / gib
                  << " GiB this process may use (" << limit.source << "); use fewer levels"
                  << (upper == Method3::schur ? ", or the multigrid instead of --linear schur (its "
                                                "dense contact systems grow as the square of the "
                                                "multipliers)"
                                              : ""));
}

} // namespace

void check_contact3_fits(const ElasticProblem3& problem, Method3 level0, Method3 upper,
                         const MemoryLimit& limit) {
    check_fits(predict_elastic3_sizes(problem, problem.levels), level0, upper, limit);
}

Plan3 plan_contact3(const std::vector<ElasticLevelSize3>& sizes, std::optional<Method3> forced,
                    const MemoryLimit& limit) {
    MLC_CHECK(!sizes.empty(), "plan_contact3: no level");
    Plan3 plan;
    std::ostringstream why;
    const double m0 = sizes.front().multipliers;
    if (forced) {
        MLC_CHECK(*forced != Method3::mg, "plan_contact3: mg cannot solve level 0");
        plan.level0 = plan.upper = *forced;
        why << "--linear " << to_string(*forced) << ": exact on every level";
    } else {
        plan.upper = Method3::mg;
        const bool fits_schur =
            limit.bytes <= 0 ||
            estimate_contact3_bytes(sizes, Method3::schur, plan.upper) <= limit.bytes;
        plan.level0 = fits_schur ? Method3::schur : Method3::lu;
        why << "level 0 " << to_string(plan.level0) << " (" << m0 << " contact components"
            << (fits_schur ? "" : ": schur's dense systems do not fit") << ")";
        if (sizes.size() > 1) why << ", gmres + mg above";
    }
    check_fits(sizes, plan.level0, plan.upper, limit);
    plan.why = why.str();
    return plan;
}

transfer::SurfaceFacets<3> contactor_faces(const ElasticProblem3& problem, const Level3& L) {
    std::set<int> tags;
    for (const auto& pair : problem.contacts)
        if (const auto t = L.mesh.find_tag(pair.contactor)) tags.insert(*t);
    transfer::SurfaceFacets<3> out;
    for (const auto& f : L.mesh.boundary)
        if (tags.count(f.tag)) out.push_back(f.v);
    return out;
}

namespace {

transfer::SurfacePoints points_of(const Level3& L) {
    return transfer::SurfacePoints(L.mesh.vertices.begin(), L.mesh.vertices.end());
}

/// The frame of each surface vertex that is a contact node (identity elsewhere), and the
/// element of each surface vertex (-1 where none).
void frames_of(const Level3& L, const transfer::SurfaceVertices& s,
               std::vector<transfer::NodeFrame>& frames, std::vector<int>& element) {
    frames.assign(static_cast<size_t>(s.size()),
                  {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()});
    element.assign(static_cast<size_t>(s.size()), -1);
    for (size_t e = 0; e < L.contacts.size(); ++e) {
        const auto& el = L.contacts[e];
        const int i = s.index[static_cast<size_t>(el.vertex[0])];
        if (i < 0) continue;
        frames[static_cast<size_t>(i)] = {el.t.col(0), el.t.col(1), el.n};
        element[static_cast<size_t>(i)] = static_cast<int>(e);
    }
}

} // namespace

std::vector<double> contact_areas(const ElasticProblem3& problem, const Level3& L) {
    const auto faces = contactor_faces(problem, L);
    const auto s = transfer::surface_vertices<3>(faces, L.mesh.n_vertices());
    const Vector m = transfer::lumped_surface_masses<3>(points_of(L), faces, s);
    std::vector<double> out(L.contacts.size(), 0.0);
    for (size_t e = 0; e < L.contacts.size(); ++e) {
        const int i = s.index[static_cast<size_t>(L.contacts[e].vertex[0])];
        if (i >= 0) out[e] = m[i];
    }
    return out;
}

MultiplierTransfer3::MultiplierTransfer3(const Level3& coarse, const Level3& fine,
                                         const transfer::SurfaceFacets<3>& coarse_faces,
                                         const transfer::SurfaceFacets<3>& fine_faces)
    : coarse_(coarse), fine_(fine) {
    MLC_CHECK(fine.mesh.n_coarse_vertices == coarse.mesh.n_vertices(),
              "MultiplierTransfer3: the fine level is not a refinement of the coarse one");
    q_ = transfer::build_surface_q<3>(points_of(coarse), coarse_faces, points_of(fine), fine_faces,
                                      fine.mesh.parents);
    frames_of(coarse, q_.coarse, coarse_frames_, coarse_element_);
    frames_of(fine, q_.fine, fine_frames_, fine_element_);
}

void MultiplierTransfer3::apply(const Vector& x_coarse, Vector& x_fine) const {
    transfer::SurfaceForces local = transfer::SurfaceForces::Zero(q_.coarse.size(), 3);
    for (int i = 0; i < q_.coarse.size(); ++i) {
        const int e = coarse_element_[static_cast<size_t>(i)];
        if (e < 0) continue;
        const auto& el = coarse_.contacts[static_cast<size_t>(e)];
        const int d = coarse_.lambda_dof[static_cast<size_t>(e)];
        if (el.frictional())
            local.row(i) = x_coarse.segment<3>(d).transpose();
        else
            local(i, 2) = x_coarse[d];
    }
    const transfer::SurfaceForces fine_local =
        transfer::transfer_local_forces(q_, local, coarse_frames_, fine_frames_);
    for (int i = 0; i < q_.fine.size(); ++i) {
        const int e = fine_element_[static_cast<size_t>(i)];
        if (e < 0) continue;
        const auto& el = fine_.contacts[static_cast<size_t>(e)];
        const int d = fine_.lambda_dof[static_cast<size_t>(e)];
        if (el.frictional())
            x_fine.segment<3>(d) = fine_local.row(i).transpose();
        else
            x_fine[d] = fine_local(i, 2);
    }
}

SparseMatrix full_prolongation3(const SparseMatrix& T_u, const MultiplierTransfer3& q) {
    const Level3& C = q.coarse();
    const Level3& F = q.fine();
    MLC_CHECK(T_u.rows() == F.n_unknowns() && T_u.cols() == C.n_unknowns(),
              "full_prolongation3: T_u is " << T_u.rows() << " x " << T_u.cols() << ", expected "
                                            << F.n_unknowns() << " x " << C.n_unknowns());
    std::vector<Triplet> t;
    t.reserve(static_cast<size_t>(T_u.nonZeros()) + 9 * static_cast<size_t>(q.q().Q.nonZeros()));
    for (int i = 0; i < T_u.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(T_u, i); it; ++it)
            t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
    auto basis = [](const transfer::NodeFrame& f) {
        Eigen::Matrix3d B;
        B << f.t1, f.t2, f.n;
        return B;
    };
    const SparseMatrix& Q = q.q().Q;
    for (int i = 0; i < Q.outerSize(); ++i) {
        const int ef = q.fine_element()[static_cast<size_t>(i)];
        if (ef < 0) continue;
        const auto& elf = F.contacts[static_cast<size_t>(ef)];
        const int df = F.lambda_dof[static_cast<size_t>(ef)];
        const Eigen::Matrix3d Bf = basis(q.fine_frames()[static_cast<size_t>(i)]);
        for (SparseMatrix::InnerIterator it(Q, i); it; ++it) {
            const int ec = q.coarse_element()[static_cast<size_t>(it.col())];
            if (ec < 0) continue;
            const auto& elc = C.contacts[static_cast<size_t>(ec)];
            const int dc = C.lambda_dof[static_cast<size_t>(ec)];
            const Eigen::Matrix3d B =
                it.value() * Bf.transpose() * basis(q.coarse_frames()[static_cast<size_t>(it.col())]);
            const int a0 = elf.frictional() ? 0 : 2, b0 = elc.frictional() ? 0 : 2;
            for (int a = a0; a < 3; ++a)
                for (int b = b0; b < 3; ++b)
                    if (B(a, b) != 0.0) t.emplace_back(df + a - a0, dc + b - b0, B(a, b));
        }
    }
    SparseMatrix T(F.n_unknowns(), C.n_unknowns());
    T.setFromTriplets(t.begin(), t.end());
    return T;
}

namespace {

/// GMRES on the assembled Jacobian of level `transfers.size()`, preconditioned by the Galerkin
/// multigrid over that level and the ones below (transfers[l]: level l -> l + 1, full unknowns).
class MultigridSystemSolver3 final : public NewtonSystemSolver3 {
public:
    MultigridSystemSolver3(const Level3& level, std::vector<const Level3*> below,
                           std::vector<std::shared_ptr<const SparseMatrix>> transfers,
                           double rel_tol)
        : jac_(level), rel_tol_(rel_tol) {
        std::vector<solvers::MultigridLevelData> data;
        for (size_t l = 0; l <= below.size(); ++l) {
            const Level3& L = l < below.size() ? *below[l] : level;
            solvers::MultigridLevelData d;
            if (l > 0) {
                d.T_storage = transfers[l - 1];
                d.R_storage = std::make_shared<const SparseMatrix>(transfers[l - 1]->transpose());
                d.T = d.T_storage.get();
                d.R = d.R_storage.get();
            }
            d.block_starts = solvers::vertex_block_starts(L.vertex_of_dof());
            data.push_back(std::move(d));
        }
        mg_ = std::make_unique<solvers::Multigrid>(std::move(data), elastic3_mg_params(),
                                                   solvers::CoarseOperators::galerkin);
    }
    using NewtonSystemSolver3::solve;
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        const double t0 = wall_seconds();
        jac_.assemble(M);
        const double t1 = wall_seconds();
        if (first_)
            mg_->setup(jac_.matrix());
        else
            mg_->update_values(jac_.matrix());
        first_ = false;
        const double t2 = wall_seconds();
        solvers::KrylovParams kp;
        kp.rel_tol = std::max(forcing, rel_tol_);
        kp.max_iter = 500;
        kp.restart = 50;
        if (dx.size() != b.size()) dx = Vector::Zero(b.size());
        SolveResult r = solvers::solve(solvers::Krylov::gmres, jac_.matrix(), *mg_, b, dx, kp);
        r.assembly_seconds = t1 - t0;
        r.setup_seconds += t2 - t0;
        r.solve_seconds = wall_seconds() - t2;
        return r;
    }
    std::string name() const override { return "gmres + mg"; }
    const solvers::Multigrid* multigrid() const override { return mg_.get(); }

private:
    BasicJacobianAssembler<3> jac_;
    std::unique_ptr<solvers::Multigrid> mg_;
    double rel_tol_;
    bool first_ = true;
};

/// The free entries of a level's unknowns from nodal displacements (3 per vertex); the
/// multiplier entries are left as they are.
void gather_displacements(const Level3& L, const Vector& u_full, Vector& x) {
    for (int v = 0; v < L.mesh.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            if (const int d = L.dofs.u_dof(v, c); d >= 0) x[d] = u_full[3 * v + c];
}

/// P_vertex applied to each component of interleaved nodal displacements.
Vector interpolate_nodal(const SparseMatrix& P_vertex, const Vector& u_coarse) {
    const Index nc = P_vertex.cols();
    const Index nf = P_vertex.rows();
    Vector out = Vector::Zero(3 * nf);
    for (int c = 0; c < 3; ++c) {
        const Vector uc = Eigen::Map<const Vector, 0, Eigen::InnerStride<3>>(u_coarse.data() + c, nc);
        const Vector uf = P_vertex * uc;
        for (Index v = 0; v < nf; ++v)
            out[3 * v + c] = uf[v];
    }
    return out;
}

std::unique_ptr<NewtonSystemSolver3>
make_solver3(const Hierarchy3& H, int l, Method3 m, const SolveOptions3& options,
             const std::vector<std::shared_ptr<const SparseMatrix>>& T_full,
             const LevelBelow3* below3) {
    const double rel_tol = options.krylov_rel_tol;
    const Level3& L = H.levels[static_cast<size_t>(l)];
    if (m == Method3::schur) return make_schur_system_solver(L);
    if (m == Method3::lu || l == 0) return make_assembled_system_solver(L, make_sparse_lu_solver());
    if (m == Method3::krylov) {
        LinearSolverSpec spec = options.krylov;
        spec.rel_tol = rel_tol;
        return make_krylov_system_solver(L, spec, below3);
    }
    std::vector<const Level3*> below;
    std::vector<std::shared_ptr<const SparseMatrix>> transfers;
    for (int k = 0; k < l; ++k) {
        below.push_back(&H.levels[static_cast<size_t>(k)]);
        transfers.push_back(T_full[static_cast<size_t>(k)]);
    }
    return std::make_unique<MultigridSystemSolver3>(L, std::move(below), std::move(transfers),
                                                    rel_tol);
}

/// What one solved level carries from step to step.
struct LevelRun {
    std::unique_ptr<ContactNewton3> newton;
    NewtonSystemSolver3* sys = nullptr; ///< newton's solver
    /// Its preconditioner (CF, SORCF) needs the level below's converged statuses.
    bool needs_coarse_statuses = false;
    Vector x;            ///< unknowns at the last converged step
    Vector x_before;     ///< unknowns at the converged step before it (zero before step 2)
    Vector start;        ///< this step's own start: x, or its secant extrapolation
    Vector u_prev_full;  ///< nodal displacements at the last converged step
    Vector x_step_start; ///< the level's unknowns of the previous step (cold start)
};

} // namespace

RunResult3 solve(const ElasticProblem3& problem, const SolveOptions3& options) {
    problem.validate();
    RunResult3 out;
    {
        ScopedTimer t(&out.timings, "setup/levels");
        out.hierarchy = build_hierarchy(problem, problem.levels);
    }
    auto& H = out.hierarchy;
    const int nl = H.n_levels();
    const int finest = nl - 1;
    const bool all = options.coarse_to_fine || options.solve_all_levels;
    const int first = all ? 0 : finest;
    out.level_steps.assign(static_cast<size_t>(nl), {});
    std::vector<LevelRun> runs(static_cast<size_t>(nl));
    std::vector<std::unique_ptr<MultiplierTransfer3>> qs(static_cast<size_t>(nl));
    std::vector<LevelBelow3> below3(static_cast<size_t>(nl)); // CF/SORCF's level below
    {
        ScopedTimer t(&out.timings, "setup/linear_solver");
        std::vector<transfer::SurfaceFacets<3>> faces(static_cast<size_t>(nl));
        for (int l = 0; l < nl; ++l)
            faces[static_cast<size_t>(l)] = contactor_faces(problem, H.levels[static_cast<size_t>(l)]);
        // The multiplier transfers: coarse-to-fine guesses and the multigrid's T.
        const bool level_below = options.upper == Method3::krylov &&
                                 options.krylov.pc.entry != nullptr &&
                                 options.krylov.pc.entry->needs_level_below;
        MLC_CHECK(!level_below || options.coarse_to_fine || finest == 0,
                  options.krylov.pc.name()
                      << " needs the level below's converged statuses: it runs coarse to fine "
                         "(not with --cold)");
        const bool mg = (options.upper == Method3::mg || level_below) && finest > 0;
        for (int l = 1; l < nl; ++l)
            if (mg || (options.coarse_to_fine && l > first))
                qs[static_cast<size_t>(l)] = std::make_unique<MultiplierTransfer3>(
                    H.levels[static_cast<size_t>(l - 1)], H.levels[static_cast<size_t>(l)],
                    faces[static_cast<size_t>(l - 1)], faces[static_cast<size_t>(l)]);
        std::vector<std::shared_ptr<const SparseMatrix>> T_full(static_cast<size_t>(nl));
        if (mg)
            for (int l = 0; l + 1 < nl; ++l)
                T_full[static_cast<size_t>(l)] = std::make_shared<const SparseMatrix>(
                    full_prolongation3(H.transfers[static_cast<size_t>(l)].T,
                                       *qs[static_cast<size_t>(l + 1)]));
        for (int l = first; l < nl; ++l) {
            const Level3& L = H.levels[static_cast<size_t>(l)];
            auto& run = runs[static_cast<size_t>(l)];
            if (l > 0 && level_below)
                below3[static_cast<size_t>(l)] = LevelBelow3{
                    &H.levels[static_cast<size_t>(l - 1)],
                    &H.transfers[static_cast<size_t>(l - 1)].P_vertex,
                    T_full[static_cast<size_t>(l - 1)].get(), runs[static_cast<size_t>(l - 1)].sys};
            auto sys = make_solver3(H, l, l == 0 ? options.level0 : options.upper, options, T_full,
                                    l > 0 && level_below ? &below3[static_cast<size_t>(l)]
                                                         : nullptr);
            if (options.wrap_system_solver)
                sys = options.wrap_system_solver(l, L, std::move(sys));
            run.sys = sys.get();
            run.needs_coarse_statuses = l > 0 && level_below;
            run.newton =
                std::make_unique<ContactNewton3>(L, problem.newton, std::move(sys), &out.timings);
            if (options.interrupt) run.newton->set_interrupt(options.interrupt);
            run.x = Vector::Zero(L.n_unknowns());
            run.x_before = Vector::Zero(L.n_unknowns());
            run.u_prev_full = Vector::Zero(3 * L.mesh.n_vertices());
        }
    }
    const int K = problem.load_steps;
    out.converged = true;
    for (int k = 1; k <= K && out.converged; ++k) {
        const double s = static_cast<double>(k) / K;
        for (int l = first; l < nl; ++l) {
            const Level3& L = H.levels[static_cast<size_t>(l)];
            auto& run = runs[static_cast<size_t>(l)];
            LevelStep3 ls;
            ls.level = l;
            // The level's own start: its last state, or the secant extrapolation of its last two
            // (steps of equal size: s_k - s_{k-1} = s_{k-1} - s_{k-2}). It extrapolates the
            // unknowns only: the prescribed components are step k's, u_fixed_at(s), in the
            // Newton residual and in every expand below (also along a loading path).
            run.start = run.x;
            if (options.extrapolate && k >= 2) run.start += run.x - run.x_before;
            Vector x0 = run.start;
            if (options.coarse_to_fine && l > first) {
                const auto& below = runs[static_cast<size_t>(l - 1)];
                const Level3& C = H.levels[static_cast<size_t>(l - 1)];
                const bool correct = options.extrapolate && k >= 2;
                // Interpolated: the level below's converged state of this step, or (secant
                // predictor) what it changed from its own start, added to this level's start.
                Vector uc;
                const Vector xc = correct ? Vector(below.x - below.start) : below.x;
                if (correct)
                    C.dofs.expand(xc, Vector::Zero(C.u_fixed_at(s).size()), uc);
                else
                    C.dofs.expand(xc, C.u_fixed_at(s), uc);
                const Vector uf = interpolate_nodal(
                    H.transfers[static_cast<size_t>(l - 1)].P_vertex, uc);
                Vector xi = correct ? Vector(Vector::Zero(x0.size())) : x0;
                gather_displacements(L, uf, xi);
                qs[static_cast<size_t>(l)]->apply(xc, xi);
                x0 = correct ? Vector(x0 + xi) : xi;
                ls.predicted = true;
                ls.predicted_statuses = run.newton->statuses(s, run.u_prev_full, x0);
            }
            ls.report = run.newton->solve(s, run.u_prev_full, x0);
            ls.report.step = k;
            ls.final_statuses = run.newton->statuses(s, run.u_prev_full, x0);
            if (ls.predicted)
                for (size_t i = 0; i < ls.final_statuses.size(); ++i)
                    ++ls.confusion[static_cast<size_t>(status_code3(ls.predicted_statuses[i]))]
                                  [static_cast<size_t>(status_code3(ls.final_statuses[i]))];
            if (options.progress) options.progress(l, k, ls.report);
            const bool ok = ls.report.converged;
            if (ok && l < finest && runs[static_cast<size_t>(l + 1)].needs_coarse_statuses) {
                Vector R(x0.size());
                std::vector<StatusMatrix<3>> M;
                run.newton->residual(s, run.u_prev_full, x0, R, nullptr, &M, nullptr);
                runs[static_cast<size_t>(l + 1)].sys->set_coarse_statuses(M);
            }
            if (ok) {
                if (l == finest) {
                    out.step_nodes.push_back(run.newton->node_states(s, run.u_prev_full, x0));
                    out.nodes = out.step_nodes.back();
                }
                run.x_before = run.x;
                run.x = x0;
                L.dofs.expand(run.x, L.u_fixed_at(s), run.u_prev_full);
                if (l == finest) out.step_u_full.push_back(run.u_prev_full);
            }
            if (l == finest) out.steps.push_back(ls.report);
            out.level_steps[static_cast<size_t>(l)].push_back(std::move(ls));
            if (!ok) {
                std::ostringstream os;
                os << "load step " << k << " on level " << l << ": "
                   << out.level_steps[static_cast<size_t>(l)].back().report.message;
                out.failure = os.str();
                out.converged = false;
                break;
            }
        }
        if (out.converged) out.completed_steps = k;
    }
    const auto& top = runs[static_cast<size_t>(finest)];
    out.x = top.x;
    out.u_full = top.u_prev_full;
    return out;
}

} // namespace mlc::levels
