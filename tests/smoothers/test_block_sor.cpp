// SPDX-License-Identifier: MIT
// Point and block SOR / SSOR against their explicit matrices (D/omega + L etc.).
#include "core/check.hpp"
#include "core/csr.hpp"
#include "smoothers/block_sor.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <sstream>

using namespace mlc;
using testmat::probe;
using namespace mlc::smoothers;

namespace {

// Explicit block splitting A = L + D + U for the given block starts (followed by n).
void splitting(const SparseMatrix& A, std::vector<Index> starts, Eigen::MatrixXd& L,
               Eigen::MatrixXd& D, Eigen::MatrixXd& U) {
    const Eigen::MatrixXd Ad = testmat::dense(A);
    const Index n = A.rows();
    if (starts.empty())
        for (Index i = 0; i < n; ++i)
            starts.push_back(i);
    starts.push_back(n);
    std::vector<Index> block_of(n);
    for (size_t b = 0; b + 1 < starts.size(); ++b)
        for (Index i = starts[b]; i < starts[b + 1]; ++i)
            block_of[i] = static_cast<Index>(b);
    L.setZero(n, n);
    D.setZero(n, n);
    U.setZero(n, n);
    for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < n; ++j) {
            if (block_of[i] > block_of[j]) L(i, j) = Ad(i, j);
            if (block_of[i] == block_of[j]) D(i, j) = Ad(i, j);
            if (block_of[i] < block_of[j]) U(i, j) = Ad(i, j);
        }
}

// Dense C^{-1} of one sweep for the given direction.
Eigen::MatrixXd explicit_inverse(const SparseMatrix& A, const std::vector<Index>& starts, double w,
                                 Sweep sweep) {
    Eigen::MatrixXd L, D, U;
    splitting(A, starts, L, D, U);
    const Eigen::MatrixXd Mf = D / w + L, Mb = D / w + U;
    if (sweep == Sweep::forward) return Mf.inverse();
    if (sweep == Sweep::backward) return Mb.inverse();
    const Eigen::MatrixXd C = w / (2.0 - w) * Mf * D.inverse() * Mb;
    return C.inverse();
}

struct SorCase {
    const char* name;
    SparseMatrix A;
    std::vector<Index> starts;
};

std::vector<SorCase> sor_cases() {
    std::vector<SorCase> c;
    c.push_back({"point convdiff", testmat::convection_diffusion(), {}});
    c.push_back({"2x2 convdiff", testmat::convection_diffusion(), uniform_block_starts(36, 2)});
    std::vector<Index> vs;
    SparseMatrix S = testmat::contact_saddle(8, &vs);
    c.push_back({"vertex+multiplier saddle", S, vs});
    return c;
}

} // namespace

TEST(BlockSOR, ApplyEqualsExplicitFormula) {
    for (const auto& c : sor_cases())
        for (Sweep sweep : {Sweep::forward, Sweep::backward, Sweep::symmetric})
            for (double w : {1.0, 1.3, 0.6}) {
                BlockSOR S(BlockSORParams{.omega = w, .sweep = sweep, .block_starts = c.starts});
                S.setup(c.A);
                const Eigen::MatrixXd Cinv = explicit_inverse(c.A, c.starts, w, sweep);
                for (unsigned s = 1; s <= 3; ++s) {
                    const Vector r = testmat::pseudo_random(c.A.rows(), s);
                    Vector z;
                    S.apply(r, z);
                    const Vector ze = Cinv * r;
                    EXPECT_LE((z - ze).norm(), 1e-12 * ze.norm())
                        << c.name << " " << sweep << " omega " << w;
                }
            }
}

