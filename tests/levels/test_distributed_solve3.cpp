// SPDX-License-Identifier: MIT
// The distributed 3D solve (levels/distributed_solve3.hpp) against the one-process solve
// (levels::solve), on any number of processes: ctest runs these tests alone (one process) and
// under mpirun -np 1, 2 and 3 (label mpi). With the Newton and Krylov tolerances at 1e-12 every
// process's displacements and its contact nodes' multipliers equal the one-process ones to 1e-8
// of their largest magnitude, with the same status, on block3d (rigid plane, friction) and
// stack3d (two bodies, non-matching meshes, segment weights; with friction too); every serial
// contact node is owned by exactly one process.
#include "core/check.hpp"

#include <gtest/gtest.h>

#if MLC_HAVE_HYPRE
#include "comm/world.hpp"
#include "levels/distributed_solve3.hpp"
#include "scene/scene3.hpp"
#include "tests/levels/distributed3_fixtures.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

using namespace mlc;

namespace {

levels::SolveOptions3 tight_options() {
    levels::SolveOptions3 o;
    o.krylov_rel_tol = 1e-12;
    return o;
}

/// Solves `p` on one process and distributed (partition level `plevel`) and compares the
/// finest level's owned displacements and contact nodes; every distributed Newton system takes at
/// most 30 GMRES iterations.
void expect_distributed_equals_serial(levels::ElasticProblem3 p, int plevel) {
    const Communicator& comm = comm::world();
    p.newton.rel_tol = 1e-12;
    const auto serial = levels::solve(p, tight_options());
    ASSERT_TRUE(serial.converged) << serial.failure;
    const auto dist = levels::solve_distributed3(p, tight_options(), comm, plevel);
    ASSERT_TRUE(dist.converged) << dist.failure;
    EXPECT_EQ(dist.completed_steps, p.load_steps);
    EXPECT_EQ(static_cast<int>(dist.steps.size()), p.load_steps);
    const levels::Level3& s = serial.finest();
    const levels::DistributedLevel3& d = dist.finest();
    const std::vector<int> sv = distributed3_fixtures::serial_vertices(d, s);
    // Displacements of the owned vertices (the ghosts' come from their owners).
    const double u_scale = serial.u_full.cwiseAbs().maxCoeff();
    ASSERT_GT(u_scale, 0.0);
    double u_err = 0.0;
    for (const int v : d.part.owned_vertices)
        for (int c = 0; c < 3; ++c)
            u_err = std::max(u_err, std::abs(dist.u_full[3 * v + c] -
                                             serial.u_full[3 * sv[static_cast<size_t>(v)] + c]));
    EXPECT_LE(comm.max(u_err), 1e-8 * u_scale);
    // Contact nodes: each serial node owned once, same multipliers and status.
    std::map<int, const levels::ContactNodeState3*> by_vertex;
    double l_scale = 0.0;
    for (const auto& n : serial.nodes) {
        by_vertex[n.vertex] = &n;
        l_scale = std::max({l_scale, std::abs(n.lambda_n), n.lambda_t.cwiseAbs().maxCoeff()});
    }
    ASSERT_GT(l_scale, 0.0);
    double l_err = 0.0;
    int same_status = 0, in_contact = 0;
    for (const auto& n : dist.nodes) {
        const auto it = by_vertex.find(sv[static_cast<size_t>(n.vertex)]);
        ASSERT_NE(it, by_vertex.end()) << "a distributed contact node is no serial one";
        const auto& r = *it->second;
        l_err = std::max({l_err, std::abs(n.lambda_n - r.lambda_n),
                          (n.lambda_t - r.lambda_t).cwiseAbs().maxCoeff()});
        same_status += n.status == r.status;
        in_contact += n.status != contact::Status::gap;
    }
    EXPECT_EQ(comm.sum(static_cast<int>(dist.nodes.size())), static_cast<int>(serial.nodes.size()));
    EXPECT_EQ(comm.sum(same_status), static_cast<int>(serial.nodes.size()));
    EXPECT_GT(comm.sum(in_contact), 0);
    EXPECT_LE(comm.max(l_err), 1e-8 * l_scale);
    // The finest level's status counts of every step, summed over the processes.
    ASSERT_EQ(dist.steps.size(), serial.steps.size());
    for (size_t k = 0; k < serial.steps.size(); ++k) {
        const auto& a = serial.steps[k].counts;
        const auto& b = dist.steps[k].counts;
        EXPECT_EQ(b.total(), static_cast<int>(serial.nodes.size())) << "step " << k + 1;
        EXPECT_EQ(std::tuple(b.gap, b.stick, b.slip), std::tuple(a.gap, a.stick, a.slip))
            << "step " << k + 1;
    }
    // Every distributed Newton system was solved by the distributed multigrid.
    EXPECT_NE(dist.solver.find("distributed mg"), std::string::npos) << dist.solver;
    for (const auto& st : dist.steps)
        for (const int its : st.linear_iterations_per_newton)
            EXPECT_LE(its, 30);
}

} // namespace

TEST(DistributedSolve3, Block3dLevel1EqualsOneProcess) {
    auto p = scene::load_scene3("block3d");
    p.levels = 1;
    expect_distributed_equals_serial(std::move(p), 0);
}

TEST(DistributedSolve3, Block3dLevel2FromPartitionLevel0EqualsOneProcess) {
    auto p = scene::load_scene3("block3d");
    p.levels = 2;
    expect_distributed_equals_serial(std::move(p), 0);
}

TEST(DistributedSolve3, Stack3dLevel1EqualsOneProcess) {
    auto p = scene::load_scene3("stack3d");
    p.levels = 1;
    expect_distributed_equals_serial(std::move(p), 0);
}

TEST(DistributedSolve3, Stack3dWithFrictionLevel1EqualsOneProcess) {
    auto p = scene::load_scene3("stack3d");
    p.levels = 1;
    p.contacts.at(0).mu = 0.3;
    expect_distributed_equals_serial(std::move(p), 0);
}

TEST(DistributedSolve3, WhatHasNoDistributedFormIsRefusedOnEveryProcess) {
    auto p = scene::load_scene3("block3d");
    p.levels = 1;
    levels::SolveOptions3 o;
    o.upper = levels::Method3::lu;
    EXPECT_THROW(levels::solve_distributed3(p, o, comm::world(), 0), InvalidInput);
    o = {};
    o.coarse_to_fine = false;
    EXPECT_THROW(levels::solve_distributed3(p, o, comm::world(), 0), InvalidInput);
    EXPECT_THROW(levels::solve_distributed3(p, {}, comm::world(), 1), InvalidInput);
    p.levels = 0;
    EXPECT_THROW(levels::solve_distributed3(p, {}, comm::world(), 0), InvalidInput);
}

#endif
