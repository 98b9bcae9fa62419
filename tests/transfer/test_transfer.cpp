// SPDX-License-Identifier: MIT
// Two-level interpolation P and Q (formulation.md §3) on the square ladder and the CGAL-meshed
// Hertz scene: reproduction of linear fields, nesting, the coarse/fine split, and the force
// transfer of Q at the ends of the contact boundary.
#include "core/check.hpp"
#include "levels/hierarchy.hpp"
#include "levels/level.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"
#include "tests/common/random.hpp"
#include "transfer/transfer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

using namespace mlc;
using transfer::ContactNodes;
using transfer::LevelTransfer;
using transfer::QRule;

namespace {

/// Levels 0..n_levels-1 of a scene by uniform refinement of its level-0 mesh.
std::vector<levels::Level> ladder(const levels::Problem& p, int n_levels) {
    std::vector<levels::Level> out;
    mesh::Mesh m = p.mesh0;
    for (int l = 0; l < n_levels; ++l) {
        if (l > 0) m = mesh::refine(m);
        out.push_back(levels::build_level(p, m));
    }
    return out;
}

LevelTransfer make_transfer(const levels::Level& coarse, const levels::Level& fine,
                            QRule rule = QRule::paper) {
    return transfer::build_transfer(fine.mesh, coarse.dofs, fine.dofs,
                                    levels::contact_nodes(coarse), levels::contact_nodes(fine),
                                    rule);
}

const std::vector<levels::Level>& square_levels() {
    static const auto L = ladder(scene::load_scene("square"), 3);
    return L;
}

const std::vector<levels::Level>& hertz_levels() {
    static const auto L = ladder(scene::load_scene("hertz"), 3);
    return L;
}

/// Samples u(x) = A x + c at the vertices (2 per vertex, interleaved).
Vector sample_linear(const mesh::Mesh& m, const Eigen::Matrix2d& A, const Vec2& c) {
    Vector u(2 * m.n_vertices());
    for (int v = 0; v < m.n_vertices(); ++v)
        u.segment<2>(2 * v) = A * m.vertices[static_cast<size_t>(v)] + c;
    return u;
}

double max_abs(const SparseMatrix& M) {
    double m = 0.0;
    for (Index i = 0; i < M.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(M, i); it; ++it)
            m = std::max(m, std::abs(it.value()));
    return m;
}

/// Uniform pressure p and tangential traction tau on the contact boundary as nodal forces:
/// lambda_n = -p * l_i, lambda_t = tau * l_i, with l_i half the length of the contactor-tagged
/// boundary edges at node i (the consistent P1 nodal forces; a share lands on non-contact
/// vertices such as the square's fixed corner).
Vector pressure_field(const levels::Level& L, const std::string& tag, double p, double tau) {
    std::vector<double> trib(static_cast<size_t>(L.mesh.n_vertices()), 0.0);
    const int t = L.mesh.tag(tag);
    for (const auto& e : L.mesh.boundary)
        if (e.tag == t) {
            const double h = (L.mesh.vertices[static_cast<size_t>(e.v1)] -
                              L.mesh.vertices[static_cast<size_t>(e.v0)])
                                 .norm();
            trib[static_cast<size_t>(e.v0)] += h / 2;
            trib[static_cast<size_t>(e.v1)] += h / 2;
        }
    Vector x = Vector::Zero(L.n_unknowns());
    for (size_t i = 0; i < L.contacts.size(); ++i) {
        const double l = trib[static_cast<size_t>(L.contacts[i].vertex[0])];
        const int d = L.lambda_dof[i];
        if (L.contacts[i].n_multipliers() == 2) {
            x[d] = tau * l;
            x[d + 1] = -p * l;
        } else {
            x[d] = -p * l;
        }
    }
    return x;
}

/// Random coarse field on every unknown.
Vector random_field(Index n, unsigned seed) {
    return mlc::testutil::random_vector(n, seed);
}

} // namespace

TEST(Prolongation, ReproducesLinearFieldsOnTheSquareLadder) {
    const auto& L = square_levels();
    Eigen::Matrix2d A;
    A << 0.3, -1.7, 2.1, 0.4;
    const Vec2 c(-0.5, 1.25);
    for (int l = 0; l + 1 < 3; ++l) {
        const auto tr = make_transfer(L[static_cast<size_t>(l)], L[static_cast<size_t>(l) + 1]);
        const Vector uc = sample_linear(L[static_cast<size_t>(l)].mesh, A, c);
        const Vector uf = sample_linear(L[static_cast<size_t>(l) + 1].mesh, A, c);
        Vector ui;
        tr.interpolate_nodal(uc, ui);
        ASSERT_EQ(ui.size(), uf.size());
        EXPECT_LT((ui - uf).lpNorm<Eigen::Infinity>(), 1e-12 * uf.lpNorm<Eigen::Infinity>())
            << "level " << l << " -> " << l + 1;
        // Scalar version: x and y coordinates as vertex fields.
        Vector xc(tr.P_vertex.cols()), xf(tr.P_vertex.rows());
        for (Index v = 0; v < xc.size(); ++v)
            xc[v] = L[static_cast<size_t>(l)].mesh.vertices[static_cast<size_t>(v)].x();
        for (Index v = 0; v < xf.size(); ++v)
            xf[v] = L[static_cast<size_t>(l) + 1].mesh.vertices[static_cast<size_t>(v)].x();
        EXPECT_LT((tr.P_vertex * xc - xf).lpNorm<Eigen::Infinity>(), 1e-12 * 40);
    }
}