TEST(BlockSOR, TransposeEqualsProbedTranspose) {
    for (const auto& c : sor_cases())
        for (Sweep sweep : {Sweep::forward, Sweep::backward, Sweep::symmetric})
            for (int sweeps : {1, 2}) {
                BlockSOR S(BlockSORParams{
                    .omega = 1.2, .sweep = sweep, .n_sweeps = sweeps, .block_starts = c.starts});
                S.setup(c.A);
                const Eigen::MatrixXd C = probe(S, c.A.rows(), false);
                const Eigen::MatrixXd Ct = probe(S, c.A.rows(), true);
                EXPECT_LE((Ct - C.transpose()).norm(), 1e-12 * C.norm())
                    << c.name << " " << sweep << " sweeps " << sweeps;
            }
}

TEST(BlockSOR, SmoothAndRepeatedSweepsFollowTheIteration) {
    for (const auto& c : sor_cases())
        for (Sweep sweep : {Sweep::forward, Sweep::symmetric}) {
            const double w = 1.1;
            BlockSOR S(BlockSORParams{
                .omega = w, .sweep = sweep, .n_sweeps = 2, .block_starts = c.starts});
            S.setup(c.A);
            const Eigen::MatrixXd Ad = testmat::dense(c.A);
            const Eigen::MatrixXd C1 = explicit_inverse(c.A, c.starts, w, sweep);
            const Vector b = testmat::pseudo_random(c.A.rows(), 7);
            Vector x = testmat::pseudo_random(c.A.rows(), 8), xe = x;
            S.smooth(b, x);
            for (int k = 0; k < 2; ++k)
                xe += C1 * (b - Ad * xe);
            EXPECT_LE((x - xe).norm(), 1e-12 * xe.norm()) << c.name << " " << sweep;
            // apply = smooth from zero.
            Vector z, z0 = Vector::Zero(c.A.rows());
            S.apply(b, z);
            S.smooth(b, z0);
            EXPECT_LE((z - z0).norm(), 1e-13 * z.norm()) << c.name << " " << sweep;
        }
}

TEST(BlockSOR, ZeroScalarDiagonalInsideABlockIsFine) {
    std::vector<Index> vs;
    const SparseMatrix A = testmat::contact_saddle(8, &vs);
    BlockSOR point;
    try {
        point.setup(A);
        FAIL() << "expected InvalidInput for a zero diagonal with point blocks";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("zero or missing diagonal in row"), std::string::npos)
            << e.what();
    }
    BlockSOR block(BlockSORParams{.block_starts = vs});
    EXPECT_NO_THROW(block.setup(A));
    EXPECT_EQ(block.n_blocks(), 8);
    EXPECT_EQ(block.max_block_size(), 4);
}

TEST(BlockSOR, RejectsBadParamsAndBlocking) {
    EXPECT_THROW(BlockSOR(BlockSORParams{.omega = 0.0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.omega = 2.0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.n_sweeps = 0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.block_size = 0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.block_starts = {1, 3}}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.block_starts = {0, 3, 3}}), InvalidInput);
    BlockSOR S(BlockSORParams{.block_starts = {0, 2, 40}});
    EXPECT_THROW(S.setup(testmat::laplace_1d(10)), InvalidInput);
    std::ostringstream os;
    os << BlockSORParams{};
    EXPECT_NE(os.str().find("omega=1"), std::string::npos);
    EXPECT_EQ(BlockSOR(BlockSORParams{.omega = 1.5, .sweep = Sweep::symmetric}).name(),
              "ssor(omega=1.5)");
}

