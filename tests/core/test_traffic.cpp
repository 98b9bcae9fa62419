// SPDX-License-Identifier: MIT
// The traffic account of core/traffic.hpp: a CSR mat-vec counts exactly the closed form of the
// header on a known matrix (values, indices, offsets, x once, y once, y twice with `add`),
// under the kind it is given; MatrixOperator's Eigen path counts the same; timing is kept only
// when switched on; STREAM returns positive finite bandwidths.
#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/first_touch.hpp"
#include "core/linear_operator.hpp"
#include "core/parallel.hpp"
#include "core/traffic.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mlc {
namespace {

// 3 x 4 with 5 stored entries.
SparseMatrix known_matrix() {
    std::vector<Triplet> t{{0, 0, 1.0}, {0, 3, 2.0}, {1, 1, 3.0}, {2, 0, 4.0}, {2, 2, 5.0}};
    SparseMatrix A(3, 4);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
}

TEST(Traffic, CsrMultiplyCountsTheClosedForm) {
    const SparseMatrix A = known_matrix();
    ASSERT_EQ(A.nonZeros(), 5);
    // 12 * 5 (values and column indices) + 4 * 4 (row offsets) + 8 * 4 (x) + 8 * 3 (y).
    EXPECT_EQ(traffic::csr_bytes(3, 4, 5, false), 132.0);
    EXPECT_EQ(traffic::csr_bytes(3, 4, 5, true), 156.0); // + 8 * 3: y read too
    const Vector x = Vector::Ones(4);
    Vector y;
    const traffic::Account a0 = traffic::snapshot();
    csr_multiply(A, x, y);
    const traffic::Account a1 = traffic::snapshot();
    csr_multiply(A, x, y, true, traffic::Kind::transfer);
    const traffic::Account a2 = traffic::snapshot();
    const traffic::Account d1 = a1 - a0, d2 = a2 - a1;
    EXPECT_EQ(d1.b(traffic::Kind::matvec), 132.0);
    EXPECT_EQ(d1.p(traffic::Kind::matvec), 1.0);
    EXPECT_EQ(d1.total_bytes(), 132.0);
    EXPECT_EQ(d2.b(traffic::Kind::transfer), 156.0);
    EXPECT_EQ(d2.p(traffic::Kind::transfer), 1.0);
    EXPECT_EQ(d2.b(traffic::Kind::matvec), 0.0);
    EXPECT_EQ(y, Vector((Vector(3) << 6.0, 6.0, 18.0).finished()));
}

TEST(Traffic, SinglePrecisionValuesCountFourBytes) {
    // The same 3 x 4 matrix with float values: 8 * 5 (values and indices) + 4 * 4 + 8 * 4 + 8 * 3.
    EXPECT_EQ(traffic::csr_bytes(3, 4, 5, false, 4), 112.0);
    EXPECT_EQ(traffic::csr_bytes(3, 4, 5, true, 4), 136.0);
    const SparseMatrix A = known_matrix();
    parallel::UninitializedVector<float> v32;
    round_values(A, v32, "test");
    const Vector x = (Vector(4) << 1.0, 0.1, 0.5, 1.0 / 3.0).finished();
    Vector y, y64, res;
    traffic::Account a0 = traffic::snapshot();
    csr_multiply(csr_arrays(A, v32.data()), x, y, false, traffic::Kind::transfer);
    traffic::Account d = traffic::snapshot() - a0;
    EXPECT_EQ(d.b(traffic::Kind::transfer), 112.0);
    EXPECT_EQ(d.p(traffic::Kind::transfer), 1.0);
    // The values are small integers (exact in float) and products are summed in double: the
    // float path gives the double one's result bit for bit.
    csr_multiply(A, x, y64);
    EXPECT_EQ(y, y64);
    a0 = traffic::snapshot();
    csr_residual(csr_arrays(A, v32.data()), Vector::Ones(3), x, res, traffic::Kind::matvec);
    d = traffic::snapshot() - a0;
    EXPECT_EQ(d.b(traffic::Kind::matvec), 136.0);
    EXPECT_EQ(res, Vector(Vector::Ones(3) - y64));
    // Rounding is real (0.1 is not a float) and a value beyond float's range is refused.
    SparseMatrix B = A;
    B.valuePtr()[0] = 0.1;
    round_values(B, v32, "test");
    EXPECT_NE(static_cast<double>(v32[0]), 0.1);
    EXPECT_EQ(v32[0], 0.1f);
    B.valuePtr()[4] = 1e39;
    EXPECT_THROW(round_values(B, v32, "test"), InvalidInput);
}

TEST(Traffic, RoundingNamesTheFirstEntryWithoutAFloatValueWhateverChunkHoldsIt) {
    // round_values runs over the threads in chunks of parallel::kTouchRowsPerChunk entries: with
    // such entries in several chunks the message names the first one, as a serial loop would.
    const Index n = 5 * static_cast<Index>(parallel::kTouchRowsPerChunk);
    SparseMatrix D(n, n);
    D.setIdentity();
    D.makeCompressed();
    parallel::UninitializedVector<float> v32;
    round_values(D, v32, "test");
    ASSERT_EQ(v32.size(), static_cast<size_t>(n));
    EXPECT_EQ(v32[static_cast<size_t>(n) - 1], 1.0f);
    const Index late = 4 * static_cast<Index>(parallel::kTouchRowsPerChunk) + 3;
    const Index early = 2 * static_cast<Index>(parallel::kTouchRowsPerChunk) + 11;
    D.valuePtr()[late] = -1e300;
    D.valuePtr()[early] = 1e39;
    try {
        round_values(D, v32, "test");
        FAIL() << "no throw";
    } catch (const InvalidInput& e) {
        const std::string want =
            "entry (" + std::to_string(early) + ", " + std::to_string(early) + ") = 1e+39";
        EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
}

TEST(Traffic, MatrixOperatorCountsOneMatVecWhicheverKernel) {
    const SparseMatrix A = known_matrix();
    const Vector x = Vector::Ones(4);
    Vector y;
    for (const MatVec kind : {MatVec::in_order, MatVec::unrolled}) {
        const traffic::Account a0 = traffic::snapshot();
        MatrixOperator(A, kind).apply(x, y);
        const traffic::Account d = traffic::snapshot() - a0;
        EXPECT_EQ(d.b(traffic::Kind::matvec), 132.0);
        EXPECT_EQ(d.p(traffic::Kind::matvec), 1.0);
    }
}

TEST(Traffic, SecondsOnlyWhileTimingIsOn) {
    const Index n = 200000;
    SparseMatrix A(n, n);
    A.setIdentity();
    A.makeCompressed();
    const Vector x = Vector::Ones(n);
    Vector y;
    traffic::set_timing(false);
    traffic::Account a0 = traffic::snapshot();
    csr_multiply(A, x, y);
    EXPECT_EQ((traffic::snapshot() - a0).s(traffic::Kind::matvec), 0.0);
    traffic::set_timing(true);
    a0 = traffic::snapshot();
    csr_multiply(A, x, y);
    const traffic::Account d = traffic::snapshot() - a0;
    traffic::set_timing(false);
    EXPECT_GT(d.s(traffic::Kind::matvec), 0.0);
    EXPECT_LT(d.s(traffic::Kind::matvec), 10.0);
    EXPECT_EQ(d.b(traffic::Kind::matvec), 12.0 * n + 4.0 * (n + 1) + 16.0 * n);
}

TEST(Traffic, SweepClosedForms) {
    // n = 4 rows, 10 entries, 2 blocks of 2 (8 inverse entries).
    EXPECT_EQ(traffic::sweep_bytes(4, 10, 2, 8),
              12 * 10 + 4 * 5 + 8 * 8 + 8 * (2 * 2 + 1) + 8 * 4 + 8 * 4 + 16 * 4);
    EXPECT_EQ(traffic::sweep_from_zero_bytes(4, 10, 2, 8),
              12 * 10 + 8 * 5 + 8 * 8 + 8 * 5 + 16 * 4 + 8 * 4 + 16 * 4 + 24 * 4);
    EXPECT_EQ(traffic::vector_bytes(1000, 3), 24000.0);
    // Single precision: 4-byte values and inverse entries, everything else unchanged.
    EXPECT_EQ(traffic::sweep_bytes(4, 10, 2, 8, 4),
              8 * 10 + 4 * 5 + 4 * 8 + 8 * (2 * 2 + 1) + 8 * 4 + 8 * 4 + 16 * 4);
    EXPECT_EQ(traffic::sweep_from_zero_bytes(4, 10, 2, 8, 4),
              8 * 10 + 8 * 5 + 4 * 8 + 8 * 5 + 16 * 4 + 8 * 4 + 16 * 4 + 24 * 4);
}

TEST(Traffic, StreamIsPositiveAndFinite) {
    const traffic::Stream s = traffic::measure_stream(std::size_t(1) << 22, 2);
    EXPECT_TRUE(std::isfinite(s.copy_gbs));
    EXPECT_TRUE(std::isfinite(s.triad_gbs));
    EXPECT_GT(s.copy_gbs, 0.0);
    EXPECT_GT(s.triad_gbs, 0.0);
    EXPECT_EQ(s.n, std::size_t(1) << 22);
    EXPECT_EQ(s.threads, parallel::num_threads());
}

} // namespace
} // namespace mlc
