// SPDX-License-Identifier: MIT
// The distributed 3D multigrid (levels::DistributedMultigrid3) against the one-process sparse LU,
// on any number of processes: ctest runs these tests alone (one process) and under mpirun -np 1,
// 2 and 3 (label mpi). On levels 0 .. n of block3d (friction on a rigid plane) and stack3d (two
// bodies, friction), at a state with contact nodes in every status: GMRES preconditioned by the
// distributed cycle solves the Newton system of level n for the owned part of a serial vector,
// and every process compares its owned entries with the serial solution of the same system.
#include "core/check.hpp"

#include <gtest/gtest.h>

#if MLC_HAVE_HYPRE
#include "comm/world.hpp"
#include "contact/element.hpp"
#include "levels/distributed3.hpp"
#include "levels/distributed_multigrid.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "levels/solve3.hpp"
#include "scene/scene3.hpp"
#include "solvers/direct.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"
#include "tests/levels/distributed3_fixtures.hpp"

#include <iostream>
#include <memory>
#include <string>

using namespace mlc;
using namespace mlc::distributed3_fixtures;

namespace {

/// The status matrices of elements `els` (lambda dofs `ld`) of level L at x, as the Newton
/// residual evaluates them (contact::evaluate).
std::vector<Eigen::Matrix3d> status_matrices(const levels::Level3& L,
                                             const std::vector<contact::ContactElement3>& els,
                                             const std::vector<int>& ld, const Vector& x,
                                             const Vector& u_prev_full,
                                             levels::StatusCounts* counts) {
    Vector u_full;
    L.dofs.expand(x, L.u_fixed, u_full);
    std::vector<Eigen::Matrix3d> M;
    for (size_t e = 0; e < els.size(); ++e) {
        const auto es = contact::evaluate(els[e], u_full, u_prev_full, x, ld[e]);
        M.push_back(es.proj.M);
        if (counts) counts->add(es.proj.status);
    }
    return M;
}

/// The statuses of a part (its contacts, then its ghost contacts) at the serial state st: owned
/// unknowns from st, ghosts from their owners, u_prev from the serial vertices.
std::vector<Eigen::Matrix3d> part_status_matrices(const levels::DistributedLevel3& d,
                                                  const levels::Level3& s, const State3& st) {
    const auto& L = d.local;
    const State3 ps = part_state(d, s, st);
    const Vector& x = ps.x;
    const Vector& u_prev = ps.u_prev_full;
    std::vector<Eigen::Matrix3d> M =
        status_matrices(L, L.contacts, L.lambda_dof, x, u_prev, nullptr);
    const auto Mg = status_matrices(L, L.ghost_contacts, L.ghost_lambda_dof, x, u_prev, nullptr);
    M.insert(M.end(), Mg.begin(), Mg.end());
    return M;
}

/// serial_state with smooth multipliers: those of a contact node a smooth function of its
/// position (smooth_u's; the tangents a twentieth of the normal, so that some nodes stick), so
/// that the statuses form patches that the levels share, as the converged statuses of one load
/// step on consecutive levels do (the distributed cycle's coarse operators are those of each
/// level's own statuses, not Galerkin products).
State3 smooth_state(const levels::Level3& s, double a) {
    State3 st = serial_state(s, a);
    const double h = s.mesh.diameter();
    for (size_t e = 0; e < s.contacts.size(); ++e) {
        const auto& el = s.contacts[e];
        const mesh::Vec3& x = s.mesh.vertices[static_cast<size_t>(el.vertex[0])];
        const int nm = el.n_multipliers();
        for (int q = 0; q < nm; ++q)
            st.x[s.lambda_dof[e] + q] =
                (q + 1 < nm ? 0.2 : 4.0) * el.r * smooth_u(x, q + 3, 0, h, 0.5 * a);
    }
    return st;
}

/// GMRES iterations of the one-process multigrid (levels::solve's Method3::mg: Galerkin
/// operators, T the displacements' P and the multipliers' surface Q, elastic3_mg_params) on
/// J x = b of the finest level of `b3`, to relative tolerance 1e-12.
int serial_mg_iterations(const Block3dLevels& b3, const SparseMatrix& J, const Vector& b) {
    const auto& H = b3.serial;
    std::vector<solvers::MultigridLevelData> data;
    for (int l = 0; l < H.n_levels(); ++l) {
        const levels::Level3& L = H.levels[static_cast<size_t>(l)];
        solvers::MultigridLevelData d;
        if (l > 0) {
            const levels::Level3& C = H.levels[static_cast<size_t>(l - 1)];
            const levels::MultiplierTransfer3 q(C, L, levels::contactor_faces(b3.p, C),
                                                levels::contactor_faces(b3.p, L));
            d.T_storage = std::make_shared<const SparseMatrix>(
                levels::full_prolongation3(H.transfers[static_cast<size_t>(l - 1)].T, q));
            d.R_storage = std::make_shared<const SparseMatrix>(d.T_storage->transpose());
            d.T = d.T_storage.get();
            d.R = d.R_storage.get();
        }
        d.block_starts = solvers::vertex_block_starts(L.vertex_of_dof());
        data.push_back(std::move(d));
    }
    solvers::Multigrid mg(std::move(data), levels::elastic3_mg_params(),
                          solvers::CoarseOperators::galerkin);
    mg.setup(J);
    solvers::KrylovParams kp;
    kp.rel_tol = 1e-12;
    kp.max_iter = 500;
    kp.restart = 50;
    Vector x = Vector::Zero(b.size());
    const SolveResult r = solvers::solve(solvers::Krylov::gmres, J, mg, b, x, kp);
    EXPECT_TRUE(r.converged) << r.message;
    return r.iterations;
}

/// Solves the Newton system of the finest level of b3 (levels 0 .. n, partitioned on level 0)
/// at smooth_state's statuses by GMRES and the distributed multigrid to 1e-12, and compares
/// the owned entries with the serial sparse LU solution of the same system: displacements to
/// 1e-8 of the largest displacement, multipliers to 1e-8 of the largest multiplier; at most
/// `max_iterations` GMRES iterations.
void expect_serial_solution(const std::string& name, const Block3dLevels& b3, int max_iterations) {
    const Communicator& comm = comm::world();
    const auto& H = b3.serial;
    const size_t n = b3.dist.levels.size() - 1;
    SCOPED_TRACE(name + " levels 0-" + std::to_string(n));
    // The state and statuses of every level (serial, and each part's at the same state), the
    // nodes in every status on every level.
    std::vector<State3> st;
    std::vector<std::vector<Eigen::Matrix3d>> Ms;
    for (size_t l = 0; l <= n; ++l) {
        const levels::Level3& s = H.levels[l];
        st.push_back(smooth_state(s, 1e-3 * s.mesh.diameter()));
        levels::StatusCounts counts;
        Ms.push_back(
            status_matrices(s, s.contacts, s.lambda_dof, st[l].x, st[l].u_prev_full, &counts));
        EXPECT_GT(counts.gap, 0) << "level " << l;
        EXPECT_GT(counts.stick, 0) << "level " << l;
        EXPECT_GT(counts.slip, 0) << "level " << l;
    }
    solvers::KrylovParams kp;
    kp.rel_tol = 1e-12;
    kp.max_iter = 200;
    kp.restart = 50;
    levels::DistributedMultigrid3 mg(b3.dist.levels, b3.dist.transfers, comm, kp,
                                     levels::elastic3_mg_params());
    EXPECT_EQ(mg.name(), "gmres + distributed mg(pre=2,post=2,omega=1,cycles=2)");
    mg.set_coarse(H.levels[0], Ms[0]);
    for (size_t k = 1; k < n; ++k)
        mg.prepare(k, part_status_matrices(b3.dist.levels[k], H.levels[k], st[k]));
    // The serial system: random loads on the displacement rows, and on the multiplier rows
    // (displacements over the element's r) random over r, so that neither part of b dominates.
    const levels::Level3& s = H.levels[n];
    levels::BasicJacobianAssembler<3> jac(s);
    jac.assemble(Ms[n]);
    Vector bs(s.n_unknowns());
    for (Index i = 0; i < bs.size(); ++i)
        bs[i] = pseudo_random(i);
    for (size_t e = 0; e < s.contacts.size(); ++e)
        for (int q = 0; q < s.contacts[e].n_multipliers(); ++q)
            bs[s.lambda_dof[e] + q] /= s.contacts[e].r;
    // Its solution by sparse LU and one step of iterative refinement (with block3d's large r the
    // multipliers dwarf the displacements, and the plain LU solution's displacements are not
    // accurate to the test's tolerance).
    solvers::SparseLUPreconditioner lu;
    lu.setup(jac.matrix());
    Vector xs, dxs;
    lu.apply(bs, xs);
    lu.apply(Vector(bs - jac.matrix() * xs), dxs);
    xs += dxs;
    double u_scale = 0.0, l_scale = 0.0;
    for (Index i = 0; i < xs.size(); ++i)
        (s.dofs.is_displacement(i) ? u_scale : l_scale) =
            std::max(s.dofs.is_displacement(i) ? u_scale : l_scale, std::abs(xs[i]));
    ASSERT_GT(u_scale, 0.0);
    ASSERT_GT(l_scale, 0.0);
    // The distributed solve of the owned part (solve prepares level n at the part's statuses).
    const auto& d = b3.dist.levels[n];
    const std::vector<Index> to_serial = serial_dofs(d, s);
    const Vector b = owned_part(to_serial, d.n_owned, bs);
    Vector dx = Vector::Zero(d.n_owned);
    const SolveResult r = mg.solve(n, part_status_matrices(d, s, st[n]), b, dx, 0.0);
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_LE(r.relative_residual, 1e-12);
    double u_err = 0.0, l_err = 0.0;
    for (Index i = 0; i < d.n_owned; ++i) {
        const Index si = to_serial[static_cast<size_t>(i)];
        (s.dofs.is_displacement(si) ? u_err : l_err) =
            std::max(s.dofs.is_displacement(si) ? u_err : l_err, std::abs(dx[i] - xs[si]));
    }
    u_err = comm.max(u_err);
    l_err = comm.max(l_err);
    EXPECT_LE(u_err, 1e-8 * u_scale);
    EXPECT_LE(l_err, 1e-8 * l_scale);
    EXPECT_LE(r.iterations, max_iterations);
    if (comm.rank() == 0)
        std::cout << "[ Distributed3Mg ] " << name << " levels 0-" << n << ", " << comm.size()
                  << " processes: " << s.n_unknowns() << " unknowns, GMRES iterations "
                  << r.iterations << " (one-process mg "
                  << serial_mg_iterations(b3, jac.matrix(), bs) << "), error / max |u| "
                  << u_err / u_scale << ", / max |lambda| " << l_err / l_scale << "\n";
}

/// block3d (a block on a rigid plane, friction), levels 0 .. n.
levels::ElasticProblem3 block3d_scene() {
    return scene::load_scene3("block3d");
}

/// stack3d (two blocks, non-matching meshes) with friction mu = 0.3 and segment weights.
levels::ElasticProblem3 stack3d_friction_scene() {
    auto p = scene::load_scene3("stack3d");
    p.contacts.at(0).mu = 0.3;
    p.contacts.at(0).integration = contact::FacetIntegration::segment;
    return p;
}

} // namespace