namespace {

// Two vertex + multiplier blocks (rows 0..3 and 4..7) with the given 4x4 diagonal block D, the
// same at both vertices, coupled through their displacements by -c (a weak elastic spring).
SparseMatrix two_contact_vertices(const Eigen::Matrix4d& D, double c) {
    std::vector<Triplet> t;
    for (int v = 0; v < 2; ++v)
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                if (D(i, j) != 0.0) t.emplace_back(4 * v + i, 4 * v + j, D(i, j));
    for (int d = 0; d < 2; ++d) {
        t.emplace_back(d, 4 + d, -c);
        t.emplace_back(4 + d, d, -c);
    }
    SparseMatrix A(8, 8);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
}

// The blocks that stopped the mg smoother (square, level 4): a gap vertex with r = 1.3e9
// ([[K, 0], [0, -I/r]]: pivots 1e5 and 7.7e-10) and a slip vertex with nu = 0.4999 (K of
// size 2e8 next to multiplier entries of size 1 and 1/r = 7.7e-5).
Eigen::Matrix4d gap_block_large_r() {
    Eigen::Matrix4d D = Eigen::Matrix4d::Zero();
    D(0, 0) = D(1, 1) = 99305.6;
    D(2, 2) = D(3, 3) = -1.0 / 1.3e9;
    return D;
}
Eigen::Matrix4d slip_block_nearly_incompressible() {
    Eigen::Matrix4d D;
    D << 2.16768e+08, -1.08354e+08, 0, -1, //
        -1.08341e+08, 2.16781e+08, 0, 1,   //
        0, -1, -7.69231e-05, -7.69231e-05, //
        0, 1, 0, 0;
    return D;
}

} // namespace

TEST(BlockSOR, BlocksSingularOnlyInFloatingPointAreInverted) {
    for (const Kernel kernel : {Kernel::in_order, Kernel::unrolled})
        for (const Eigen::Matrix4d& D : {gap_block_large_r(), slip_block_nearly_incompressible()}) {
            // The old tests: the unrolled kernel's full-pivot LU and the in-order kernel's
            // partial-pivot LU against singular_tol times the largest entry both reject D.
            Eigen::FullPivLU<Eigen::MatrixXd> full(D);
            full.setThreshold(1e-14);
            ASSERT_FALSE(full.isInvertible());
            const SparseMatrix A = two_contact_vertices(D, 1e-3);
            BlockSOR S(BlockSORParams{.block_starts = {0, 4}, .kernel = kernel});
            ASSERT_NO_THROW(S.setup(A));
            // One sweep solves each block exactly: the block part of the residual vanishes
            // and the whole residual drops, with a finite correction.
            const Vector b = Vector::LinSpaced(8, 1.0, 8.0);
            Vector x = Vector::Zero(8);
            S.smooth(b, x);
            ASSERT_TRUE(x.allFinite());
            const Vector r = b - A * x;
            EXPECT_LT(r.norm(), 1e-2 * b.norm()) << to_string(kernel);
            // The block inverse itself is backward stable: A x = b for the decoupled blocks up
            // to round-off in ||A|| ||x||.
            const SparseMatrix A0 = two_contact_vertices(D, 0.0);
            S.setup(A0);
            S.apply(b, x);
            const double scale = testmat::dense(A0).cwiseAbs().maxCoeff() * x.cwiseAbs().maxCoeff();
            EXPECT_LT((A0 * x - b).lpNorm<Eigen::Infinity>(), 1e-14 * scale) << to_string(kernel);
        }
}

