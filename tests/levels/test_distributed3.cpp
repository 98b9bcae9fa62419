// SPDX-License-Identifier: MIT
// The distributed 3D levels (levels/distributed3.hpp) against the one-process levels
// (levels::build_hierarchy), on any number of processes: ctest runs these tests alone (one
// process) and under mpirun -np 1, 2 and 3 (label mpi). Every process compares the unknowns it
// owns with the one-process level's, matched by their vertices' exact coordinates and bodies
// (midpoints are computed by the same arithmetic on every process): the numbering, K, f and T
// (block3d, its rigid contact), BoomerAMG-PCG on the elastic block (block3d without contact), the
// contact elements of the owned and ghost contact nodes (block3d; stack3d, two bodies, with its
// segment weights, and with friction and segment or nodal weights) and the owned rows of the
// contact residual and Jacobian at a global state.
#include "core/check.hpp"

#include <gtest/gtest.h>

#if MLC_HAVE_HYPRE
#include "comm/world.hpp"
#include "contact/element.hpp"
#include "levels/distributed3.hpp"
#include "levels/newton.hpp"
#include "scene/scene3.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/par_matrix.hpp"
#include "tests/common/direct_solve.hpp"
#include "tests/levels/distributed3_fixtures.hpp"

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>

using namespace mlc;
using namespace mlc::distributed3_fixtures;

namespace {

/// x with a reproducible value at every serial displacement unknown (0 at multipliers).
Vector serial_random(const levels::Level3& s) {
    Vector x = Vector::Zero(s.dofs.n_dofs());
    for (Index i = 0; i < x.size(); ++i)
        if (s.dofs.is_displacement(i)) x[i] = pseudo_random(i);
    return x;
}

/// Levels 0-1 of p, serial and partitioned on level 0.
Block3dLevels levels01(levels::ElasticProblem3 p) {
    return levels_up_to(std::move(p), 1, comm::world());
}

/// block3d (a block on a rigid plane, friction, a symmetry plane), levels 0-1.
const Block3dLevels& block3d() {
    static const Block3dLevels b = levels01(scene::load_scene3("block3d"));
    return b;
}

/// block3d without its contact pair (the elastic block alone), levels 0-1.
const Block3dLevels& block3d_elastic() {
    static const Block3dLevels b = [] {
        auto p = scene::load_scene3("block3d");
        p.contacts.clear();
        return levels01(std::move(p));
    }();
    return b;
}

/// stack3d (two blocks, non-matching meshes, frictionless, segment weights), levels 0-1.
const Block3dLevels& stack3d() {
    static const Block3dLevels b = levels01(scene::load_scene3("stack3d"));
    return b;
}

/// stack3d with friction (mu = 0.3: three multipliers, the symmetry planes pinning the first
/// tangent) and segment or nodal weights, levels 0-1.
const Block3dLevels& stack3d_friction(contact::FacetIntegration integration) {
    auto make = [](contact::FacetIntegration i) {
        auto p = scene::load_scene3("stack3d");
        p.contacts.at(0).mu = 0.3;
        p.contacts.at(0).integration = i;
        return levels01(std::move(p));
    };
    static const Block3dLevels segment = make(contact::FacetIntegration::segment);
    static const Block3dLevels nodal = make(contact::FacetIntegration::nodal);
    return integration == contact::FacetIntegration::nodal ? nodal : segment;
}

/// The contact scenes of the tests, with their names.
std::vector<std::pair<std::string, const Block3dLevels*>> contact_scenes() {
    return {{"block3d", &block3d()},
            {"stack3d", &stack3d()},
            {"stack3d mu 0.3 segment", &stack3d_friction(contact::FacetIntegration::segment)},
            {"stack3d mu 0.3 nodal", &stack3d_friction(contact::FacetIntegration::nodal)}};
}

} // namespace

