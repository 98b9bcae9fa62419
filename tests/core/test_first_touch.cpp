// SPDX-License-Identifier: MIT
// core/first_touch: fills and copies over the threads give the serial loops' arrays on every
// chunk (sizes around and across the chunk size, one and two threads), and SparsityPattern, whose
// arrays they copy, keeps its value semantics.
#include "core/csr.hpp"
#include "core/first_touch.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

using namespace mlc;
namespace par = mlc::parallel;

namespace {

class FirstTouch : public ::testing::Test {
protected:
    void TearDown() override { par::set_num_threads(0); }
};

std::vector<size_t> sizes() {
    const size_t c = par::kTouchRowsPerChunk;
    return {0, 1, c - 1, c, c + 1, 5 * c + 7, 300 * c + 3}; // the last: more than 256 chunks
}

} // namespace

TEST_F(FirstTouch, FillCopyAndZerosWriteEveryElementOnce) {
    for (int threads : {1, 2}) {
        par::set_num_threads(threads);
        for (size_t n : sizes()) {
            std::vector<std::int64_t> src(n);
            std::iota(src.begin(), src.end(), std::int64_t{-3});
            // Guards one past the end catch a chunk that writes beyond its rows.
            std::vector<std::int64_t> dst(n + 1, 99);
            par::copy(src.data(), n, dst.data());
            EXPECT_TRUE(std::equal(src.begin(), src.end(), dst.begin())) << n << " " << threads;
            EXPECT_EQ(dst[n], 99);
            par::fill(dst.data(), n, std::int64_t{-7});
            EXPECT_EQ(std::count(dst.begin(), dst.begin() + static_cast<long>(n), -7),
                      static_cast<long>(n));
            EXPECT_EQ(dst[n], 99);

            const Vector z = par::zeros(static_cast<Index>(n));
            ASSERT_EQ(z.size(), static_cast<Index>(n));
            EXPECT_EQ(z, Vector::Zero(static_cast<Index>(n)));
            Vector v = Vector::Constant(3, 1.5);
            par::set_zero(v, static_cast<Index>(n));
            EXPECT_EQ(v, Vector::Zero(static_cast<Index>(n)));

            const auto a = par::uninitialized_array<double>(n);
            par::fill(a.get(), n, 2.5);
            for (size_t i = 0; i < n; i += 997)
                ASSERT_EQ(a[i], 2.5);
        }
    }
}

TEST_F(FirstTouch, SparsityPatternCopiesAndMovesKeepThePattern) {
    par::set_num_threads(2);
    // A banded matrix with more column indices than 3 chunks.
    const Index n = 40000;
    std::vector<Triplet> t;
    for (Index i = 0; i < n; ++i)
        for (Index j = std::max<Index>(0, i - 1); j <= std::min(n - 1, i + 1); ++j)
            t.emplace_back(static_cast<int>(i), static_cast<int>(j), 1.0 + static_cast<double>(j));
    SparseMatrix A(n, n);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    ASSERT_GT(static_cast<size_t>(A.nonZeros()), 3 * par::kTouchRowsPerChunk);
    SparseMatrix B = A; // one column index changed in the last row
    B.innerIndexPtr()[B.nonZeros() - 2] -= 1;

    const SparsityPattern p(A);
    EXPECT_TRUE(p.matches(A));
    EXPECT_FALSE(p.matches(B));
    const SparsityPattern copy(p);
    EXPECT_TRUE(copy.matches(A));
    EXPECT_FALSE(copy.matches(B));
    SparsityPattern assigned;
    EXPECT_TRUE(assigned.empty());
    assigned = p;
    EXPECT_FALSE(assigned.empty());
    EXPECT_TRUE(assigned.matches(A));
    SparsityPattern moved(std::move(assigned));
    EXPECT_TRUE(moved.matches(A));
    assigned = SparsityPattern(); // reassigned after the move: empty again
    EXPECT_TRUE(assigned.empty());
    EXPECT_FALSE(assigned.matches(A));
    const SparsityPattern empty_copy(assigned);
    EXPECT_TRUE(empty_copy.empty());
}
