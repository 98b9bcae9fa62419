// SPDX-License-Identifier: MIT
// The smoother's traffic count (core/traffic.hpp): a block Gauss–Seidel half-sweep counts one
// pass of sweep_bytes, the multigrid's forward sweep from zero with its residual two passes of
// sweep_from_zero_bytes, on a known 4 x 4 tridiagonal matrix with two 2 x 2 blocks.
#include "core/check.hpp"
#include "core/traffic.hpp"
#include "smoothers/block_sor.hpp"

#include <gtest/gtest.h>

using namespace mlc;
using namespace mlc::smoothers;

namespace {

// 4 x 4 tridiagonal: 10 stored entries.
SparseMatrix tridiagonal() {
    std::vector<Triplet> t;
    for (int i = 0; i < 4; ++i) {
        t.emplace_back(i, i, 4.0);
        if (i > 0) t.emplace_back(i, i - 1, -1.0);
        if (i < 3) t.emplace_back(i, i + 1, -1.0);
    }
    SparseMatrix A(4, 4);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
}

} // namespace

TEST(SweepTraffic, HalfSweepsAndTheSweepFromZeroCountTheirClosedForms) {
    const SparseMatrix A = tridiagonal();
    ASSERT_EQ(A.nonZeros(), 10);
    // 12 * 10 + 4 * 5 (matrix) + 8 * 8 (two 2 x 2 inverses) + 8 * 5 (block starts, offsets)
    // + 8 * 4 (row bounds) + 8 * 4 (b) + 16 * 4 (x read and written).
    const double sweep = 372.0;
    // 12 * 10 + 8 * 5 + 8 * 8 + 8 * 5 + 16 * 4 + 8 * 4 (b) + 16 * 4 (x) + 24 * 4 (residual).
    const double from_zero = 520.0;
    ASSERT_EQ(traffic::sweep_bytes(4, 10, 2, 8), sweep);
    ASSERT_EQ(traffic::sweep_from_zero_bytes(4, 10, 2, 8), from_zero);
    for (const Kernel kernel : {Kernel::in_order, Kernel::unrolled}) {
        BlockSOR s(BlockSORParams{.sweep = Sweep::symmetric, .block_size = 2, .kernel = kernel});
        s.setup(A);
        const Vector b = Vector::Ones(4);
        Vector x, res;
        traffic::Account a0 = traffic::snapshot();
        s.apply(b, x); // one symmetric sweep: two half-sweeps
        traffic::Account d = traffic::snapshot() - a0;
        EXPECT_EQ(d.b(traffic::Kind::smoother), 2 * sweep) << to_string(kernel);
        EXPECT_EQ(d.p(traffic::Kind::smoother), 2.0);
        EXPECT_EQ(d.total_bytes(), 2 * sweep);
        a0 = traffic::snapshot();
        s.forward_from_zero(b, x, res);
        d = traffic::snapshot() - a0;
        EXPECT_EQ(d.b(traffic::Kind::smoother), from_zero) << to_string(kernel);
        EXPECT_EQ(d.p(traffic::Kind::smoother), 2.0);
        // The residual it returns is b - A x.
        EXPECT_LT((res - (b - A * x)).norm(), 1e-14);
    }
}

TEST(SweepTraffic, SinglePrecisionSweepsCountFourByteValues) {
    const SparseMatrix A = tridiagonal();
    // 8 * 10 + 4 * 5 (float values, int indices, offsets) + 4 * 8 (float inverses)
    // + 8 * 5 + 8 * 4 + 8 * 4 + 16 * 4: 72 bytes fewer than the double sweep's 372.
    const double sweep = 300.0;
    // 8 * 10 + 8 * 5 + 4 * 8 + 8 * 5 + 16 * 4 + 8 * 4 + 16 * 4 + 24 * 4 (double: 520).
    const double from_zero = 448.0;
    ASSERT_EQ(traffic::sweep_bytes(4, 10, 2, 8, 4), sweep);
    ASSERT_EQ(traffic::sweep_from_zero_bytes(4, 10, 2, 8, 4), from_zero);
    const Vector b = (Vector(4) << 1.0, 0.3, -0.7, 2.0).finished();
    for (const Kernel kernel : {Kernel::in_order, Kernel::unrolled}) {
        BlockSORParams p{.sweep = Sweep::symmetric, .block_size = 2, .kernel = kernel};
        BlockSOR s64(p);
        p.precision = Precision::float32;
        BlockSOR s32(p);
        s64.setup(A);
        s32.setup(A);
        EXPECT_NE(s32.name().find(",single"), std::string::npos);
        Vector x32, x64, r32, r64;
        traffic::Account a0 = traffic::snapshot();
        s32.apply(b, x32);
        traffic::Account d = traffic::snapshot() - a0;
        EXPECT_EQ(d.b(traffic::Kind::smoother), 2 * sweep) << to_string(kernel);
        EXPECT_EQ(d.p(traffic::Kind::smoother), 2.0);
        EXPECT_EQ(d.total_bytes(), 2 * sweep);
        a0 = traffic::snapshot();
        s32.forward_from_zero(b, x32, r32);
        d = traffic::snapshot() - a0;
        EXPECT_EQ(d.b(traffic::Kind::smoother), from_zero) << to_string(kernel);
        EXPECT_EQ(d.p(traffic::Kind::smoother), 2.0);
        // The same map up to the rounding of the block inverses (1/15 [[4, 1], [1, 4]] is not a
        // float): within float's precision of the double sweep, but not equal to it.
        s64.forward_from_zero(b, x64, r64);
        EXPECT_LT((x32 - x64).norm(), 1e-6 * x64.norm()) << to_string(kernel);
        EXPECT_GT((x32 - x64).norm(), 0.0) << to_string(kernel);
        // The residual is b - A x with A's entries as stored (these are exact in float).
        EXPECT_LT((r32 - (b - A * x32)).norm(), 1e-14);
        // No transpose of the float sweeps.
        BlockSORParams q{.block_size = 2, .precision = Precision::float32};
        BlockSOR t(q);
        t.setup(A);
        EXPECT_THROW(t.apply_transpose(b, x32), InvalidInput);
    }
}