TEST(Distributed3Levels, NumberingCoversTheSerialUnknownsOnce) {
    const Communicator& comm = comm::world();
    for (const auto& [name, bp] : contact_scenes())
        for (size_t l = 0; l < 2; ++l) {
            SCOPED_TRACE(name);
            const auto& b = *bp;
            ASSERT_EQ(b.dist.levels.size(), 2U);
            const auto& d = b.dist.levels[l];
            const auto& s = b.serial.levels[l];
            ASSERT_GT(s.n_contact_nodes(), 0);
            EXPECT_EQ(d.n_global_dofs, s.dofs.n_dofs()) << "level " << l;
            EXPECT_EQ(d.first_dof, comm.exclusive_sum(static_cast<std::int64_t>(d.n_owned)));
            const auto to_serial = serial_dofs(d, s);
            // Every serial unknown (displacement or multiplier) is owned by exactly one process.
            std::vector<int> count(static_cast<size_t>(s.dofs.n_dofs()), 0);
            for (Index i = 0; i < d.n_owned; ++i) {
                ASSERT_GE(to_serial[static_cast<size_t>(i)], 0);
                ++count[static_cast<size_t>(to_serial[static_cast<size_t>(i)])];
            }
            comm.allreduce(std::span<int>(count), ReduceOp::sum);
            for (Index i = 0; i < s.dofs.n_dofs(); ++i)
                EXPECT_EQ(count[static_cast<size_t>(i)], 1)
                    << "level " << l << " serial unknown " << i;
            // Ghost unknowns carry their owners' global numbers: the same serial unknown.
            std::vector<std::int64_t> serial_of_global(static_cast<size_t>(d.n_global_dofs), 0);
            for (Index i = 0; i < d.n_owned; ++i)
                serial_of_global[static_cast<size_t>(d.first_dof + i)] =
                    to_serial[static_cast<size_t>(i)];
            comm.allreduce(std::span<std::int64_t>(serial_of_global), ReduceOp::sum);
            for (Index i = d.n_owned; i < d.local.dofs.n_dofs(); ++i)
                EXPECT_EQ(
                    serial_of_global[static_cast<size_t>(d.global_dof[static_cast<size_t>(i)])],
                    to_serial[static_cast<size_t>(i)])
                    << "level " << l << " ghost unknown " << i;
        }
}

TEST(Distributed3Levels, StiffnessTimesARandomVectorAndLoadAreTheSerialOnes) {
    const auto& b = block3d();
    for (size_t l = 0; l < 2; ++l) {
        const auto& d = b.dist.levels[l];
        const auto& s = b.serial.levels[l];
        const auto to_serial = serial_dofs(d, s);
        const Vector x = serial_random(s);
        const Vector Kx = s.elastic.K * x;
        Vector y;
        d.K->apply(owned_part(to_serial, d.n_owned, x), y);
        ASSERT_EQ(y.size(), d.n_owned);
        const double scale = Kx.cwiseAbs().maxCoeff();
        ASSERT_GT(scale, 0.0);
        const Vector ref = owned_part(to_serial, d.n_owned, Kx);
        for (Index i = 0; i < d.n_owned; ++i)
            EXPECT_NEAR(y[i], ref[i], 1e-12 * scale) << "level " << l << " row " << i;
        const Vector f = d.owned_load();
        const Vector f_ref = owned_part(to_serial, d.n_owned, s.elastic.f);
        const double f_scale = s.elastic.f.cwiseAbs().maxCoeff();
        ASSERT_GT(f_scale, 0.0);
        for (Index i = 0; i < d.n_owned; ++i)
            EXPECT_NEAR(f[i], f_ref[i], 1e-12 * f_scale) << "level " << l << " row " << i;
    }
}

