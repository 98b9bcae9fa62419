// SPDX-License-Identifier: MIT
// EBE preconditioner: exactness on one element, the paper's contact factorizations, and C1, C4,
// C5 against their explicit matrices on a two-triangle mesh with a contact element.
#include "core/check.hpp"
#include "fem/elasticity.hpp"
#include "smoothers/ebe.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>

using namespace mlc;
using testmat::probe;
using namespace mlc::smoothers;

namespace {

const double kR = 2.0, kMu = 0.3;

// Status matrix M in the (t, n) frame: 0 gap, 1 stick, 2 forward slip, 3 backward slip.
Eigen::Matrix2d status_matrix(int status) {
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
    if (status == 1) M.setIdentity();
    if (status == 2) M << 0.0, -kMu, 0.0, 1.0;
    if (status == 3) M << 0.0, kMu, 0.0, 1.0;
    return M;
}

// Node-on-rigid tangent on a flat floor (G = I), unknowns (u_x, u_y, lambda_t, lambda_n):
// [[r M, M], [M, (M - I)/r]] (formulation.md sect. 2).
Eigen::Matrix4d contact_tangent(const Eigen::Matrix2d& M) {
    Eigen::Matrix4d A;
    A << kR * M, M, M, (M - Eigen::Matrix2d::Identity()) / kR;
    return A;
}

SparseMatrix assemble(Index n, const std::vector<ElementMatrix>& els) {
    std::vector<Triplet> t;
    for (const auto& e : els)
        for (size_t a = 0; a < e.dofs.size(); ++a)
            for (size_t b = 0; b < e.dofs.size(); ++b)
                t.emplace_back(e.dofs[a], e.dofs[b],
                               e.A(static_cast<Index>(a), static_cast<Index>(b)));
    return testmat::from_triplets(n, t);
}


// Two triangles (0,1,2), (0,2,3) of the unit square; vertex 3 fixed, vertex 2 fixed in y, a
// node-on-rigid contact element at vertex 0 with the given status. Unknowns: vertex 0: u 0,1 and
// lambda 2,3; vertex 1: u 4,5; vertex 2: u_x 6. Elements listed elastic first, contact last.
std::vector<ElementMatrix> two_triangles(int status) {
    const std::vector<Vec2> x = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const std::vector<std::array<int, 2>> dof = {{0, 1}, {4, 5}, {6, -1}, {-1, -1}};
    fem::Material mat;
    mat.E = 10.0;
    mat.nu = 0.3;
    std::vector<ElementMatrix> els;
    for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        const auto ke = fem::element_stiffness(x[tri[0]], x[tri[1]], x[tri[2]], mat);
        ElementMatrix e;
        std::vector<int> local;
        for (int i = 0; i < 6; ++i)
            if (dof[tri[i / 2]][i % 2] >= 0) {
                local.push_back(i);
                e.dofs.push_back(dof[tri[i / 2]][i % 2]);
            }
        const auto ne = static_cast<Index>(local.size());
        e.A.resize(ne, ne);
        for (Index a = 0; a < ne; ++a)
            for (Index b = 0; b < ne; ++b)
                e.A(a, b) = ke(local[a], local[b]);
        // Store the elastic element in a non-sorted order to exercise the sorting.
        std::reverse(e.dofs.begin(), e.dofs.end());
        e.A = e.A.reverse().eval();
        els.push_back(e);
    }
    ElementMatrix c;
    c.dofs = {0, 1, 2, 3};
    c.A = contact_tangent(status_matrix(status));
    c.is_contact = true;
    els.push_back(c);
    return els;
}