TEST(Prolongation, MapsConstantsToConstants) {
    for (const auto* levs : {&square_levels(), &hertz_levels()}) {
        const auto tr = make_transfer((*levs)[0], (*levs)[1]);
        const Vector one_f = tr.P_vertex * Vector::Ones(tr.P_vertex.cols());
        EXPECT_LT((one_f - Vector::Ones(one_f.size())).lpNorm<Eigen::Infinity>(), 1e-15);
        Vector uc(tr.P_nodal.cols());
        for (Index v = 0; v < uc.size() / 2; ++v)
            uc.segment<2>(2 * v) = Vec2(3.0, -7.0);
        Vector uf;
        tr.interpolate_nodal(uc, uf);
        for (Index v = 0; v < uf.size() / 2; ++v) {
            EXPECT_DOUBLE_EQ(uf[2 * v], 3.0);
            EXPECT_DOUBLE_EQ(uf[2 * v + 1], -7.0);
        }
        // On unknowns: a constant displacement of the free components is kept wherever both
        // parents' components are free (T maps homogeneous corrections, so a prescribed parent
        // component contributes 0).
        const auto& C = (*levs)[0];
        const auto& F = (*levs)[1];
        Vector xc = Vector::Zero(C.n_unknowns());
        for (int v = 0; v < C.mesh.n_vertices(); ++v)
            for (int k = 0; k < 2; ++k)
                if (C.dofs.u_dof(v, k) >= 0) xc[C.dofs.u_dof(v, k)] = k == 0 ? 3.0 : -7.0;
        Vector xf;
        tr.prolongate(xc, xf);
        const int nc = F.mesh.n_coarse_vertices;
        for (int v = 0; v < F.mesh.n_vertices(); ++v)
            for (int k = 0; k < 2; ++k) {
                const int d = F.dofs.u_dof(v, k);
                if (d < 0) continue;
                bool parents_free = true;
                if (v >= nc)
                    for (int p : F.mesh.parents[static_cast<size_t>(v - nc)])
                        parents_free = parents_free && C.dofs.u_dof(p, k) >= 0;
                if (parents_free) {
                    EXPECT_DOUBLE_EQ(xf[d], k == 0 ? 3.0 : -7.0);
                }
            }
    }
}

// On the Hertz half-disc the refinement moves midpoints of arc edges onto the arc, so the fine
// vertex is no longer the midpoint of its parents. P still interpolates (it does not know the
// geometry): it gives u at the chord midpoint (x_a + x_b) / 2. Hence a linear field is
// reproduced exactly at every coarse vertex and every unmoved midpoint (interior and straight
// boundary edges), and at a moved arc midpoint the error is exactly A (x_mid - x_h), of the order
// of the sagitta h^2 / (8 R).
TEST(Prolongation, OnTheHertzArcInterpolatesAtTheChordMidpoint) {
    const auto& L = hertz_levels();
    Eigen::Matrix2d A;
    A << 0.3, -1.7, 2.1, 0.4;
    const Vec2 c(-0.5, 1.25);
    for (int l = 0; l + 1 < 3; ++l) {
        const auto& C = L[static_cast<size_t>(l)];
        const auto& F = L[static_cast<size_t>(l) + 1];
        const auto tr = make_transfer(C, F);
        Vector uf;
        tr.interpolate_nodal(sample_linear(C.mesh, A, c), uf);
        const int nc = F.mesh.n_coarse_vertices;
        ASSERT_EQ(nc, C.mesh.n_vertices());
        ASSERT_EQ(F.mesh.shapes.size(), 1u);
        const double R = F.mesh.shapes[0].radius;
        int n_moved = 0, n_unmoved = 0;
        double max_shift = 0.0;
        for (int v = 0; v < F.mesh.n_vertices(); ++v) {
            const Vec2& x = F.mesh.vertices[static_cast<size_t>(v)];
            const Vec2 got = uf.segment<2>(2 * v);
            if (v < nc) {
                EXPECT_LT((got - (A * x + c)).norm(), 1e-14) << "coarse vertex " << v;
                continue;
            }
            const auto& pr = F.mesh.parents[static_cast<size_t>(v - nc)];
            const Vec2& xa = C.mesh.vertices[static_cast<size_t>(pr[0])];
            const Vec2& xb = C.mesh.vertices[static_cast<size_t>(pr[1])];
            const Vec2 mid = 0.5 * (xa + xb);
            EXPECT_LT((got - (A * mid + c)).norm(), 1e-14) << "new vertex " << v;
            const double shift = (x - mid).norm();
            if (shift == 0.0) {
                ++n_unmoved;
                EXPECT_LT((got - (A * x + c)).norm(), 1e-14) << "unmoved midpoint " << v;
            } else {
                ++n_moved;
                max_shift = std::max(max_shift, shift);
                const double h = (xb - xa).norm();
                EXPECT_LE(shift, 1.01 * h * h / (8 * R)) << "arc midpoint " << v;
                EXPECT_LT((got - (A * x + c) - A * (mid - x)).norm(), 1e-14)
                    << "arc midpoint " << v;
            }
        }
        EXPECT_GT(n_moved, 10) << "the arc must have been refined";
        EXPECT_GT(n_unmoved, 10 * n_moved);
        EXPECT_GT(max_shift, 0.0);
    }
}