TEST(BlockSOR, RegularBlocksKeepTheirFastPathBitForBit) {
    // A regular 2x2 and 4x4 block: the unrolled kernel's inverses are the closed form and
    // omega times Eigen's full-pivot LU inverse; the in-order kernel's the partial-pivot one,
    // with omega applied after the block product, exactly as before the fallback existed.
    Eigen::Matrix4d D;
    D << 4, -1, 0.5, 0, //
        -1, 5, 0, 1,    //
        0.5, 0, -2, 0,  //
        0, 1, 0, -3;
    const SparseMatrix A = two_contact_vertices(D, 0.0);
    Eigen::Matrix4d D2 = D; // its 2x2 diagonal blocks only, for 2x2 blocking
    D2.block(0, 2, 2, 2).setZero();
    D2.block(2, 0, 2, 2).setZero();
    const SparseMatrix A2 = two_contact_vertices(D2, 0.0);
    const Vector b = Vector::LinSpaced(8, -1.0, 3.0);
    const double w = 1.3;
    for (const Kernel kernel : {Kernel::in_order, Kernel::unrolled}) {
        BlockSOR S(BlockSORParams{.omega = w, .block_starts = {0, 2, 4, 6}, .kernel = kernel});
        S.setup(A2);
        Vector x;
        S.apply(b, x);
        for (int blk = 0; blk < 4; ++blk) {
            const Eigen::Matrix2d Db = testmat::dense(A2).block(2 * blk, 2 * blk, 2, 2);
            Eigen::Matrix2d inv;
            if (kernel == Kernel::unrolled) {
                const double det = Db(0, 0) * Db(1, 1) - Db(0, 1) * Db(1, 0);
                const double f = w / det;
                inv << f * Db(1, 1), -f * Db(0, 1), -f * Db(1, 0), f * Db(0, 0);
            } else {
                inv = Eigen::PartialPivLU<Eigen::MatrixXd>(Db).inverse();
            }
            // The sweep's residual for this block (the blocks are decoupled: b itself).
            for (int a = 0; a < 2; ++a) {
                double c = 0.0;
                for (int q = 0; q < 2; ++q)
                    c += inv(a, q) * b[2 * blk + q];
                const double expected = kernel == Kernel::unrolled ? c : w * c;
                EXPECT_EQ(x[2 * blk + a], expected) << to_string(kernel) << " block " << blk;
            }
        }
        BlockSOR S4(BlockSORParams{.omega = w, .block_starts = {0, 4}, .kernel = kernel});
        S4.setup(A);
        S4.apply(b, x);
        Eigen::Matrix4d inv;
        if (kernel == Kernel::unrolled) {
            Eigen::FullPivLU<Eigen::MatrixXd> lu{Eigen::MatrixXd(D)};
            lu.setThreshold(1e-14);
            inv = w * lu.inverse();
        } else {
            inv = Eigen::PartialPivLU<Eigen::MatrixXd>(Eigen::MatrixXd(D)).inverse();
        }
        for (int a = 0; a < 4; ++a) {
            double c = 0.0;
            for (int q = 0; q < 4; ++q)
                c += inv(a, q) * b[q];
            EXPECT_EQ(x[a], kernel == Kernel::unrolled ? c : w * c) << to_string(kernel);
        }
    }
}

TEST(BlockSOR, TrulySingularBlockIsABreakdownAndAZeroRowABadBlocking) {
    // Rank 3 with no zero row or column: a numerical breakdown, named with the block.
    Eigen::Matrix4d D;
    D << 1, 2, 0, 1, //
        2, 4, 0, 2,  //
        0, 0, 3, 1,  //
        1, 0, 1, 5;
    for (const Kernel kernel : {Kernel::in_order, Kernel::unrolled}) {
        BlockSOR S(BlockSORParams{.block_starts = {0, 4}, .kernel = kernel});
        try {
            S.setup(two_contact_vertices(D, 0.0));
            FAIL() << "expected SolverBreakdown";
        } catch (const SolverBreakdown& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("diagonal block 0 (rows 0..3)"), std::string::npos) << m;
            EXPECT_NE(m.find("rank 3 of 4"), std::string::npos) << m;
        }
        // A zero row in the block: the blocking does not suit A.
        Eigen::Matrix4d Z = D;
        Z.row(3).setZero();
        Z(3, 3) = 0.0;
        SparseMatrix A = two_contact_vertices(Z, 0.0);
        A.coeffRef(3, 7) = 1.0; // row 3 is not empty, only its diagonal block part
        A.makeCompressed();
        EXPECT_THROW(S.setup(A), InvalidInput);
    }
}