// The regularized element matrix J_e + W~^{-1/2} (A_e - W~_e) W~^{-1/2} of the file comment of
// ebe.hpp, in sorted order.
Eigen::MatrixXd regularized(const ElementMatrix& e, const EBE& P, std::vector<int>& sorted) {
    sorted = e.dofs;
    std::sort(sorted.begin(), sorted.end());
    const auto ne = static_cast<Index>(sorted.size());
    Eigen::MatrixXd R(ne, ne);
    for (Index a = 0; a < ne; ++a)
        for (Index b = 0; b < ne; ++b) {
            const auto pa = std::find(e.dofs.begin(), e.dofs.end(), sorted[a]) - e.dofs.begin();
            const auto pb = std::find(e.dofs.begin(), e.dofs.end(), sorted[b]) - e.dofs.begin();
            const bool unit = P.is_unit_scaled(sorted[a]);
            const double wa = P.scaling()[sorted[a]], wb = P.scaling()[sorted[b]];
            const double j = (a == b && !(e.is_contact && unit)) ? 1.0 : 0.0;
            const double we = (a == b && !unit) ? e.A(pa, pa) : 0.0;
            R(a, b) = j + (e.A(pa, pb) - we) / std::sqrt(wa * wb);
        }
    return R;
}

// Element factor as a global n x n matrix: L_e (lower = true) or U_e, identity off the element.
Eigen::MatrixXd global_factor(const EBE& P, int e, Index n, bool lower) {
    std::vector<int> sd;
    const Eigen::MatrixXd f = P.element_factors(e, sd);
    Eigen::MatrixXd G = Eigen::MatrixXd::Identity(n, n);
    const auto ne = static_cast<Index>(sd.size());
    for (Index a = 0; a < ne; ++a)
        for (Index b = 0; b < ne; ++b) {
            if (lower && a > b) G(sd[a], sd[b]) = f(a, b);
            if (!lower && a <= b) G(sd[a], sd[b]) = f(a, b);
        }
    return G;
}

} // namespace

TEST(EBE, SingleElasticElementIsExact) {
    // One triangle with vertex 0 fixed and vertex 1 fixed in y: A = K_e on the three free
    // components (x1, x2, y2); W~ = diag(A) and the regularized matrix is W^{-1/2} A W^{-1/2},
    // so C1 = C4 = A.
    fem::Material mat;
    const auto ke = fem::element_stiffness({0, 0}, {2, 0}, {0.5, 1.5}, mat);
    const int free[3] = {2, 4, 5};
    ElementMatrix e;
    e.dofs = {0, 1, 2};
    e.A.resize(3, 3);
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            e.A(a, b) = ke(free[a], free[b]);
    const std::vector<ElementMatrix> els = {e};
    const SparseMatrix A = assemble(3, els);
    const Eigen::MatrixXd Ainv = testmat::dense(A).inverse();
    for (EBEVariant v : {EBEVariant::c1, EBEVariant::c4}) {
        EBE P(els, {.variant = v});
        P.setup(A);
        EXPECT_EQ(P.n_replaced_pivots(), 0);
        EXPECT_LT((probe(P, 3) - Ainv).norm(), 1e-10 * Ainv.norm()) << to_string(v);
    }
}

TEST(EBE, SingleContactElementIsExact) {
    // A stick element alone: every unknown is a contact unknown (W~ = 1, D kept in C5), and
    // the stick tangent has a pivot-free LU, so C1 = C4 = C5 = A_ce.
    ElementMatrix e;
    e.dofs = {3, 2, 1, 0}; // stored reversed; the class sorts to (u_x, u_y, lambda_t, lambda_n)
    e.A = contact_tangent(status_matrix(1)).reverse();
    e.is_contact = true;
    const std::vector<ElementMatrix> els = {e};
    const SparseMatrix A = assemble(4, els);
    const Eigen::MatrixXd Ainv = testmat::dense(A).inverse();
    for (EBEVariant v : {EBEVariant::c1, EBEVariant::c4, EBEVariant::c5}) {
        EBE P(els, {.variant = v});
        P.setup(A);
        EXPECT_EQ(P.n_replaced_pivots(), 0);
        EXPECT_LT((probe(P, 4) - Ainv).norm(), 1e-12 * Ainv.norm()) << to_string(v);
    }
}

