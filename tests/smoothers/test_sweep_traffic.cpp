// SPDX-License-Identifier: MIT
// The smoother's traffic count (core/traffic.hpp): a block Gauss–Seidel half-sweep counts one
// pass of sweep_bytes, the multigrid's forward sweep from zero with its residual two passes of
// sweep_from_zero_bytes, on a known 4 x 4 tridiagonal matrix with two 2 x 2 blocks.
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
