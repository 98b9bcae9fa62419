// SPDX-License-Identifier: MIT
// The algebraic hierarchy of mg (solvers/aggregation.hpp) on the square's level 2: the tentative
// prolongation reproduces the rigid modes of every aggregate (a constant per displacement
// component, and the rotation), Q shares each coarse force out so that the resultant is
// preserved, the smoothed T still reproduces them where K does not see the supports, the coarse K
// is T^T K T, and the levels coarsen down to the coarse size.
#include "core/check.hpp"
#include "levels/hierarchy.hpp"
#include "levels/krylov_system.hpp"
#include "scene/scene.hpp"
#include "solvers/aggregation.hpp"
#include "solvers/mg.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <set>

using namespace mlc;
using solvers::UnknownKind;

namespace {

struct SquareLevel {
    levels::Hierarchy h;
    solvers::AggregationInput in;
    explicit SquareLevel(int level) {
        auto p = scene::load_scene("square");
        p.levels = level;
        h = levels::build_hierarchy(p);
        in = levels::aggregation_input(h.finest());
    }
};

} // namespace

TEST(Aggregation, TentativeProlongationReproducesTheRigidModesOfEveryAggregate) {
    const SquareLevel s(2);
    ASSERT_EQ(s.in.near_null.cols(), 3); // translations and the rotation
    const auto step = solvers::aggregate_once(s.in, {});
    const Index nf = s.in.K->rows();
    ASSERT_EQ(step.P_tentative.rows(), nf);
    EXPECT_LT(step.n_aggregates * 6, s.h.finest().mesh.n_vertices()); // about 9 vertices each
    // P_tent B_c = B: a constant per component, and the rotation, on every displacement.
    const Eigen::MatrixXd PB = step.P_tentative * step.near_null_coarse;
    EXPECT_LT((PB - s.in.near_null).norm(), 1e-12 * s.in.near_null.norm());
    for (UnknownKind k : {UnknownKind::ux, UnknownKind::uy}) {
        const Vector f = PB.col(static_cast<Index>(k));
        for (Index i = 0; i < nf; ++i)
            EXPECT_NEAR(f[i], s.in.kind[static_cast<size_t>(i)] == k ? 1.0 : 0.0, 1e-13) << i;
    }
    // Its columns are orthonormal within each aggregate, and a fine unknown's coarse parents
    // all belong to its own aggregate.
    const Eigen::MatrixXd PtP =
        Eigen::MatrixXd(SparseMatrix(step.P_tentative.transpose()) * step.P_tentative);
    for (Index J = 0; J < PtP.rows(); ++J) {
        if (solvers::is_multiplier(step.coarse_kind[static_cast<size_t>(J)])) continue;
        EXPECT_NEAR(PtP(J, J), 1.0, 1e-12) << J;
    }
    for (Index i = 0; i < nf; ++i) {
        int parent = -1;
        for (SparseMatrix::InnerIterator it(step.P_tentative, i); it; ++it) {
            const int agg = step.coarse_vertex[static_cast<size_t>(it.col())];
            if (parent < 0) parent = agg;
            EXPECT_EQ(agg, parent) << i;
            EXPECT_EQ(solvers::is_multiplier(step.coarse_kind[static_cast<size_t>(it.col())]),
                      solvers::is_multiplier(s.in.kind[static_cast<size_t>(i)]));
        }
        EXPECT_GE(parent, 0) << i;
    }
}