TEST(EBE, ContactFactorsFollowThePaper) {
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity(), Z = Eigen::Matrix2d::Zero();
    for (int status = 0; status < 4; ++status) {
        ElementMatrix e;
        e.dofs = {0, 1, 2, 3};
        e.A = contact_tangent(status_matrix(status));
        e.is_contact = true;
        const std::vector<ElementMatrix> els = {e};
        EBE P(els);
        P.setup(assemble(4, els));
        std::vector<int> sd;
        const Eigen::MatrixXd f = P.element_factors(0, sd);
        Eigen::Matrix4d L = Eigen::Matrix4d::Identity(), U = Eigen::Matrix4d::Zero();
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                (a > b ? L(a, b) : U(a, b)) = f(a, b);
        Eigen::Matrix4d Lp, Up;
        if (status == 1) {
            // Eq. 34: A_ce = [[I, 0], [I/r, I]] [[r I, I], [0, -I/r]].
            Lp << I, Z, I / kR, I;
            Up << kR * I, I, Z, -I / kR;
            EXPECT_EQ(P.n_replaced_pivots(), 0);
            EXPECT_LT((L - Lp).norm() + (U - Up).norm(), 1e-14);
        } else if (status == 0) {
            // Eq. 33, L = I, U = diag(0, 0, -1/r, -1/r), with its zero pivots set to 1.
            EXPECT_EQ(P.n_replaced_pivots(), 2);
            EXPECT_LT((L - Eigen::Matrix4d::Identity()).norm(), 1e-14);
            EXPECT_LT(
                (U - Eigen::Vector4d(1, 1, -1 / kR, -1 / kR).asDiagonal().toDenseMatrix()).norm(),
                1e-14);
        } else {
            // Slip on a flat floor (M_11 = M_21 = 0, eq. 38): one zero pivot (u_t) set to 1, and
            // L U = A_ce + e_t e_t^T (a diagonal perturbation only).
            EXPECT_EQ(P.n_replaced_pivots(), 1);
            Eigen::Matrix4d target = e.A;
            target(0, 0) += 1.0;
            EXPECT_LT((L * U - target).norm(), 1e-14);
            // The multiplier pivots are -1/r as in eq. 38.
            EXPECT_NEAR(U(2, 2), -1 / kR, 1e-15);
            EXPECT_NEAR(U(3, 3), -1 / kR, 1e-15);
        }
    }
}

TEST(EBE, C1EqualsItsExplicitProductOnTwoTriangles) {
    for (int mode = 0; mode < 8; ++mode) {
        const int status = mode % 4;
        const UnitScaling us = mode < 4 ? UnitScaling::contact_unknowns : UnitScaling::multipliers;
        const std::vector<ElementMatrix> els = two_triangles(status);
        const Index n = 7;
        const SparseMatrix A = assemble(n, els);
        EBE P(els, {.variant = EBEVariant::c1, .unit_scaling = us});
        P.setup(A);
        // W~ = 1 on the contact unknowns 0..3 (contact_unknowns) or on the multipliers 2, 3
        // (multipliers), diag(A) elsewhere.
        for (Index i = 0; i < n; ++i) {
            const bool unit = us == UnitScaling::contact_unknowns ? i < 4 : (i == 2 || i == 3);
            EXPECT_EQ(P.is_unit_scaled(i), unit);
            EXPECT_DOUBLE_EQ(P.scaling()[i], unit ? 1.0 : A.coeff(i, i));
        }
        // Each factor pair reproduces its regularized element matrix (up to replaced pivots).
        int replaced = 0;
        for (int e = 0; e < 3; ++e) {
            std::vector<int> sd, sr;
            const Eigen::MatrixXd R = regularized(els[e], P, sr);
            const Eigen::MatrixXd f = P.element_factors(e, sd);
            ASSERT_EQ(sd, sr);
            const auto ne = static_cast<Index>(sd.size());
            Eigen::MatrixXd L = Eigen::MatrixXd::Identity(ne, ne),
                            U = Eigen::MatrixXd::Zero(ne, ne);
            for (Index a = 0; a < ne; ++a)
                for (Index b = 0; b < ne; ++b)
                    (a > b ? L(a, b) : U(a, b)) = f(a, b);
            const Eigen::MatrixXd diff = L * U - R;
            EXPECT_LT((diff - Eigen::MatrixXd(diff.diagonal().asDiagonal())).norm(), 1e-12);
            for (Index a = 0; a < ne; ++a)
                if (std::abs(diff(a, a)) > 1e-12) ++replaced;
        }
        EXPECT_EQ(replaced, P.n_replaced_pivots());
        // Gap and slip contact elements are singular: zero pivots appear when all their unknowns
        // are unit-scaled, never when only the multipliers are.
        if (us == UnitScaling::multipliers) {
            EXPECT_EQ(replaced, 0) << "status " << status;
        } else if (status != 1) {
            EXPECT_GT(replaced, 0) << "status " << status;
        }
        // C1 = W^{1/2} (prod L_e) (prod U_e, reverse) W^{1/2} in the class's element order.
        Eigen::MatrixXd C = Eigen::MatrixXd::Identity(n, n);
        for (int e : P.element_order())
            C = C * global_factor(P, e, n, true);
        const std::vector<int>& o = P.element_order();
        for (auto it = o.rbegin(); it != o.rend(); ++it)
            C = C * global_factor(P, *it, n, false);
        const Eigen::VectorXd sw = P.scaling().cwiseSqrt();
        C = sw.asDiagonal() * C * sw.asDiagonal();
        const Eigen::MatrixXd Cinv = C.inverse();
        EXPECT_LT((probe(P, n) - Cinv).norm(), 1e-10 * Cinv.norm()) << "mode " << mode;
        EXPECT_LT((probe(P, n, true) - Cinv.transpose()).norm(), 1e-10 * Cinv.norm());
    }
}