TEST(Distributed3Levels, TransferTimesACoarseVectorIsTheSerialOne) {
    const auto& b = block3d();
    ASSERT_EQ(b.dist.transfers.size(), 1U);
    const auto& dc = b.dist.levels[0];
    const auto& df = b.dist.levels[1];
    const auto& sc = b.serial.levels[0];
    const auto& sf = b.serial.levels[1];
    const Vector xc = serial_random(sc);
    const Vector Tx = b.serial.transfers[0].T * xc;
    Vector y;
    b.dist.transfers[0].T->apply(owned_part(serial_dofs(dc, sc), dc.n_owned, xc), y);
    ASSERT_EQ(y.size(), df.n_owned);
    const Vector ref = owned_part(serial_dofs(df, sf), df.n_owned, Tx);
    const double scale = Tx.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    for (Index i = 0; i < df.n_owned; ++i)
        EXPECT_NEAR(y[i], ref[i], 1e-12 * scale) << "fine row " << i;
    // The transpose too (restriction of a fine vector).
    const Vector xf = serial_random(sf);
    const Vector Rx = b.serial.transfers[0].R * xf;
    Vector z;
    b.dist.transfers[0].T->apply_transpose(owned_part(serial_dofs(df, sf), df.n_owned, xf), z);
    ASSERT_EQ(z.size(), dc.n_owned);
    const Vector zref = owned_part(serial_dofs(dc, sc), dc.n_owned, Rx);
    const double zscale = Rx.cwiseAbs().maxCoeff();
    for (Index i = 0; i < dc.n_owned; ++i)
        EXPECT_NEAR(z[i], zref[i], 1e-12 * zscale) << "coarse row " << i;
}

TEST(Distributed3Levels, BoomerAmgPcgSolutionIsTheSerialDirectOne) {
    const auto& b = block3d_elastic();
    const Communicator& comm = comm::world();
    const auto& d = b.dist.levels[1];
    const auto& s = b.serial.levels[1];
    // Serial: K on the displacements (the empty multiplier rows and columns made identity).
    SparseMatrix K = s.elastic.K;
    for (Index i = 0; i < K.rows(); ++i)
        if (!s.dofs.is_displacement(i)) K.coeffRef(i, i) = 1.0;
    const Vector x_serial = test::lu_solve(K, s.elastic.f);
    const double scale = x_serial.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    // Distributed: BoomerAMG-PCG on K through IJ, three functions interleaved.
    const solvers::ParMatrix Kp(comm, d.K_rows());
    const std::vector<int> func = d.dof_function();
    for (const int c : func)
        ASSERT_TRUE(c >= 0 && c < 3);
    solvers::BoomerAMGParams amg;
    amg.num_functions = 3;
    Vector x = Vector::Zero(d.n_owned);
    const SolveResult r = solvers::boomeramg_pcg_par(Kp, d.owned_load(), x, 1e-13, 500, amg, func);
    EXPECT_TRUE(r.converged) << r.iterations << " iterations, relative residual "
                             << r.relative_residual;
    const Vector ref = owned_part(serial_dofs(d, s), d.n_owned, x_serial);
    for (Index i = 0; i < d.n_owned; ++i)
        EXPECT_NEAR(x[i], ref[i], 1e-8 * scale) << "row " << i;
}

// A loading path on the parts: block3d pressed at the first of two path points and pushed at the
// second, its held bottom edge moved along x and back. At path parameters on both sides of the
// first point, every part's prescribed values (ghost vertices' too) and loads on its owned
// unknowns are the serial level's.
TEST(Distributed3Levels, LoadingPathOfEachPartIsTheSerialOne) {
    levels::ElasticProblem3 p = scene::load_scene3("block3d");
    p.loads[0].factors = {1.0, 1.0};
    p.loads[1].factors = {0.0, 1.0};
    ASSERT_TRUE(p.supports[1].line.has_value());
    p.supports[1].u_path[0] = {0.5, 0.0};
    ASSERT_EQ(p.n_path_points(), 2);
    const Block3dLevels b = levels01(p);
    for (size_t l = 0; l < 2; ++l) {
        const auto& d = b.dist.levels[l];
        const auto& s = b.serial.levels[l];
        const auto to_serial = serial_dofs(d, s);
        const auto sv = serial_vertices(d, s);
        for (const double t : {0.3, 0.5, 0.8, 1.0}) {
            const Vector f_ref = owned_part(to_serial, d.n_owned, s.f_at(t));
            const Vector f = d.local.f_at(t).head(d.n_owned);
            const double f_scale = s.f_at(t).cwiseAbs().maxCoeff();
            ASSERT_GT(f_scale, 0.0);
            for (Index i = 0; i < d.n_owned; ++i)
                EXPECT_NEAR(f[i], f_ref[i], 1e-12 * f_scale) << "level " << l << " s " << t;
            const Vector u = d.local.u_fixed_at(t), u_ref = s.u_fixed_at(t);
            for (int v = 0; v < d.local.mesh.n_vertices(); ++v)
                for (int c = 0; c < 3; ++c)
                    EXPECT_EQ(u[3 * v + c], u_ref[3 * sv[static_cast<size_t>(v)] + c])
                        << "level " << l << " s " << t << " vertex " << v;
        }
        // Half way to the first point the edge is at 0.25 along x: the path is not proportional.
        EXPECT_NEAR(s.u_fixed_at(0.25).maxCoeff(), 0.25, 1e-15);
    }
}