TEST(BlockSOR, ADecoupledUnknownGetsNoCorrectionAndTheRestOfItsBlockIsInverted) {
    // A stuck contact node whose tangential displacement is prescribed: its tangential
    // multiplier (row and column 1 of the block) has vanished from the Jacobian.
    Eigen::Matrix4d D;
    D << 4, 0, 1, 0, //
        0, 0, 0, 0,  //
        1, 0, 3, 1,  //
        0, 0, 1, 2;
    for (const Kernel kernel : {Kernel::in_order, Kernel::unrolled}) {
        SCOPED_TRACE(to_string(kernel));
        const SparseMatrix A = two_contact_vertices(D, 0.0);
        BlockSOR S(BlockSORParams{.block_starts = {0, 4}, .kernel = kernel});
        ASSERT_NO_THROW(S.setup(A));
        Vector b = Vector::LinSpaced(8, 1.0, 8.0);
        b[1] = b[5] = 0.0; // consistent right-hand side: the decoupled rows read 0 = 0
        Vector x;
        S.apply(b, x);
        EXPECT_EQ(x[1], 0.0);
        EXPECT_EQ(x[5], 0.0);
        // The other unknowns solve their 3x3 blocks exactly.
        EXPECT_LT((A * x - b).lpNorm<Eigen::Infinity>(), 1e-14 * 8.0);
    }
}