TEST(EBE, C4AndC5EqualTheirExplicitFormulas) {
    for (int mode = 0; mode < 8; ++mode) {
        const int status = mode % 4;
        const UnitScaling us = mode < 4 ? UnitScaling::contact_unknowns : UnitScaling::multipliers;
        const std::vector<ElementMatrix> els = two_triangles(status);
        const Index n = 7;
        const SparseMatrix A = assemble(n, els);
        for (EBEVariant v : {EBEVariant::c4, EBEVariant::c5}) {
            EBE P(els, {.variant = v, .unit_scaling = us});
            P.setup(A);
            // E, D, F gathered from the element factors in the global numbering.
            Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, n), F = E, D = E;
            for (int e = 0; e < 3; ++e) {
                std::vector<int> sd;
                const Eigen::MatrixXd f = P.element_factors(e, sd);
                for (size_t a = 0; a < sd.size(); ++a)
                    for (size_t b = 0; b < sd.size(); ++b) {
                        const double x = f(static_cast<Index>(a), static_cast<Index>(b));
                        if (a > b) E(sd[a], sd[b]) += x;
                        if (a == b) D(sd[a], sd[b]) += x;
                        if (a < b) F(sd[a], sd[b]) += x;
                    }
            }
            if (v == EBEVariant::c5)
                for (Index i = 0; i < n; ++i)
                    if (!P.is_unit_scaled(i)) D(i, i) = 1.0; // the scaled diagonal of A
            const Eigen::VectorXd sw = P.scaling().cwiseSqrt();
            const Eigen::MatrixXd C =
                sw.asDiagonal() * (Eigen::MatrixXd::Identity(n, n) + E) * (D + F) * sw.asDiagonal();
            const Eigen::MatrixXd Cinv = C.inverse();
            EXPECT_LT((probe(P, n) - Cinv).norm(), 1e-10 * Cinv.norm())
                << to_string(v) << " mode " << mode;
            EXPECT_LT((probe(P, n, true) - Cinv.transpose()).norm(), 1e-10 * Cinv.norm());
        }
    }
}

