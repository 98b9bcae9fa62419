// SPDX-License-Identifier: MIT
// The distributed solve (levels/distributed_solve.hpp) against the one-process solve, on any
// number of processes: ctest runs these tests alone (one process: the distributed code on
// comm::world(), the serial communicator) and under mpirun -np 2 and -np 3 (label mpi). Every
// process compares the contact nodes it owns with the one-process run's, matched by their exact
// coordinates. The partition-level rule is checked against its closed form everywhere. Two-body
// scenes: the contact elements of every part, owned and ghost, are the one-process
// level's, and patch and dovetail give the one-process answer.
#include "levels/distributed.hpp"

#include "core/check.hpp"

#include <gtest/gtest.h>

using namespace mlc;

TEST(PartitionLevel, IsTheCoarsestLevelWithTwoThousandTrianglesPerProcessBelowTheFinest) {
    // The square's level 0 has 512 triangles; level l has 512 * 4^l.
    EXPECT_EQ(levels::partition_level(512, 6, 1), 1);    // 2 048 >= 2 000
    EXPECT_EQ(levels::partition_level(512, 6, 2), 2);    // 4 000 needed: 8 192
    EXPECT_EQ(levels::partition_level(512, 6, 4), 2);    // 8 000 needed: 8 192
    EXPECT_EQ(levels::partition_level(512, 6, 5), 3);    // 10 000 needed: 32 768
    EXPECT_EQ(levels::partition_level(512, 3, 1000), 2); // at most finest - 1
    EXPECT_EQ(levels::partition_level(512, 1, 64), 0);
    EXPECT_EQ(levels::partition_level(100000, 4, 2), 0); // level 0 is large enough
    EXPECT_THROW(levels::partition_level(512, 3, 0), InvalidInput);
}

#if MLC_HAVE_HYPRE
#include "comm/world.hpp"
#include "levels/checks.hpp"
#include "levels/distributed_solve.hpp"
#include "scene/scene.hpp"

#include "levels/resources.hpp"
#include "mesh/distributed.hpp"

#include <cmath>
#include <map>
#include <set>

namespace {

using Point = std::pair<double, double>;

/// The square scene on a 4 x 4 level 0 (32 macro triangles): level 4 has the 16 subdivisions
/// per macro edge the lattice sweep needs at 8 192 triangles.
levels::Problem coarse_square() {
    std::string text = scene::builtin_scene_text("square");
    const std::string from = "divisions = [16, 16]";
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "the square scene has no '" << from << "'";
    if (at != std::string::npos) text.replace(at, from.size(), "divisions = [4, 4]");
    return scene::parse_scene(text, "coarse square");
}

levels::DistributedRunResult
expect_same_answer(const std::string& scene, int levels, int p, const std::string& krylov = "cgs",
                   const std::string& pc = "mg",
                   levels::Problem::Numbering numbering = levels::Problem::Numbering::hilbert) {
    const Communicator& comm = comm::world();
    levels::Problem prob = scene == "coarse square" ? coarse_square() : scene::load_scene(scene);
    prob.levels = levels;
    prob.numbering = numbering;
    prob.newton.rel_tol = 1e-12;
    levels::SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::parse_krylov(krylov),
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = 1e-12};
    const levels::RunResult one = levels::solve(prob, so);
    levels::DistributedRunResult d = levels::solve_distributed(prob, so, comm, p);
    EXPECT_TRUE(one.converged) << one.failure;
    EXPECT_TRUE(d.converged) << d.failure;
    if (!one.converged || !d.converged) return d;
    EXPECT_EQ(d.n_processes, comm.size());
    EXPECT_EQ(d.completed_steps, prob.load_steps);
    EXPECT_EQ(d.finest().n_global_dofs, one.finest().n_unknowns());
    EXPECT_EQ(d.finest().n_global_contacts, one.finest().n_contact_nodes());
    EXPECT_EQ(comm.sum(static_cast<int>(d.nodes.size())), one.finest().n_contact_nodes());
    std::map<Point, levels::ContactNodeState> ref;
    double u_scale = 0, l_scale = 0;
    for (const auto& n : one.nodes) {
        ref[{n.x.x(), n.x.y()}] = n;
        u_scale = std::max(u_scale, n.u.cwiseAbs().maxCoeff());
        l_scale = std::max({l_scale, std::abs(n.lambda_t), std::abs(n.lambda_n)});
    }
    EXPECT_GT(u_scale, 0);
    EXPECT_GT(l_scale, 0);
    for (const auto& n : d.nodes) {
        const auto it = ref.find({n.x.x(), n.x.y()});
        EXPECT_NE(it, ref.end()) << "no contact node at (" << n.x.x() << ", " << n.x.y() << ")";
        if (it == ref.end()) continue;
        EXPECT_EQ(n.status, it->second.status);
        EXPECT_LE((n.u - it->second.u).cwiseAbs().maxCoeff(), 1e-8 * u_scale);
        EXPECT_LE(std::abs(n.lambda_t - it->second.lambda_t), 1e-8 * l_scale);
        EXPECT_LE(std::abs(n.lambda_n - it->second.lambda_n), 1e-8 * l_scale);
    }
    // The reduced checks and the status counts of every step are the one process's.
    const levels::StateChecks c1 = levels::check_state(prob, one);
    const levels::StateChecks cd = levels::check_state(prob, d, comm);
    EXPECT_LE(cd.force_balance, std::max(10 * c1.force_balance, 1e-11));
    EXPECT_LE(cd.penetration, std::max(10 * c1.penetration, 1e-12));
    EXPECT_EQ(d.steps.size(), one.steps.size());
    for (size_t k = 0; k < std::min(d.steps.size(), one.steps.size()); ++k) {
        EXPECT_EQ(d.steps[k].counts.gap, one.steps[k].counts.gap) << "step " << k + 1;
        EXPECT_EQ(d.steps[k].counts.stick, one.steps[k].counts.stick) << "step " << k + 1;
        EXPECT_EQ(d.steps[k].counts.total(), one.steps[k].counts.total()) << "step " << k + 1;
    }
    return d;
}