TEST(Distributed3Mg, Block3dSolutionIsTheSerialLuOne) {
    for (int n = 1; n <= 2; ++n)
        expect_serial_solution("block3d", levels_up_to(block3d_scene(), n, comm::world()), 30);
}

// Levels 0-1 only: levels 0-2 take several times the rest of the suite (mostly the serial
// levels and their sparse LU). On this small mesh the cuts cross the two-body contact couplings
// (a contact node's multipliers and its target vertices on different processes); with the
// multipliers in the transfer the iterations stay those of one process.
TEST(Distributed3Mg, Stack3dWithFrictionSolutionIsTheSerialLuOne) {
    expect_serial_solution("stack3d mu 0.3",
                           levels_up_to(stack3d_friction_scene(), 1, comm::world()), 30);
}

TEST(Distributed3Mg, RefusesTheTwoDimensionalOptionsOnEveryProcess) {
    const Block3dLevels b3 = levels_up_to(block3d_scene(), 1, comm::world());
    solvers::MultigridParams single = levels::elastic3_mg_params();
    single.precision = Precision::float32;
    EXPECT_THROW(
        levels::DistributedMultigrid3(b3.dist.levels, b3.dist.transfers, comm::world(), {}, single),
        InvalidInput);
    solvers::MultigridParams lattice = levels::elastic3_mg_params();
    lattice.smoother = solvers::MultigridParams::Smoother::lattice;
    EXPECT_THROW(levels::DistributedMultigrid3(b3.dist.levels, b3.dist.transfers, comm::world(), {},
                                               lattice),
                 InvalidInput);
    solvers::MultigridParams three = levels::elastic3_mg_params();
    three.cycles = 3;
    EXPECT_THROW(
        levels::DistributedMultigrid3(b3.dist.levels, b3.dist.transfers, comm::world(), {}, three),
        InvalidInput);
}

#endif