namespace {

/// Expects the part's element a (vertices local) to be the serial element b: its contactor the
/// serial one, the same nonzero weights at the same serial vertices, frame, gap, pair, mu, r,
/// pinned components and multipliers, to 1e-14 (the search of a part sees its target faces in
/// another order, so a target vertex of weight 0 may differ).
void expect_same_element(const contact::ContactElement3& a, const std::vector<int>& serial_of,
                         const contact::ContactElement3& b, const std::string& where) {
    SCOPED_TRACE(where);
    EXPECT_EQ(serial_of[static_cast<size_t>(a.vertex[0])], b.vertex[0]);
    std::map<int, double> wa, wb;
    for (int j = 0; j < a.n_nodes(); ++j)
        wa[serial_of[static_cast<size_t>(a.vertex[static_cast<size_t>(j)])]] +=
            a.weight[static_cast<size_t>(j)];
    for (int j = 0; j < b.n_nodes(); ++j)
        wb[b.vertex[static_cast<size_t>(j)]] += b.weight[static_cast<size_t>(j)];
    for (const auto& [v, w] : wa)
        EXPECT_NEAR(w, wb.count(v) ? wb.at(v) : 0.0, 1e-14) << "serial vertex " << v;
    for (const auto& [v, w] : wb)
        EXPECT_NEAR(w, wa.count(v) ? wa.at(v) : 0.0, 1e-14) << "serial vertex " << v;
    EXPECT_LE((a.n - b.n).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((a.t - b.t).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(a.g0, b.g0, 1e-14);
    EXPECT_EQ(a.pair, b.pair);
    EXPECT_EQ(a.mu, b.mu);
    EXPECT_EQ(a.r, b.r);
    EXPECT_EQ(a.pinned, b.pinned);
    EXPECT_EQ(a.n_multipliers(), b.n_multipliers());
}

/// Whether some target vertex of serial element e with a nonzero weight is one of `vertices`.
bool reaches(const contact::ContactElement3& e, const std::set<int>& vertices) {
    for (int j = 1; j < e.n_nodes(); ++j)
        if (e.weight[static_cast<size_t>(j)] != 0.0 &&
            vertices.count(e.vertex[static_cast<size_t>(j)]))
            return true;
    return false;
}

/// The contact residual and Jacobian entries of a level's elements `els` (lambda dofs `ld`) at
/// x, as the 3D Newton assembles them (contact::evaluate, add_residual, for_each_tangent_entry
/// with each element's status matrix); `J` keyed by (row, col) of the level's unknowns.
void contact_rows(const levels::Level3& L, const std::vector<contact::ContactElement3>& els,
                  const std::vector<int>& ld, const Vector& x, const Vector& u_prev_full, Vector& R,
                  std::map<std::pair<Index, Index>, double>& J, levels::StatusCounts* counts) {
    Vector u_full;
    L.dofs.expand(x, L.u_fixed, u_full);
    for (size_t e = 0; e < els.size(); ++e) {
        const auto es = contact::evaluate(els[e], u_full, u_prev_full, x, ld[e]);
        contact::add_residual(els[e], es, L.dofs, ld[e], R);
        contact::for_each_tangent_entry(els[e], es.proj.M, L.dofs, ld[e],
                                        [&](Index i, Index j, double v) {
                                            J[{i, j}] += v;
                                        });
        if (counts) counts->add(es.proj.status);
    }
}

} // namespace

TEST(Distributed3Levels, OwnedContactNodesAreTheSerialOnes) {
    const Communicator& comm = comm::world();
    for (const auto& [name, bp] : contact_scenes())
        for (size_t l = 0; l < 2; ++l) {
            SCOPED_TRACE(name + " level " + std::to_string(l));
            const auto& d = bp->dist.levels[l];
            const auto& s = bp->serial.levels[l];
            const auto& L = d.local;
            const std::vector<int> sv = serial_vertices(d, s);
            std::set<int> owned_serial;
            std::vector<char> owned(static_cast<size_t>(L.mesh.n_vertices()), 0);
            for (const int v : d.part.owned_vertices) {
                owned[static_cast<size_t>(v)] = 1;
                owned_serial.insert(sv[static_cast<size_t>(v)]);
            }
            // Owned nodes: each serial node once over all processes, the same element.
            std::vector<int> count(s.contacts.size(), 0);
            EXPECT_EQ(L.lambda_dof.size(), L.contacts.size());
            for (size_t e = 0; e < L.contacts.size(); ++e) {
                const int v = L.contacts[e].vertex[0];
                EXPECT_TRUE(owned[static_cast<size_t>(v)]) << "element " << e;
                const int se = s.contact_of_vertex[static_cast<size_t>(sv[static_cast<size_t>(v)])];
                EXPECT_GE(se, 0) << "element " << e << " is at no serial contact node";
                if (se < 0) continue; // (no ASSERT before the collective sum below)
                ++count[static_cast<size_t>(se)];
                expect_same_element(L.contacts[e], sv, s.contacts[static_cast<size_t>(se)],
                                    "element " + std::to_string(e));
                EXPECT_EQ(L.lambda_dof[e], L.dofs.extra_dof(v));
                EXPECT_EQ(L.contact_of_vertex[static_cast<size_t>(v)], static_cast<int>(e));
            }
            comm.allreduce(std::span<int>(count), ReduceOp::sum);
            for (size_t e = 0; e < count.size(); ++e)
                EXPECT_EQ(count[e], 1) << "serial element " << e;
            EXPECT_EQ(d.n_global_contacts, s.n_contact_nodes());
            // Two-body pairs cut by the partition: some process holds ghost elements.
            const int n_ghost = comm.sum(static_cast<int>(L.ghost_contacts.size()));
            if (comm.size() > 1 && s.contacts.front().n_nodes() > 1) {
                EXPECT_GT(n_ghost, 0);
            }
            // Multipliers and pinned components of every local vertex, ghosts included.
            for (int v = 0; v < L.mesh.n_vertices(); ++v) {
                const int w = sv[static_cast<size_t>(v)];
                const int se = s.contact_of_vertex[static_cast<size_t>(w)];
                EXPECT_EQ(d.n_extra[static_cast<size_t>(v)], serial_n_extra(s, w))
                    << "vertex " << v;
                EXPECT_EQ(d.pinned[static_cast<size_t>(v)],
                          se < 0 ? 0 : s.contacts[static_cast<size_t>(se)].pinned)
                    << "vertex " << v;
            }
            // Ghost elements: the serial elements of other processes' nodes that reach an owned
            // vertex (a target vertex of weight 0 may differ with the order of the faces).
            std::set<int> ghost_serial;
            EXPECT_EQ(L.ghost_lambda_dof.size(), L.ghost_contacts.size());
            for (size_t e = 0; e < L.ghost_contacts.size(); ++e) {
                const auto& el = L.ghost_contacts[e];
                const int v = el.vertex[0];
                EXPECT_FALSE(owned[static_cast<size_t>(v)]) << "ghost element " << e;
                bool reaches_owned = false;
                for (int j = 1; j < el.n_nodes(); ++j)
                    reaches_owned = reaches_owned ||
                                    owned[static_cast<size_t>(el.vertex[static_cast<size_t>(j)])];
                EXPECT_TRUE(reaches_owned) << "ghost element " << e;
                const int se = s.contact_of_vertex[static_cast<size_t>(sv[static_cast<size_t>(v)])];
                EXPECT_GE(se, 0) << "ghost element " << e << " is at no serial contact node";
                if (se < 0) continue;
                EXPECT_TRUE(ghost_serial.insert(se).second) << "ghost element " << e << " twice";
                expect_same_element(el, sv, s.contacts[static_cast<size_t>(se)],
                                    "ghost element " + std::to_string(e));
                EXPECT_EQ(L.ghost_lambda_dof[e], L.dofs.extra_dof(v));
            }
            for (size_t e = 0; e < s.contacts.size(); ++e) {
                const auto& el = s.contacts[e];
                if (!owned_serial.count(el.vertex[0]) && reaches(el, owned_serial)) {
                    EXPECT_EQ(ghost_serial.count(static_cast<int>(e)), 1U)
                        << "serial element " << e;
                }
                if (owned_serial.count(el.vertex[0]) || el.n_nodes() == 1) {
                    EXPECT_EQ(ghost_serial.count(static_cast<int>(e)), 0U)
                        << "serial element " << e;
                }
            }
        }
}

TEST(Distributed3Levels, OnOneProcessThePartsContactsAreBuildLevels) {
    if (comm::world().size() != 1) GTEST_SKIP() << "one process only";
    for (const auto& [name, bp] : contact_scenes())
        for (size_t l = 0; l < 2; ++l) {
            SCOPED_TRACE(name + " level " + std::to_string(l));
            const auto& L = bp->dist.levels[l].local;
            const auto& s = bp->serial.levels[l];
            ASSERT_EQ(L.mesh.n_vertices(), s.mesh.n_vertices());
            ASSERT_EQ(L.contacts.size(), s.contacts.size());
            EXPECT_TRUE(L.ghost_contacts.empty());
            EXPECT_EQ(L.lambda_dof, s.lambda_dof);
            EXPECT_EQ(L.contact_of_vertex, s.contact_of_vertex);
            EXPECT_EQ(L.not_found, s.not_found);
            ASSERT_EQ(L.dofs.n_dofs(), s.dofs.n_dofs());
            for (int v = 0; v < s.mesh.n_vertices(); ++v) {
                EXPECT_EQ(L.dofs.extra_dof(v), s.dofs.extra_dof(v)) << "vertex " << v;
                for (int c = 0; c < 3; ++c)
                    EXPECT_EQ(L.dofs.u_dof(v, c), s.dofs.u_dof(v, c)) << "vertex " << v;
            }
            for (size_t e = 0; e < s.contacts.size(); ++e) {
                const auto& a = L.contacts[e];
                const auto& b = s.contacts[e];
                EXPECT_EQ(a.vertex, b.vertex) << "element " << e;
                EXPECT_EQ(a.weight, b.weight) << "element " << e;
                EXPECT_EQ(a.n, b.n) << "element " << e;
                EXPECT_EQ(a.t, b.t) << "element " << e;
                EXPECT_EQ(a.g0, b.g0) << "element " << e;
                EXPECT_EQ(a.pinned, b.pinned) << "element " << e;
                EXPECT_EQ(a.mu, b.mu) << "element " << e;
                EXPECT_EQ(a.r, b.r) << "element " << e;
            }
        }
}

TEST(Distributed3Levels, OwnedContactResidualAndJacobianRowsAreTheSerialOnes) {
    const Communicator& comm = comm::world();
    for (const auto& [name, bp] : contact_scenes())
        for (size_t l = 0; l < 2; ++l) {
            SCOPED_TRACE(name + " level " + std::to_string(l));
            const auto& d = bp->dist.levels[l];
            const auto& s = bp->serial.levels[l];
            const auto& L = d.local;
            const double a = 1e-3 * s.mesh.diameter();
            const State3 st = serial_state(s, a);
            // Serial rows; the state puts nodes in every status.
            Vector Rs = Vector::Zero(s.dofs.n_dofs());
            std::map<std::pair<Index, Index>, double> Js;
            levels::StatusCounts counts;
            contact_rows(s, s.contacts, s.lambda_dof, st.x, st.u_prev_full, Rs, Js, &counts);
            EXPECT_GT(counts.gap, 0);
            EXPECT_GT(counts.stick + counts.slip, 0);
            if (s.contacts.front().frictional()) {
                EXPECT_GT(counts.stick, 0);
                EXPECT_GT(counts.slip, 0);
            }
            // The part's: owned unknowns from the serial state, ghosts from their owners.
            const std::vector<Index> to_serial = serial_dofs(d, s);
            const State3 ps = part_state(d, s, st);
            const Vector& x = ps.x;
            const Vector& u_prev = ps.u_prev_full;
            Vector R = Vector::Zero(L.dofs.n_dofs());
            std::map<std::pair<Index, Index>, double> J;
            contact_rows(L, L.contacts, L.lambda_dof, x, u_prev, R, J, nullptr);
            contact_rows(L, L.ghost_contacts, L.ghost_lambda_dof, x, u_prev, R, J, nullptr);
            // Residual: the owned rows.
            const double r_scale = Rs.cwiseAbs().maxCoeff();
            ASSERT_GT(r_scale, 0.0);
            std::set<Index> owned_rows;
            for (Index i = 0; i < d.n_owned; ++i) {
                const Index si = to_serial[static_cast<size_t>(i)];
                owned_rows.insert(si);
                EXPECT_NEAR(R[i], Rs[si], 1e-12 * r_scale) << "owned row " << i;
            }
            // Jacobian: the entries of the owned rows, in serial numbering.
            std::map<std::pair<Index, Index>, double> Jp;
            for (const auto& [ij, v] : J)
                if (ij.first < d.n_owned)
                    Jp[{to_serial[static_cast<size_t>(ij.first)],
                        to_serial[static_cast<size_t>(ij.second)]}] += v;
            double j_scale = 0.0;
            for (const auto& [ij, v] : Js)
                j_scale = std::max(j_scale, std::abs(v));
            ASSERT_GT(j_scale, 0.0);
            int compared = 0;
            for (const auto& [ij, v] : Js) {
                if (!owned_rows.count(ij.first)) continue;
                const auto it = Jp.find(ij);
                EXPECT_NEAR(it == Jp.end() ? 0.0 : it->second, v, 1e-12 * j_scale)
                    << "serial entry (" << ij.first << ", " << ij.second << ")";
                ++compared;
            }
            for (const auto& [ij, v] : Jp) {
                if (!Js.count(ij)) {
                    EXPECT_NEAR(v, 0.0, 1e-12 * j_scale)
                        << "serial entry (" << ij.first << ", " << ij.second << ") not in serial";
                }
            }
            // Every serial entry of a contact row is compared on some process.
            EXPECT_EQ(comm.sum(compared), static_cast<int>(Js.size()));
        }
}

TEST(Distributed3Levels, PairWithoutContactNodeIsRefusedOnEveryProcess) {
    levels::ElasticProblem3 p = scene::load_scene3("block3d");
    levels::Box3 away;
    away.lo = mesh::Vec3(100.0, 100.0, 100.0);
    away.hi = mesh::Vec3(101.0, 101.0, 101.0);
    p.contacts.at(0).region = away;
    EXPECT_THROW(levels::build_distributed_hierarchy3(p, 0, 0, comm::world()), InvalidInput);
}

TEST(Distributed3Levels, GhostReachOfStack3dIsTwiceTheSearchReach) {
    const levels::ElasticProblem3 p = scene::load_scene3("stack3d");
    const auto reach = levels::contact_ghost_reach3(p, p.mesh0);
    ASSERT_EQ(reach.size(), 1U);
    EXPECT_EQ(reach[0].tags,
              (std::vector<int>{p.mesh0.tag("upper_bottom"), p.mesh0.tag("lower_top")}));
    // h0 = hp = the diagonal of the lower block's 0.25 x 0.25 face squares (the longest edge of
    // both faces on level 0); search_radius 2: 2 ((2 + 2) h0 + 2 hp) = 12 h0.
    ASSERT_EQ(p.contacts[0].search_radius, 2.0);
    EXPECT_NEAR(reach[0].distance, 12.0 * 0.25 * std::sqrt(2.0), 1e-12);
    // Without a two-body pair, no reach.
    EXPECT_TRUE(levels::contact_ghost_reach3(scene::load_scene3("block3d"),
                                             scene::load_scene3("block3d").mesh0)
                    .empty());
}

#endif