/// The contact elements of a distributed level, owned and ghost, are the one-process level's:
/// the same target vertices (matched by coordinates), weights, normal and gap.
void expect_same_elements(const levels::Problem& prob, int p) {
    const Communicator& comm = comm::world();
    mesh::Mesh m = prob.mesh0;
    for (int l = 0; l < prob.levels; ++l)
        m = mesh::refine(m);
    const levels::Level one = levels::build_level(prob, m);
    std::map<Point, const contact::ContactElement*> ref;
    for (const auto& e : one.contacts) {
        const Vec2& x = one.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        ref[{x.x(), x.y()}] = &e;
    }
    mesh::Mesh mp = prob.mesh0;
    for (int l = 0; l < p; ++l)
        mp = mesh::refine(mp);
    auto h = mesh::distribute(mp, prob.levels - p, comm, {}, levels::contact_ghost_reach(prob, mp));
    const levels::DistributedLevel d =
        levels::build_distributed_level(prob, std::move(h.levels.back()), comm);
    const auto& L = d.local;
    auto check = [&](const contact::ContactElement& e) {
        const Vec2& x = L.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        const auto it = ref.find({x.x(), x.y()});
        ASSERT_NE(it, ref.end()) << "no contact node at (" << x.x() << ", " << x.y() << ")";
        const contact::ContactElement& r = *it->second;
        ASSERT_EQ(e.n_nodes(), r.n_nodes());
        std::map<Point, double> wr;
        for (int j = 1; j < r.n_nodes(); ++j) {
            const Vec2& y =
                one.mesh.vertices[static_cast<size_t>(r.vertex[static_cast<size_t>(j)])];
            wr[{y.x(), y.y()}] = r.weight[static_cast<size_t>(j)];
        }
        for (int j = 1; j < e.n_nodes(); ++j) {
            const Vec2& y = L.mesh.vertices[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])];
            const auto w = wr.find({y.x(), y.y()});
            ASSERT_NE(w, wr.end()) << "a target vertex the one-process element does not have";
            EXPECT_NEAR(e.weight[static_cast<size_t>(j)], w->second, 1e-14);
        }
        EXPECT_LE((e.n - r.n).norm(), 1e-14);
        EXPECT_NEAR(e.g0, r.g0, 1e-14 * (1 + std::abs(r.g0)));
    };
    for (const auto& e : L.contacts)
        check(e);
    for (const auto& e : L.ghost_contacts)
        check(e);
    EXPECT_EQ(comm.sum(L.n_contact_nodes()), one.n_contact_nodes());
    // Every element whose targets another process owns is among that process's ghost elements:
    // count the (element, process) pairs both ways.
    std::int64_t reaching = 0;
    for (const auto& e : L.contacts) {
        std::set<int> others;
        for (int j = 1; j < e.n_nodes(); ++j) {
            const int o =
                d.part.vertex_owner[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])];
            if (o != comm.rank()) others.insert(o);
        }
        reaching += static_cast<std::int64_t>(others.size());
    }
    EXPECT_EQ(comm.sum(reaching), comm.sum(static_cast<std::int64_t>(L.ghost_contacts.size())));
    if (comm.size() > 1) {
        EXPECT_GT(comm.sum(reaching), 0) << "the interface is not cut";
    }
}

} // namespace

TEST(DistributedSolve, TwoBodyElementsAreTheOneProcessElements) {
    for (const auto integration :
         {contact::FacetIntegration::nodal, contact::FacetIntegration::segment,
          contact::FacetIntegration::dual}) {
        SCOPED_TRACE(contact::to_string(integration));
        levels::Problem prob = scene::load_scene("patch");
        prob.levels = 2;
        prob.contacts[0].integration = integration;
        expect_same_elements(prob, 0);
        expect_same_elements(prob, 1);
    }
    levels::Problem dove = scene::load_scene("dovetail");
    dove.levels = 2;
    expect_same_elements(dove, 0);
    levels::Problem matching = scene::load_scene("patch_matching");
    matching.levels = 2;
    expect_same_elements(matching, 1);
}