TEST(BlockSOR, TwinRowsOfAVertexBlockSweepAsTheirRowsOneByOneBitForBit) {
    // The unrolled kernel sweeps a 2x2 block whose rows have the same columns (a vertex of K) in
    // one pass over its columns. Reference: each row on its own by core's row_dot (own part
    // first, then the other parts' snapshot before and after it), the closed-form 2x2 inverse,
    // on a chain of 7 000 vertices coupled to the vertices 1, 2 and 50 away, in three parts (the
    // long couplings cross the cuts). Every 7th vertex's second row misses one coupling, so
    // twin and non-twin blocks alternate.
    const int nv = 7000;
    const Index n = 2 * nv;
    std::vector<Eigen::Triplet<double>> trip;
    unsigned state = 12345u;
    auto next = [&] { // values in [-1, 1)
        state = state * 1664525u + 1013904223u;
        return static_cast<double>(state >> 8) / static_cast<double>(1u << 23) - 1.0;
    };
    for (int v = 0; v < nv; ++v) {
        for (int a = 0; a < 2; ++a)
            for (int c = 0; c < 2; ++c)
                trip.emplace_back(2 * v + a, 2 * v + c, (a == c ? 12.0 : 0.0) + next());
        for (const int d : {-50, -2, -1, 1, 2, 50}) {
            const int w = v + d;
            if (w < 0 || w >= nv) continue;
            for (int a = 0; a < 2; ++a) {
                if (a == 1 && v % 7 == 3 && d == 1) continue; // not twins
                for (int c = 0; c < 2; ++c)
                    trip.emplace_back(2 * v + a, 2 * w + c, next());
            }
        }
    }
    SparseMatrix A(n, n);
    A.setFromTriplets(trip.begin(), trip.end());
    A.makeCompressed();
    const double w = 1.1;
    BlockSOR S(BlockSORParams{.omega = w, .block_size = 2, .parts = 3, .kernel = Kernel::unrolled});
    S.setup(A);
    ASSERT_EQ(S.parts(), 3);
    Vector b(n), x0(n);
    for (Index i = 0; i < n; ++i) {
        b[i] = next();
        x0[i] = next();
    }
    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    const double* av = A.valuePtr();
    const std::vector<Index> rows = S.part_rows();
    // The unrolled kernel's closed-form inverse of block [i0, i0 + 2) (omega w) times (t0, t1),
    // each entry summed from 0.0 as the kernel does.
    auto block_solve = [&](Index i0, double t0, double t1) {
        const double d00 = A.coeff(i0, i0), d01 = A.coeff(i0, i0 + 1);
        const double d10 = A.coeff(i0 + 1, i0), d11 = A.coeff(i0 + 1, i0 + 1);
        const double f = w / (d00 * d11 - d01 * d10);
        const double inv[4] = {f * d11, -f * d01, -f * d10, f * d00};
        std::array<double, 2> c{0.0, 0.0};
        for (int a = 0; a < 2; ++a) {
            c[a] += inv[2 * a] * t0;
            c[a] += inv[2 * a + 1] * t1;
        }
        return c;
    };
    auto reference_half_sweep = [&](Vector& x, bool forward) {
        const Vector snap = x;
        for (size_t p = 0; p + 1 < rows.size(); ++p) {
            const Index r0 = rows[p], r1 = rows[p + 1];
            for (Index k = 0; k < (r1 - r0) / 2; ++k) {
                const Index i0 = forward ? r0 + 2 * k : r1 - 2 - 2 * k;
                double t[2];
                for (int a = 0; a < 2; ++a) {
                    const Index i = i0 + a;
                    const int ob =
                        static_cast<int>(std::lower_bound(ai + ao[i], ai + ao[i + 1], r0) - ai);
                    const int oe =
                        static_cast<int>(std::lower_bound(ai + ob, ai + ao[i + 1], r1) - ai);
                    t[a] = b[i] - row_dot(ai, av, x.data(), ob, oe) -
                           row_dot(ai, av, snap.data(), ao[i], ob) -
                           row_dot(ai, av, snap.data(), oe, ao[i + 1]);
                }
                const auto c = block_solve(i0, t[0], t[1]);
                x[i0] += c[0];
                x[i0 + 1] += c[1];
            }
        }
    };
    Vector want = x0;
    reference_half_sweep(want, true);
    reference_half_sweep(want, false);
    Vector x = x0;
    S.sweep(b, x, Sweep::symmetric);
    int differing = 0;
    for (Index i = 0; i < n; ++i)
        differing += x[i] != want[i];
    EXPECT_EQ(differing, 0) << "of " << n << " entries";
    EXPECT_GT((x - x0).norm(), 0.1 * x0.norm()); // the sweep did something

    // forward_from_zero: each part's lower entries from x = 0, then the residual b - A x as
    // (b - own lower part) - (diagonal and upper part + other parts' lower part), row by row.
    Vector xz(n), rz(n);
    for (size_t p = 0; p + 1 < rows.size(); ++p) {
        const Index r0 = rows[p], r1 = rows[p + 1];
        for (Index i0 = r0; i0 < r1; i0 += 2) {
            for (int a = 0; a < 2; ++a) {
                const Index i = i0 + a;
                const int ob =
                    static_cast<int>(std::lower_bound(ai + ao[i], ai + ao[i + 1], r0) - ai);
                const int db =
                    static_cast<int>(std::lower_bound(ai + ao[i], ai + ao[i + 1], i0) - ai);
                rz[i] = b[i] - row_dot(ai, av, xz.data(), ob, db);
            }
            const auto c = block_solve(i0, rz[i0], rz[i0 + 1]);
            xz[i0] = c[0];
            xz[i0 + 1] = c[1];
        }
    }
    for (size_t p = 0; p + 1 < rows.size(); ++p)
        for (Index i = rows[p]; i < rows[p + 1]; ++i) {
            const Index i0 = i - (i - rows[p]) % 2;
            const int ob =
                static_cast<int>(std::lower_bound(ai + ao[i], ai + ao[i + 1], rows[p]) - ai);
            const int db = static_cast<int>(std::lower_bound(ai + ao[i], ai + ao[i + 1], i0) - ai);
            rz[i] -=
                row_dot(ai, av, xz.data(), db, ao[i + 1]) + row_dot(ai, av, xz.data(), ao[i], ob);
        }
    Vector xf, rf;
    S.forward_from_zero(b, xf, rf);
    int differing_x = 0, differing_r = 0;
    for (Index i = 0; i < n; ++i) {
        differing_x += xf[i] != xz[i];
        differing_r += rf[i] != rz[i];
    }
    EXPECT_EQ(differing_x, 0) << "of " << n << " entries of x";
    EXPECT_EQ(differing_r, 0) << "of " << n << " entries of the residual";
    Vector check = b;
    check.noalias() -= A * xf;
    EXPECT_LT((rf - check).norm(), 1e-12 * b.norm()); // and it is b - A x
}