TEST(Aggregation, MultipliersAreSharedOutAlongTheContactBoundaryPreservingTheResultant) {
    const SquareLevel s(2);
    const auto step = solvers::aggregate_once(s.in, {});
    const SparseMatrix PtT = step.P_tentative.transpose();
    int n_coarse_multipliers = 0, n_fine_multipliers = 0;
    for (UnknownKind k : s.in.kind)
        n_fine_multipliers += solvers::is_multiplier(k);
    std::set<int> contact_aggregates;
    for (Index J = 0; J < PtT.rows(); ++J) {
        if (!solvers::is_multiplier(step.coarse_kind[static_cast<size_t>(J)])) continue;
        ++n_coarse_multipliers;
        contact_aggregates.insert(step.coarse_vertex[static_cast<size_t>(J)]);
        double sum = 0.0;
        int members = 0;
        for (SparseMatrix::InnerIterator it(PtT, J); it; ++it) {
            sum += it.value();
            ++members;
        }
        EXPECT_NEAR(sum, 1.0, 1e-15) << "coarse multiplier " << J;
        EXPECT_GE(members, 1);
    }
    // 64 contact nodes on level 2 (t and n each), about three per aggregate (a node and its two
    // neighbours along the boundary; 22 aggregates measured), and the smoothed T keeps the
    // multiplier rows as they were (Q is not smoothed).
    EXPECT_GT(n_coarse_multipliers, 0);
    EXPECT_LE(5 * n_coarse_multipliers, 2 * n_fine_multipliers);
    for (Index i = 0; i < s.in.K->rows(); ++i) {
        if (!solvers::is_multiplier(s.in.kind[static_cast<size_t>(i)])) continue;
        for (SparseMatrix::InnerIterator it(step.T, i); it; ++it)
            EXPECT_EQ(it.value(), step.P_tentative.coeff(i, it.col()));
    }
    // The coarse unknowns of each aggregate are contiguous: rigid modes, then its multipliers.
    for (size_t J = 1; J < step.coarse_vertex.size(); ++J) {
        if (step.coarse_vertex[J] == step.coarse_vertex[J - 1])
            EXPECT_TRUE(!solvers::is_multiplier(step.coarse_kind[J]) ||
                        step.coarse_kind[J - 1] != UnknownKind::lambda_n);
        else
            EXPECT_EQ(step.coarse_vertex[J], step.coarse_vertex[J - 1] + 1);
    }
}

TEST(Aggregation, SmoothedProlongationReproducesRigidModesAwayFromTheSupports) {
    const SquareLevel s(2);
    const auto step = solvers::aggregate_once(s.in, {});
    EXPECT_GT(step.omega, 0.0);
    const SparseMatrix& K = *s.in.K;
    int checked = 0;
    for (Index mode = 0; mode < 3; ++mode) {
        const Vector b = s.in.near_null.col(mode);
        const Vector Kb = K * b; // zero where the row does not couple to a support
        const Vector f = step.T * Vector(step.near_null_coarse.col(mode));
        for (Index i = 0; i < K.rows(); ++i) {
            if (solvers::is_multiplier(s.in.kind[static_cast<size_t>(i)])) continue;
            // D^-1 mixes the two components of a vertex: both rows must see no support.
            bool near_support = false;
            for (Index j = std::max<Index>(0, i - 3); j < std::min<Index>(K.rows(), i + 4); ++j)
                if (s.in.vertex[static_cast<size_t>(j)] == s.in.vertex[static_cast<size_t>(i)] &&
                    !solvers::is_multiplier(s.in.kind[static_cast<size_t>(j)]) &&
                    std::abs(Kb[j]) > 1e-9 * K.coeff(j, j) * b.cwiseAbs().maxCoeff())
                    near_support = true;
            if (near_support) continue;
            EXPECT_NEAR(f[i], b[i], 1e-9 * b.cwiseAbs().maxCoeff()) << mode << " " << i;
            ++checked;
        }
    }
    EXPECT_GT(checked, 3 * s.in.K->rows() / 2);
    // Smoothing widens the basis functions beyond their aggregate.
    EXPECT_GT(step.T.nonZeros(), 2 * step.P_tentative.nonZeros());
}

TEST(Aggregation, CoarseStiffnessIsTheGalerkinProductComputedDensely) {
    const SquareLevel s(1);
    const auto step = solvers::aggregate_once(s.in, {});
    // Dense T, and K T as a sparse-times-dense product: an independent Galerkin product (a dense
    // K would cost n^2 times the coarse size, minutes under the sanitizers).
    const Eigen::MatrixXd T = Eigen::MatrixXd(step.T);
    const Eigen::MatrixXd KT = *s.in.K * T;
    const Eigen::MatrixXd Kc = T.transpose() * KT;
    EXPECT_LT((Eigen::MatrixXd(step.K_coarse) - Kc).norm(), 1e-12 * Kc.norm());
    // The coarse K has empty multiplier rows, as the fine one does: it is the next step's input.
    const solvers::AggregationInput next{&step.K_coarse, step.coarse_vertex, step.coarse_kind,
                                         step.near_null_coarse};
    EXPECT_NO_THROW(next.validate());
}