TEST(DistributedSolve, PatchLevelTwoIsTheOneProcessAnswer) {
    expect_same_answer("patch", 2, 0, "bicgstab", levels::kMgDefaultTwoBody);
}

TEST(DistributedSolve, DovetailLevelOneIsTheOneProcessAnswer) {
    expect_same_answer("dovetail", 1, 0, "bicgstab", levels::kMgDefaultTwoBody);
}

TEST(DistributedSolve, SquareLevelThreeIsTheOneProcessAnswer) {
    expect_same_answer("square", 3, 1);
}

TEST(DistributedSolve, HertzLevelTwoIsTheOneProcessAnswer) {
    expect_same_answer("hertz", 2, 1);
}

TEST(DistributedSolve, EbeOnEachProcessBlockIsTheOneProcessAnswer) {
    // EBE (C1) from each process's elements restricted to its owned unknowns, coloured within
    // the process, Jacobi across the cuts; level 0 whole, level 1 distributed (the driver's
    // test, tests/output/test_distributed_run.py, runs level 2). BiCGStab: CGS with EBE on 2
    // processes stalls on level 2 (docs/solver-guide.md); BiCGStab needs about as many
    // iterations as on one process.
    expect_same_answer("square", 1, 0, "bicgstab", "ebe");
}

TEST(DistributedSolve, LatticeSweepOnEachProcessIsTheOneProcessAnswer) {
    // mg:smoother=lattice on level 4 (16 subdivisions per macro edge): one process sweeps its
    // whole level by macro triangles; on several, each process sweeps the macros it owns whole
    // (numbered by lattices, Problem::Numbering::lattice) and the rest of its diagonal block by
    // vertex blocks, Jacobi across the cuts. The level below keeps the vertex-block sweep.
    const levels::DistributedRunResult d =
        expect_same_answer("coarse square", 4, 2, "bicgstab", "mg:pre=0,post=2,smoother=lattice",
                           levels::Problem::Numbering::lattice);
    ASSERT_FALSE(d.levels.empty());
    const auto& rows = d.finest().local.lattice;
    ASSERT_NE(rows, nullptr);
    EXPECT_EQ(rows->n, 16);
    // Every macro a process owns whole is numbered as a lattice on its owned rows, and together
    // the processes own at least half of the 32 macros whole.
    long lattice_macros = 0;
    for (long m = 0; m < rows->macros(); ++m) {
        const Index base = rows->lattice_base(m);
        if (base >= 0) ++lattice_macros;
        EXPECT_LT(base, d.finest().n_owned);
    }
    const Communicator& comm = comm::world();
    EXPECT_EQ(comm.sum(static_cast<int>(rows->macros())),
              comm.sum(static_cast<int>(lattice_macros)));
    EXPECT_GE(comm.sum(static_cast<int>(lattice_macros)), 16);
    if (comm.size() == 1) {
        EXPECT_EQ(lattice_macros, 32);
    }
    // The level below keeps the Hilbert numbering and the vertex-block sweep.
    EXPECT_EQ(d.levels[d.levels.size() - 2].local.lattice, nullptr);
}

TEST(DistributedSolve, SinglePrecisionOnEachProcessIsTheOneProcessAnswer) {
    // mg:precision=single: each process's smoother keeps its diagonal block's values and block
    // inverses in float32 (the transfers, hypre's, stay double).
    expect_same_answer("coarse square", 4, 2, "bicgstab", "mg:pre=0,post=2,precision=single");
}

TEST(DistributedSolve, RefusesWhatHasNoDistributedForm) {
    const Communicator& comm = comm::world();
    levels::Problem prob = scene::load_scene("square");
    prob.levels = 2;
    levels::SolveOptions so;
    so.linear.method = solvers::Method::schur;
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 1), InvalidInput);
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg:coarse=galerkin")};
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 1), InvalidInput);
    so.linear.pc = solvers::parse_pc("mg:coarse=aggregation");
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 1), InvalidInput);
    so.linear.pc =
        solvers::parse_pc("mg:smoother=lattice,precision=single"); // not on one process either
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 1), InvalidInput);
    so.linear.pc = solvers::parse_pc("sorcf");
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 1), InvalidInput);
    // A bad option is refused where the spec is read, before any process solves.
    EXPECT_THROW((void)solvers::parse_pc("ebe:variant=c9"), InvalidInput);
    so.linear.pc = solvers::parse_pc("mg");
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 2), InvalidInput); // p = L
    so.coarse_to_fine = false;
    EXPECT_THROW(levels::solve_distributed(prob, so, comm, 1), InvalidInput);
}
#endif
