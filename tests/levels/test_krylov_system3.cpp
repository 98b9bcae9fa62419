// SPDX-License-Identifier: MIT
// The 3D Newton systems by a Krylov method with a preconditioner of the registry: the coarse/fine
// split of a 3D level, the solution every preconditioner of the 3D family gives (the multigrid's,
// to the tolerances), CF's iteration counts, and the refusals.
#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "levels/solve3.hpp"
#include "scene/scene3.hpp"
#include "solvers/pc_spec.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

using namespace mlc;

namespace {

levels::ElasticProblem3 tight_block3d(int levels) {
    auto p = scene::load_scene3("block3d");
    p.levels = levels;
    p.newton.rel_tol = 1e-12;
    return p;
}

levels::SolveOptions3 with_pc(const std::string& pc) {
    levels::SolveOptions3 so;
    so.krylov_rel_tol = 1e-12;
    so.upper = levels::Method3::krylov;
    so.krylov.pc = solvers::parse_pc(pc);
    return so;
}

} // namespace

// block3d's levels 0 and 1: every coarse unknown has its fine unknown in the coarse set (the
// displacements of a coarse vertex keep their component; each multiplier of a coarse contact node
// maps to its own component with the surface Q's weight, a mass ratio in (0, 1)), and the fine set
// is the rest, in one block per vertex.
TEST(KrylovSystem3, CoarseFineSplitTakesEveryCoarseUnknownOnce) {
    const auto p = tight_block3d(1);
    const levels::Hierarchy3 H = levels::build_hierarchy(p, 1);
    const auto& C = H.levels[0];
    const auto& F = H.levels[1];
    const levels::MultiplierTransfer3 q(C, F, levels::contactor_faces(p, C),
                                        levels::contactor_faces(p, F));
    const SparseMatrix T = levels::full_prolongation3(H.transfers[0].T, q);
    const auto s =
        levels::coarse_fine_split3(F, C, H.transfers[0].P_vertex, T, solvers::MultiplierScale::q);
    ASSERT_EQ(static_cast<Index>(s.coarse_set.size()), C.n_unknowns());
    EXPECT_EQ(static_cast<Index>(s.coarse_set.size() + s.fine_set.size()), F.n_unknowns());
    EXPECT_EQ(std::set<int>(s.coarse_dof.begin(), s.coarse_dof.end()).size(), s.coarse_dof.size());
    int multipliers = 0;
    for (size_t k = 0; k < s.coarse_set.size(); ++k) {
        const int i = s.coarse_set[k], c = s.coarse_dof[k];
        ASSERT_EQ(F.dofs.is_displacement(i), C.dofs.is_displacement(c));
        if (F.dofs.is_displacement(i)) {
            EXPECT_EQ(s.prolong_scale[k], 1.0);
            EXPECT_EQ(T.coeff(i, c), 1.0); // the vertex's own displacement, injected
        } else {
            ++multipliers;
            EXPECT_GT(s.prolong_scale[k], 0.0);
            EXPECT_LT(s.prolong_scale[k], 1.0);
            EXPECT_EQ(s.prolong_scale[k], T.coeff(i, c));
            EXPECT_EQ(s.restrict_scale[k], 1.0);
        }
    }
    EXPECT_GT(multipliers, 0);
    EXPECT_EQ(s.fine_block_starts.front(), 0);
}

namespace {

/// block3d on levels 0-1 with friction, solved with `pc` above level 0: the multigrid's solution
/// to the Newton and Krylov tolerances (1e-12); returns the most Krylov iterations of a Newton
/// step of level 1.
int expect_the_multigrid_solution(const std::string& pc) {
    const auto p = tight_block3d(1);
    levels::SolveOptions3 ref_options;
    ref_options.krylov_rel_tol = 1e-12;
    static const auto ref = levels::solve(p, ref_options);
    EXPECT_TRUE(ref.converged) << ref.failure;
    const double xs = ref.x.cwiseAbs().maxCoeff();
    const auto r = levels::solve(p, with_pc(pc));
    EXPECT_TRUE(r.converged) << pc << ": " << r.failure;
    if (!r.converged) return -1;
    EXPECT_LE((r.x - ref.x).cwiseAbs().maxCoeff(), 1e-8 * xs) << pc;
    int newton = 0, most = 0;
    for (const auto& st : r.level_steps[1])
        for (const int k : st.report.linear_iterations_per_newton) {
            ++newton;
            most = std::max(most, k);
        }
    EXPECT_GT(newton, 0) << pc;
    EXPECT_GT(most, 0) << pc;
    return most;
}

} // namespace

// CF: the multigrid's solution, with few iterations per Newton step (the level below's exact
// solve does most of the work).
TEST(KrylovSystem3, CfGivesTheMultigridSolution) {
    EXPECT_LE(expect_the_multigrid_solution("cf"), 40) << "CF's Krylov iterations per Newton step";
}

// ILU(0), SORCF and hypre's MGR (with hypre): the multigrid's solution.
TEST(KrylovSystem3, EveryOtherPreconditionerOfThe3dFamilyGivesTheMultigridSolution) {
    std::vector<std::string> pcs = {"ilu:0", "sorcf"};
#ifdef MLC_HAVE_HYPRE
    pcs.push_back("mgr");
#endif
    for (const auto& pc : pcs)
        expect_the_multigrid_solution(pc);
}

// What has no 3D form, or needs the level below without it, is refused naming why.
TEST(KrylovSystem3, WhatHasNo3dFormIsRefused) {
    auto p = tight_block3d(1);
    auto refused = [&](const levels::SolveOptions3& so, const std::string& words) {
        try {
            (void)levels::solve(p, so);
            ADD_FAILURE() << "not refused: " << words;
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    refused(with_pc("ebe"), "2D-only");
    auto cold = with_pc("cf");
    cold.coarse_to_fine = false;
    refused(cold, "needs the level below's converged statuses");
}