TEST(Aggregation, LevelsCoarsenToTheCoarseSizeAndOwnTheirTransfers) {
    const SquareLevel s(3);
    const auto levels = solvers::aggregation_levels(s.in, {.coarse_size = 300});
    ASSERT_GE(levels.size(), 3u);
    EXPECT_EQ(levels.front().T, nullptr);
    for (size_t k = 1; k < levels.size(); ++k) {
        ASSERT_NE(levels[k].T_storage, nullptr);
        EXPECT_EQ(levels[k].T, levels[k].T_storage.get());
        EXPECT_EQ(levels[k].R->rows(), levels[k].T->cols());
        if (k >= 2) {
            EXPECT_GT(levels[k].T->cols(), 300);
        }
    }
    EXPECT_LE(levels[1].T->cols(), 300);
    EXPECT_EQ(levels.back().T->rows(), s.in.K->rows());
    // A Multigrid takes them (Galerkin) and outlives the vector that held them.
    solvers::Multigrid mg(levels, {}, solvers::CoarseOperators::galerkin);
    SparseMatrix A = *s.in.K;
    for (Index i = 0; i < A.rows(); ++i)
        if (solvers::is_multiplier(s.in.kind[static_cast<size_t>(i)])) A.coeffRef(i, i) = -1.0;
    A.makeCompressed();
    mg.setup(A);
    EXPECT_EQ(static_cast<size_t>(mg.report().levels.size()), levels.size());
    EXPECT_NE(mg.report().coarse_operators.find("aggregates"), std::string::npos);
}

TEST(Aggregation, BadInputIsRejected) {
    const SquareLevel s(0);
    solvers::AggregationInput bad = s.in;
    bad.kind.pop_back();
    EXPECT_THROW(solvers::aggregate_once(bad, {}), InvalidInput);
    EXPECT_THROW(solvers::aggregate_once(s.in, {.smoothing = 2.0}), InvalidInput);
    EXPECT_THROW(solvers::aggregate_once(s.in, {.max_levels = 1}), InvalidInput);
}

TEST(Aggregation, GalerkinRefreshOfChangedRowsIsTheFullProduct) {
    // A Newton Jacobian changes in its contact rows only: update_values adds T^T (A2 - A) T
    // level by level instead of forming T^T A2 T again. The cycle equals a multigrid set up on
    // A2 from scratch to round-off; a change of most entries takes the full products instead.
    const SquareLevel s(3);
    const auto levels = solvers::aggregation_levels(s.in, {.coarse_size = 300});
    ASSERT_GE(levels.size(), 3u);
    SparseMatrix A = *s.in.K;
    for (Index i = 0; i < A.rows(); ++i)
        if (solvers::is_multiplier(s.in.kind[static_cast<size_t>(i)])) A.coeffRef(i, i) = -1.0;
    A.makeCompressed();
    // A2: the multiplier rows and the first 60 displacement rows changed (within A's pattern).
    SparseMatrix A2 = A;
    int changed = 0;
    for (Index i = 0; i < A2.rows(); ++i) {
        const bool mult = solvers::is_multiplier(s.in.kind[static_cast<size_t>(i)]);
        if (!mult && i >= 60) continue;
        for (SparseMatrix::InnerIterator it(A2, i); it; ++it) {
            it.valueRef() *= mult ? 0.5 : 1.1;
            ++changed;
        }
    }
    ASSERT_GT(changed, 60);
    ASSERT_LT(10 * changed, A.nonZeros());
    solvers::Multigrid refreshed(levels, {}, solvers::CoarseOperators::galerkin);
    refreshed.setup(A);
    refreshed.update_values(A2);
    EXPECT_EQ(refreshed.galerkin_refreshes(), 1);
    solvers::Multigrid fresh(levels, {}, solvers::CoarseOperators::galerkin);
    fresh.setup(A2);
    const Vector r = Vector::LinSpaced(A.rows(), -1.0, 2.0).array().sin();
    Vector z1, z2;
    refreshed.apply(r, z1);
    fresh.apply(r, z2);
    EXPECT_LT((z1 - z2).norm(), 1e-11 * z2.norm());
    // Back to A (a second refresh), then every entry scaled: the full products, bit for bit.
    refreshed.update_values(A);
    EXPECT_EQ(refreshed.galerkin_refreshes(), 2);
    const SparseMatrix A3 = 2.0 * A2;
    refreshed.update_values(A3);
    EXPECT_EQ(refreshed.galerkin_refreshes(), 2);
    fresh.update_values(A3);
    refreshed.apply(r, z1);
    fresh.apply(r, z2);
    EXPECT_EQ(z1, z2);
}