// P(l -> l+2) = P(l+1 -> l+2) P(l -> l+1), checked against a matrix built from coordinates
// alone: row v holds the barycentric coordinates of fine vertex v in a level-l triangle
// containing it (the fine values of the piecewise-linear interpolant on the coarse mesh).
TEST(Prolongation, TwoStepsEqualDirectInterpolationOnCoarseTriangles) {
    auto direct = [](const mesh::Mesh& coarse, const mesh::Mesh& fine) {
        std::vector<Triplet> t;
        for (int v = 0; v < fine.n_vertices(); ++v) {
            const Vec2& x = fine.vertices[static_cast<size_t>(v)];
            bool found = false;
            for (const auto& tri : coarse.cells) {
                const Vec2& a = coarse.vertices[static_cast<size_t>(tri[0])];
                const Vec2& b = coarse.vertices[static_cast<size_t>(tri[1])];
                const Vec2& c = coarse.vertices[static_cast<size_t>(tri[2])];
                Eigen::Matrix2d J;
                J << b - a, c - a;
                const Vec2 s = J.inverse() * (x - a);
                const double l[3] = {1 - s.x() - s.y(), s.x(), s.y()};
                if (std::min({l[0], l[1], l[2]}) < -1e-12) continue;
                for (int k = 0; k < 3; ++k)
                    if (std::abs(l[k]) > 1e-13)
                        t.emplace_back(v, tri[static_cast<size_t>(k)], l[k]);
                found = true;
                break;
            }
            EXPECT_TRUE(found) << "fine vertex " << v << " outside the coarse mesh";
        }
        SparseMatrix D(fine.n_vertices(), coarse.n_vertices());
        D.setFromTriplets(t.begin(), t.end());
        return D;
    };
    // The square ladder, and a union-jack rectangle whose diagonals alternate.
    const auto& L = square_levels();
    const SparseMatrix P01 = make_transfer(L[0], L[1]).P_vertex;
    const SparseMatrix P12 = make_transfer(L[1], L[2]).P_vertex;
    const SparseMatrix prod = P12 * P01;
    const SparseMatrix D = direct(L[0].mesh, L[2].mesh);
    EXPECT_LT(max_abs(SparseMatrix(prod - D)), 1e-14);
    EXPECT_EQ(prod.rows(), 65 * 65);

    const mesh::Mesh m0 = mesh::structured_rectangle(Vec2(-1.0, 2.0), Vec2(3.0, 1.5), 5, 3,
                                                     mesh::Diagonal::alternate);
    const mesh::Mesh m1 = mesh::refine(m0), m2 = mesh::refine(m1);
    auto plain = [](const mesh::Mesh& m) {
        return fem::DofMap(std::vector<std::array<bool, 2>>(static_cast<size_t>(m.n_vertices())),
                           std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    };
    const auto t01 = transfer::build_transfer(m1, plain(m0), plain(m1), {}, {});
    const auto t12 = transfer::build_transfer(m2, plain(m1), plain(m2), {}, {});
    const SparseMatrix prod2 = t12.P_vertex * t01.P_vertex;
    EXPECT_LT(max_abs(SparseMatrix(prod2 - direct(m0, m2))), 1e-14);
    // With no prescribed components and no contact, T is P_nodal.
    EXPECT_LT(max_abs(SparseMatrix(t01.T - t01.P_nodal)), 1e-15);
}

TEST(Transfer, CoarseRowsAreIdentityOnDisplacementsAndHalfOnMultipliers) {
    const auto& L = square_levels();
    for (int l = 0; l + 1 < 3; ++l) {
        const auto& C = L[static_cast<size_t>(l)];
        const auto& F = L[static_cast<size_t>(l) + 1];
        for (QRule rule : {QRule::paper, QRule::conservative}) {
            const auto tr = make_transfer(C, F, rule);
            ASSERT_EQ(tr.coarse_set.size(), tr.coarse_dof.size());
            const double x_end = 0.0; // the left end has one contact edge
            for (size_t k = 0; k < tr.coarse_set.size(); ++k) {
                const int d = tr.coarse_set[k];
                ASSERT_EQ(tr.T.row(d).nonZeros(), 1) << "fine unknown " << d;
                SparseMatrix::InnerIterator it(tr.T, d);
                EXPECT_EQ(it.index(), tr.coarse_dof[k]);
                if (F.dofs.is_displacement(d)) {
                    EXPECT_EQ(it.value(), 1.0);
                    EXPECT_EQ(tr.Q.row(d).nonZeros(), 0);
                } else {
                    const bool end =
                        F.mesh.vertices[static_cast<size_t>(F.dofs.vertex_of(d))].x() == x_end;
                    const double w = rule == QRule::paper ? 0.5 : (end ? 0.75 : 0.5);
                    EXPECT_EQ(it.value(), w) << "multiplier unknown " << d;
                }
            }
            // New-vertex displacement rows average the free parent components.
            const int nc = F.mesh.n_coarse_vertices;
            for (int d : tr.fine_set) {
                if (!F.dofs.is_displacement(d)) continue;
                const int v = F.dofs.vertex_of(d);
                const int comp = F.dofs.u_dof(v, 0) == d ? 0 : 1;
                int n_free = 0;
                for (int p : F.mesh.parents[static_cast<size_t>(v - nc)]) {
                    const int cd = C.dofs.u_dof(p, comp);
                    if (cd < 0) continue;
                    ++n_free;
                    EXPECT_EQ(tr.T.coeff(d, cd), 0.5);
                }
                EXPECT_EQ(tr.T.row(d).nonZeros(), n_free);
            }
        }
    }
}

TEST(Transfer, MatricesAreCompressedWithIncreasingColumnsAndPNodalIsPVertexPerComponent) {
    // The operators are written straight into CSR: every row's columns strictly increase (what
    // Eigen's products and coeff() assume), and P_nodal(2v + c, 2p + c) = P_vertex(v, p).
    for (const auto* levs : {&square_levels(), &hertz_levels()}) {
        for (int l = 0; l + 1 < 3; ++l) {
            const auto tr =
                make_transfer((*levs)[static_cast<size_t>(l)], (*levs)[static_cast<size_t>(l) + 1]);
            for (const SparseMatrix* M : {static_cast<const SparseMatrix*>(&tr.P_vertex),
                                          static_cast<const SparseMatrix*>(&tr.P_nodal),
                                          static_cast<const SparseMatrix*>(&tr.T),
                                          static_cast<const SparseMatrix*>(&tr.R)}) {
                ASSERT_TRUE(M->isCompressed());
                for (Index i = 0; i < M->rows(); ++i)
                    for (int k = M->outerIndexPtr()[i] + 1; k < M->outerIndexPtr()[i + 1]; ++k)
                        ASSERT_LT(M->innerIndexPtr()[k - 1], M->innerIndexPtr()[k]) << "row " << i;
            }
            ASSERT_EQ(tr.P_nodal.nonZeros(), 2 * tr.P_vertex.nonZeros());
            for (Index v = 0; v < tr.P_vertex.rows(); ++v)
                for (SparseMatrix::InnerIterator it(tr.P_vertex, v); it; ++it)
                    for (int c = 0; c < 2; ++c)
                        EXPECT_EQ(tr.P_nodal.coeff(2 * v + c, 2 * it.index() + c), it.value());
        }
    }
}

TEST(Transfer, CoarseAndFineSetsPartitionTheUnknowns) {
    for (const auto* levs : {&square_levels(), &hertz_levels()}) {
        for (int l = 0; l + 1 < 3; ++l) {
            const auto& C = (*levs)[static_cast<size_t>(l)];
            const auto& F = (*levs)[static_cast<size_t>(l) + 1];
            const auto tr = make_transfer(C, F);
            EXPECT_TRUE(std::is_sorted(tr.coarse_set.begin(), tr.coarse_set.end()));
            EXPECT_TRUE(std::is_sorted(tr.fine_set.begin(), tr.fine_set.end()));
            std::vector<int> all = tr.coarse_set;
            all.insert(all.end(), tr.fine_set.begin(), tr.fine_set.end());
            std::sort(all.begin(), all.end());
            ASSERT_EQ(static_cast<Index>(all.size()), F.n_unknowns());
            for (size_t i = 0; i < all.size(); ++i)
                ASSERT_EQ(all[i], static_cast<int>(i));
            for (int d : tr.coarse_set)
                EXPECT_LT(F.dofs.vertex_of(d), F.mesh.n_coarse_vertices);
            for (int d : tr.fine_set)
                EXPECT_GE(F.dofs.vertex_of(d), F.mesh.n_coarse_vertices);
            // coarse_dof: a bijection onto the coarse unknowns, same vertex and kind.
            std::vector<int> cd = tr.coarse_dof;
            std::sort(cd.begin(), cd.end());
            ASSERT_EQ(static_cast<Index>(cd.size()), C.n_unknowns());
            for (size_t i = 0; i < cd.size(); ++i)
                ASSERT_EQ(cd[i], static_cast<int>(i));
            for (size_t k = 0; k < tr.coarse_set.size(); ++k) {
                EXPECT_EQ(F.dofs.vertex_of(tr.coarse_set[k]), C.dofs.vertex_of(tr.coarse_dof[k]));
                EXPECT_EQ(F.dofs.is_displacement(tr.coarse_set[k]),
                          C.dofs.is_displacement(tr.coarse_dof[k]));
            }
        }
    }
}

TEST(Transfer, RestrictionIsTheTransposeAndAppliesMatchTheMatrices) {
    for (const auto* levs : {&square_levels(), &hertz_levels()}) {
        const auto& C = (*levs)[1];
        const auto& F = (*levs)[2];
        for (QRule rule : {QRule::paper, QRule::conservative}) {
            const auto tr = make_transfer(C, F, rule);
            EXPECT_EQ(tr.rule, rule);
            ASSERT_EQ(tr.T.rows(), F.n_unknowns());
            ASSERT_EQ(tr.T.cols(), C.n_unknowns());
            EXPECT_EQ(max_abs(SparseMatrix(tr.R - SparseMatrix(tr.T.transpose()))), 0.0);
            // T = P_u + Q with Q only on multiplier rows.
            for (Index i = 0; i < tr.Q.outerSize(); ++i)
                if (tr.Q.row(i).nonZeros() > 0) {
                    EXPECT_FALSE(F.dofs.is_displacement(i));
                }
            const Vector x = random_field(C.n_unknowns(), 1);
            const Vector r = random_field(F.n_unknowns(), 2);
            Vector y, z, u;
            tr.prolongate(x, y);
            EXPECT_LT((y - tr.T * x).lpNorm<Eigen::Infinity>(), 1e-15);
            tr.restrict_to_coarse(r, z);
            EXPECT_LT((z - tr.R * r).lpNorm<Eigen::Infinity>(), 1e-14);
            // Adjointness: r . (T x) = (R r) . x.
            EXPECT_NEAR(r.dot(y), z.dot(x), 1e-12 * r.norm() * y.norm());
            const Vector uc = random_field(2 * C.mesh.n_vertices(), 3);
            tr.interpolate_nodal(uc, u);
            EXPECT_LT((u - tr.P_nodal * uc).lpNorm<Eigen::Infinity>(), 1e-15);
            // Outputs of the wrong size are resized.
            Vector w = Vector::Zero(3);
            tr.prolongate(x, w);
            EXPECT_EQ(w, y);
        }
    }
}

// A uniform pressure p (and traction tau) has nodal forces -p l_i (tau l_i), l_i the tributary
// length. At a coarse vertex Q halves the force, as the tributary halves; at the midpoint of a
// coarse edge (a, b) it gives (l_a + l_b) p / 4 = h p / 2 when l_a = l_b = h, the fine tributary.
// Only the midpoints next to an end of the contact boundary differ: (0, 2.5) next to the left
// end, whose tributary is h / 2, and (37.5, 40) next to the fixed corner, which is no contact
// node and contributes 0.
TEST(MultiplierTransfer, UniformPressureIsReproducedAwayFromTheEnds) {
    const auto& L = square_levels();
    const double p = 50.0, tau = 12.0;
    for (int l = 0; l + 1 < 3; ++l) {
        const auto& C = L[static_cast<size_t>(l)];
        const auto& F = L[static_cast<size_t>(l) + 1];
        const double H = 2.5 / (1 << l), h = H / 2;
        const auto tr = make_transfer(C, F);
        const Vector xc = pressure_field(C, "bottom", p, tau);
        const Vector want = pressure_field(F, "bottom", p, tau);
        Vector got;
        tr.prolongate(xc, got);
        ASSERT_EQ(F.n_contact_nodes(), 2 * C.n_contact_nodes());
        int n_checked = 0;
        for (int i = 0; i < F.n_contact_nodes(); ++i) {
            const int d = F.lambda_dof[static_cast<size_t>(i)];
            const double x =
                F.mesh.vertices[static_cast<size_t>(F.contacts[static_cast<size_t>(i)].vertex[0])]
                    .x();
            const double wt = got[d] / want[d], wn = got[d + 1] / want[d + 1];
            if (std::abs(x - h) < 1e-12) { // midpoint of the left end's edge: (H/2 + H) / 4
                EXPECT_NEAR(wt, 0.75, 1e-14);
                EXPECT_NEAR(wn, 0.75, 1e-14);
            } else if (std::abs(x - (40.0 - h)) < 1e-12) { // next to the fixed corner: H / 4
                EXPECT_NEAR(wt, 0.5, 1e-14);
                EXPECT_NEAR(wn, 0.5, 1e-14);
            } else {
                EXPECT_NEAR(got[d], want[d], 1e-13 * tau * h) << "x = " << x;
                EXPECT_NEAR(got[d + 1], want[d + 1], 1e-13 * p * h) << "x = " << x;
                ++n_checked;
            }
        }
        EXPECT_EQ(n_checked, F.n_contact_nodes() - 2);
        // Resultants (p = 1): coarse 40 - H/2, fine 40 - h/2 (the corner's share shrinks), and
        // the paper's Q gives the coarse one less a quarter of the left end's H/2.
        const Eigen::Vector2d Rc = transfer::multiplier_resultant(levels::contact_nodes(C), xc);
        const Eigen::Vector2d Rq = transfer::multiplier_resultant(levels::contact_nodes(F), got);
        const Eigen::Vector2d Rf = transfer::multiplier_resultant(levels::contact_nodes(F), want);
        EXPECT_NEAR(Rc.y(), -p * (40.0 - H / 2), 1e-12 * p * 40);
        EXPECT_NEAR(Rf.y(), -p * (40.0 - h / 2), 1e-12 * p * 40);
        EXPECT_NEAR(Rq.y(), -p * (40.0 - H / 2 - H / 8), 1e-12 * p * 40);
        EXPECT_NEAR(Rq.x(), tau * (40.0 - H / 2 - H / 8), 1e-12 * tau * 40);
    }
}

// The paper's Q keeps 1/2 + k/4 of lambda_H(i), k the contact midpoints next to i: all of it at
// interior nodes, 3/4 at an end node. So sum Q lambda = sum lambda - (1/4) sum_ends lambda_end,
// which is exact only when the end nodes carry no force; the conservative rule keeps 3/4 at the
// end node itself and is exact for every field.
TEST(MultiplierTransfer, ConservativeRulePreservesTheResultantPaperOnlyWithUnloadedEnds) {
    for (const auto* levs : {&square_levels(), &hertz_levels()}) {
        for (int l = 0; l + 1 < 3; ++l) {
            const auto& C = (*levs)[static_cast<size_t>(l)];
            const auto& F = (*levs)[static_cast<size_t>(l) + 1];
            const ContactNodes cn = levels::contact_nodes(C), fn = levels::contact_nodes(F);
            const auto paper = make_transfer(C, F, QRule::paper);
            const auto cons = make_transfer(C, F, QRule::conservative);
            // The paper's rule keeps 1/2 + k/4 of lambda_H(i), k = contact midpoints fed by i.
            std::vector<int> k(static_cast<size_t>(C.mesh.n_vertices()), 0);
            const int nc = F.mesh.n_coarse_vertices;
            for (const auto& e : F.contacts)
                if (e.vertex[0] >= nc)
                    for (int pv : F.mesh.parents[static_cast<size_t>(e.vertex[0] - nc)])
                        if (C.contact_of_vertex[static_cast<size_t>(pv)] >= 0)
                            ++k[static_cast<size_t>(pv)];
            ContactNodes ends; // coarse nodes with k < 2, and the share the paper's rule drops
            std::vector<double> dropped;
            for (size_t i = 0; i < cn.vertex.size(); ++i) {
                const int kv = k[static_cast<size_t>(cn.vertex[i])];
                if (kv >= 2) continue;
                ends.vertex.push_back(cn.vertex[i]);
                ends.lambda_dof.push_back(cn.lambda_dof[i]);
                ends.n_multipliers.push_back(cn.n_multipliers[i]);
                dropped.push_back(0.5 - 0.25 * kv);
            }
            ASSERT_FALSE(ends.vertex.empty());
            if (levs == &square_levels()) {
                // One free end, the left one (the other is next to the fixed corner, k = 2).
                ASSERT_EQ(ends.vertex.size(), 1u);
                EXPECT_EQ(C.mesh.vertices[static_cast<size_t>(ends.vertex[0])].x(), 0.0);
                EXPECT_EQ(dropped[0], 0.25);
            }

            for (unsigned seed : {7u, 8u, 9u}) {
                Vector xc = random_field(C.n_unknowns(), seed);
                // Loaded ends whatever the random draw gave them (so `lost` below is not ~0).
                for (size_t e = 0; e < ends.vertex.size(); ++e)
                    for (int q = 0; q < ends.n_multipliers[e]; ++q)
                        xc[ends.lambda_dof[e] + q] = (q == 0 ? 1.0 : -0.5) * (1.0 + seed % 3);
                const Eigen::Vector2d Rc = transfer::multiplier_resultant(cn, xc);
                double scale = 0.0; // sum of |lambda| over the coarse multipliers
                for (size_t i = 0; i < cn.vertex.size(); ++i)
                    scale += xc.segment(cn.lambda_dof[i], cn.n_multipliers[i]).lpNorm<1>();
                Vector xp, xq;
                cons.prolongate(xc, xq);
                const Eigen::Vector2d Rq = transfer::multiplier_resultant(fn, xq);
                EXPECT_LT((Rq - Rc).lpNorm<Eigen::Infinity>(), 1e-14 * scale);
                paper.prolongate(xc, xp);
                const Eigen::Vector2d Rp = transfer::multiplier_resultant(fn, xp);
                Eigen::Vector2d lost = Eigen::Vector2d::Zero();
                for (size_t e = 0; e < ends.vertex.size(); ++e)
                    for (int q = 0; q < ends.n_multipliers[e]; ++q)
                        lost[q + 2 - ends.n_multipliers[e]] +=
                            dropped[e] * xc[ends.lambda_dof[e] + q];
                EXPECT_GT(lost.norm(), 1e-3);
                EXPECT_LT((Rc - Rp - lost).lpNorm<Eigen::Infinity>(), 1e-14 * scale);
                // Unloaded ends: the paper's rule is exact too.
                for (size_t e = 0; e < ends.vertex.size(); ++e)
                    for (int q = 0; q < ends.n_multipliers[e]; ++q)
                        xc[ends.lambda_dof[e] + q] = 0.0;
                paper.prolongate(xc, xp);
                EXPECT_LT((transfer::multiplier_resultant(fn, xp) -
                           transfer::multiplier_resultant(cn, xc))
                              .lpNorm<Eigen::Infinity>(),
                          1e-14 * scale);
            }
        }
    }
}

// The paper's claim on the problem it was made for: in the solved square (level 0, mu = 1, final
// load step) the left end of the contact edge has lifted off, so Q loses nothing there and the
// resultant of (lambda_t, lambda_n) survives the transfer to level 1 exactly.
TEST(MultiplierTransfer, PaperRuleIsExactOnTheSolvedSquareBecauseTheLeftEndLiftsOff) {
    auto p = scene::load_scene("square");
    p.levels = 0;
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    const levels::Level& C = r.finest();
    const levels::Level F = levels::build_level(p, mesh::refine(C.mesh));
    const auto tr = make_transfer(C, F);
    const int end = C.contact_of_vertex[0]; // vertex 0 is (0, 0), the left end
    ASSERT_GE(end, 0);
    const int d = C.lambda_dof[static_cast<size_t>(end)];
    const Eigen::Vector2d Rc = transfer::multiplier_resultant(levels::contact_nodes(C), r.x);
    EXPECT_LT(std::abs(r.x[d]) + std::abs(r.x[d + 1]), 1e-12 * Rc.norm());
    Vector xf;
    tr.prolongate(r.x, xf);
    const Eigen::Vector2d Rq = transfer::multiplier_resultant(levels::contact_nodes(F), xf);
    EXPECT_LT((Rq - Rc).norm(), 1e-12 * Rc.norm());
}

// Hertz: the contact region is a box, so the arc edge leaving it has one contact parent; its
// midpoint (if inside the box) receives a quarter of that node only.
TEST(MultiplierTransfer, MidpointsAtTheEdgeOfTheContactRegionTakeOneParent) {
    const auto& L = hertz_levels();
    for (int l = 0; l + 1 < 3; ++l) {
        const auto& C = L[static_cast<size_t>(l)];
        const auto& F = L[static_cast<size_t>(l) + 1];
        const auto tr = make_transfer(C, F);
        const int nc = F.mesh.n_coarse_vertices;
        int n_one_parent = 0;
        for (int i = 0; i < F.n_contact_nodes(); ++i) {
            const int v = F.contacts[static_cast<size_t>(i)].vertex[0];
            ASSERT_EQ(F.contacts[static_cast<size_t>(i)].n_multipliers(), 1);
            const int d = F.lambda_dof[static_cast<size_t>(i)];
            if (v < nc) {
                EXPECT_EQ(tr.T.row(d).nonZeros(), 1);
                EXPECT_EQ(tr.T.coeff(d, C.lambda_dof[static_cast<size_t>(
                                            C.contact_of_vertex[static_cast<size_t>(v)])]),
                          0.5);
                continue;
            }
            int n_contact_parents = 0;
            for (int pv : F.mesh.parents[static_cast<size_t>(v - nc)]) {
                const int j = C.contact_of_vertex[static_cast<size_t>(pv)];
                if (j < 0) continue;
                ++n_contact_parents;
                EXPECT_EQ(tr.T.coeff(d, C.lambda_dof[static_cast<size_t>(j)]), 0.25);
            }
            EXPECT_EQ(tr.T.row(d).nonZeros(), n_contact_parents);
            if (n_contact_parents == 1) ++n_one_parent;
        }
        EXPECT_LE(n_one_parent, 1);
    }
}

TEST(Transfer, SquareLadderUnknownCounts) {
    const auto p = scene::load_scene("square");
    // (N+1)^2 vertices with N = 16 * 2^l: 2 (N+1)^2 components, less u_x on the N+1 vertices of
    // the symmetry plane and u_y at the corner, plus (lambda_t, lambda_n) at the N contact nodes
    // (the corner is no contact node). Level 2: 8450 - 66 + 128 = 8512.
    const int want[] = {592, 2208, 8512, 33408, 132352};
    for (int l = 0; l <= 4; ++l) {
        const int N = 16 << l;
        EXPECT_EQ(want[l], 2 * (N + 1) * (N + 1) - (N + 1) - 1 + 2 * N);
    }
    mesh::Mesh m = p.mesh0;
    std::optional<levels::Level> prev;
    for (int l = 0; l <= 4; ++l) {
        if (l > 0) m = mesh::refine(m);
        levels::Level L = levels::build_level(p, m);
        EXPECT_EQ(L.n_unknowns(), want[l]) << "level " << l;
        if (prev) {
            const auto tr = make_transfer(*prev, L);
            EXPECT_EQ(static_cast<Index>(tr.coarse_set.size()), prev->n_unknowns());
            EXPECT_EQ(static_cast<Index>(tr.fine_set.size()), L.n_unknowns() - prev->n_unknowns());
        }
        prev = std::move(L);
    }
}

TEST(Transfer, RejectsLevelsThatDoNotNest) {
    const auto& L = square_levels();
    const auto& C = L[0];
    const auto& F = L[1];
    const ContactNodes cn = levels::contact_nodes(C), fn = levels::contact_nodes(F);
    // Not a refined mesh / wrong numberings.
    EXPECT_THROW(transfer::build_transfer(C.mesh, C.dofs, F.dofs, cn, fn), InvalidInput);
    EXPECT_THROW(transfer::build_transfer(F.mesh, F.dofs, F.dofs, cn, fn), InvalidInput);
    EXPECT_THROW(transfer::build_transfer(L[2].mesh, C.dofs, F.dofs, cn, fn), InvalidInput);
    // A coarse contact vertex that is no fine contact vertex.
    ContactNodes fewer = fn;
    const auto it = std::find(fewer.vertex.begin(), fewer.vertex.end(), cn.vertex[3]);
    ASSERT_NE(it, fewer.vertex.end());
    const auto k = it - fewer.vertex.begin();
    fewer.vertex.erase(it);
    fewer.lambda_dof.erase(fewer.lambda_dof.begin() + k);
    fewer.n_multipliers.erase(fewer.n_multipliers.begin() + k);
    EXPECT_THROW(transfer::build_transfer(F.mesh, C.dofs, F.dofs, cn, fewer), InvalidInput);
    // A different multiplier count (frictionless on the fine level only).
    auto p = scene::load_scene("square");
    p.contacts[0].mu = 0.0;
    const auto F0 = levels::build_level(p, F.mesh);
    EXPECT_THROW(transfer::build_transfer(F.mesh, C.dofs, F0.dofs, cn, levels::contact_nodes(F0)),
                 InvalidInput);
    // lambda_dof that does not match the numbering; ragged lists.
    ContactNodes bad = fn;
    bad.lambda_dof[0] += 1;
    EXPECT_THROW(transfer::build_transfer(F.mesh, C.dofs, F.dofs, cn, bad), InvalidInput);
    bad = fn;
    bad.n_multipliers.pop_back();
    EXPECT_THROW(transfer::build_transfer(F.mesh, C.dofs, F.dofs, cn, bad), InvalidInput);
    // Apply with a vector of the wrong size, or in place.
    const auto tr = make_transfer(C, F);
    Vector y;
    EXPECT_THROW(tr.prolongate(Vector::Zero(F.n_unknowns()), y), InvalidInput);
    EXPECT_THROW(tr.restrict_to_coarse(Vector::Zero(C.n_unknowns()), y), InvalidInput);
    EXPECT_THROW(tr.interpolate_nodal(Vector::Zero(3), y), InvalidInput);
    Vector x = Vector::Zero(C.n_unknowns());
    EXPECT_THROW(tr.prolongate(x, x), InvalidInput);
}

TEST(Transfer, LevelsThatDoNotNestAreRefusedNamingTheDefect) {
    const mesh::Mesh m0 = mesh::structured_rectangle(Vec2(0.0, 0.0), Vec2(1.0, 1.0), 2, 2);
    mesh::Mesh m1 = mesh::refine(m0);
    auto plain = [](const mesh::Mesh& m) {
        return fem::DofMap(std::vector<std::array<bool, 2>>(static_cast<size_t>(m.n_vertices())),
                           std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    };
    auto message = [&](const mesh::Mesh& fine, const mesh::Mesh& coarse) {
        try {
            transfer::build_transfer(fine, plain(coarse), plain(fine), {}, {});
        } catch (const InvalidInput& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    // A level-0 mesh is no refinement; a new vertex with one parent twice is no edge midpoint;
    // a coarse numbering of another mesh does not nest.
    EXPECT_NE(message(m0, m0).find("must come from mesh::refine"), std::string::npos);
    mesh::Mesh bad = m1;
    bad.parents[3] = {bad.parents[3][0], bad.parents[3][0]};
    EXPECT_NE(
        message(bad, m0).find("new vertex " + std::to_string(m0.n_vertices() + 3) + " has parents"),
        std::string::npos)
        << message(bad, m0);
    EXPECT_NE(message(m1, m1).find("coarse numbering has"), std::string::npos);
    EXPECT_EQ(message(m1, m0), "accepted");
}