TEST(EBE, ColoursShareNoUnknownAndParallelPassesAgree) {
    // A 6 x 6 structured mesh (72 triangles), bottom row fixed.
    const int m = 6;
    std::vector<ElementMatrix> els;
    fem::Material mat;
    auto dof = [&](int i, int j, int c) { return j == 0 ? -1 : 2 * ((j - 1) * (m + 1) + i) + c; };
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i)
            for (int half = 0; half < 2; ++half) {
                std::array<std::array<int, 2>, 3> v =
                    half == 0
                        ? std::array<std::array<int, 2>, 3>{{{i, j}, {i + 1, j}, {i + 1, j + 1}}}
                        : std::array<std::array<int, 2>, 3>{{{i, j}, {i + 1, j + 1}, {i, j + 1}}};
                const auto ke = fem::element_stiffness(
                    Vec2(v[0][0], v[0][1]), Vec2(v[1][0], v[1][1]), Vec2(v[2][0], v[2][1]), mat);
                ElementMatrix e;
                std::vector<int> local;
                for (int k = 0; k < 6; ++k)
                    if (const int d = dof(v[k / 2][0], v[k / 2][1], k % 2); d >= 0) {
                        local.push_back(k);
                        e.dofs.push_back(d);
                    }
                const auto ne = static_cast<Index>(local.size());
                e.A.resize(ne, ne);
                for (Index a = 0; a < ne; ++a)
                    for (Index b = 0; b < ne; ++b)
                        e.A(a, b) = ke(local[a], local[b]);
                els.push_back(e);
            }
    const Index n = 2 * m * (m + 1);
    const SparseMatrix A = assemble(n, els);
    EBE P(els, {.parallel = true, .min_parallel_elements = 1});
    P.setup(A);
    EXPECT_GE(P.n_colours(), 6); // six triangles meet at an interior vertex
    EXPECT_LE(P.n_colours(), 12);
    // Same-coloured elements share no unknown.
    const std::vector<int>& cs = P.colour_starts();
    ASSERT_EQ(static_cast<int>(cs.size()), P.n_colours() + 1);
    EXPECT_EQ(cs.back(), static_cast<int>(els.size()));
    for (int c = 0; c < P.n_colours(); ++c) {
        std::vector<int> seen;
        for (int k = cs[c]; k < cs[c + 1]; ++k)
            for (int d : els[P.element_order()[k]].dofs) {
                EXPECT_EQ(std::count(seen.begin(), seen.end(), d), 0) << "colour " << c;
                seen.push_back(d);
            }
    }
    const Vector r = testmat::pseudo_random(n, 3);
    Vector z_par, z_seq;
    P.apply(r, z_par);
    EBE S(els, {.parallel = false});
    S.setup(A);
    S.apply(r, z_seq);
    EXPECT_LT((z_par - z_seq).norm(), 1e-14 * z_seq.norm());
    // C1 is an approximation of A: C1^{-1} A is closer to the identity than the unpreconditioned
    // A scaled by its diagonal (the element product keeps the couplings).
    const Eigen::MatrixXd Ad = testmat::dense(A);
    const Eigen::MatrixXd E1 = probe(S, n) * Ad - Eigen::MatrixXd::Identity(n, n);
    const Eigen::VectorXd d = Ad.diagonal();
    const Eigen::MatrixXd E0 = d.cwiseInverse().asDiagonal() * Ad - Eigen::MatrixXd::Identity(n, n);
    EXPECT_LT(E1.norm(), 0.8 * E0.norm());
}

TEST(EBE, RejectsBadInput) {
    std::vector<ElementMatrix> els = two_triangles(1);
    const SparseMatrix A = assemble(7, els);
    {
        auto bad = els;
        bad[0].dofs[0] = 7; // out of range
        EBE P(bad);
        EXPECT_THROW(P.setup(A), InvalidInput);
    }
    {
        auto bad = els;
        bad[1].A.resize(2, 2); // size mismatch
        EBE P(bad);
        EXPECT_THROW(P.setup(A), InvalidInput);
    }
    {
        // A zero diagonal on an unknown of no contact element (unknown 6).
        SparseMatrix Z = A;
        Z.coeffRef(6, 6) = 0.0;
        EBE P(els);
        EXPECT_THROW(P.setup(Z), InvalidInput);
    }
    EXPECT_THROW(EBE(els, {.zero_pivot_tol = 1.5}), InvalidInput);
    EXPECT_THROW(parse_ebe_variant("c3"), InvalidInput);
    EXPECT_EQ(parse_ebe_variant("c5"), EBEVariant::c5);
}
