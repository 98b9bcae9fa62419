// SPDX-License-Identifier: MIT
// comm::world() against closed forms, for any number of processes: ctest runs this executable
// alone (one process, the serial communicator) and under mpirun -np 2 and -np 3 (label mpi).
// Rank r contributes values built from r, so every result has a closed form in (r, size).
#include "comm/world.hpp"
#include "core/check.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <numeric>

using mlc::ReduceOp;

namespace {

const mlc::Communicator& W() {
    return mlc::comm::world();
}

} // namespace

TEST(World, SizeMatchesTheLauncher) {
    const char* n = std::getenv("OMPI_COMM_WORLD_SIZE");
    const int expected = n ? std::atoi(n) : 1;
    if (!mlc::comm::have_mpi()) {
        EXPECT_EQ(W().size(), 1);
        return;
    }
    EXPECT_EQ(W().size(), expected);
    EXPECT_GE(W().rank(), 0);
    EXPECT_LT(W().rank(), W().size());
    EXPECT_EQ(mlc::comm::launched_by_mpirun(), n != nullptr);
    // Every rank appears once: sum of ranks and sum of squares.
    const int p = W().size(), r = W().rank();
    EXPECT_EQ(W().sum(r), p * (p - 1) / 2);
    EXPECT_EQ(W().sum(r * r), (p - 1) * p * (2 * p - 1) / 6);
}

TEST(World, ScalarReductions) {
    const int p = W().size(), r = W().rank();
    EXPECT_DOUBLE_EQ(W().sum(0.5 + r), 0.5 * p + p * (p - 1) / 2.0);
    EXPECT_DOUBLE_EQ(W().max(-1.0 * r), 0.0);
    EXPECT_DOUBLE_EQ(W().min(-1.0 * r), -(p - 1.0));
    EXPECT_EQ(W().max(r + 7), p + 6);
    EXPECT_EQ(W().min(r + 7), 7);
    const std::int64_t big = std::int64_t{1} << 40;
    EXPECT_EQ(W().sum(big + r), p * big + p * (p - 1) / 2);
    EXPECT_EQ(W().max(big * (r + 1)), big * p);
    EXPECT_EQ(W().min(big * (r + 1)), big);
}

TEST(World, VectorReductionsAreElementwise) {
    const int p = W().size(), r = W().rank();
    std::vector<double> s(5), mx(5), mn(5);
    std::vector<int> si(5);
    for (int i = 0; i < 5; ++i) {
        s[i] = r + 0.25 * i; // sum: p(p-1)/2 + p i / 4
        mx[i] = (r - 1) * i; // max over r of (r-1) i: (p-2) i for i >= 0
        mn[i] = (r - 1) * i; // min: -i
        si[i] = r * 10 + i;  // sum: 10 p(p-1)/2 + p i
    }
    W().allreduce(std::span<double>(s), ReduceOp::sum);
    W().allreduce(std::span<double>(mx), ReduceOp::max);
    W().allreduce(std::span<double>(mn), ReduceOp::min);
    W().allreduce(std::span<int>(si), ReduceOp::sum);
    for (int i = 0; i < 5; ++i) {
        EXPECT_DOUBLE_EQ(s[i], p * (p - 1) / 2.0 + p * 0.25 * i) << i;
        EXPECT_DOUBLE_EQ(mx[i], (p - 2.0) * i) << i;
        EXPECT_DOUBLE_EQ(mn[i], -1.0 * i) << i;
        EXPECT_EQ(si[i], 10 * p * (p - 1) / 2 + p * i) << i;
    }
    std::vector<std::int64_t> l = {r, -r};
    W().allreduce(std::span<std::int64_t>(l), ReduceOp::max);
    EXPECT_EQ(l[0], p - 1);
    EXPECT_EQ(l[1], 0);
}

// Rank r sends r + 1 values 100 r + j (j < r + 1): the root holds the blocks in rank order.
TEST(World, GatherConcatenatesInRankOrder) {
    const int p = W().size(), r = W().rank();
    for (int root = 0; root < p; ++root) {
        std::vector<double> d(static_cast<size_t>(r + 1));
        std::vector<int> n(d.size());
        std::vector<std::int64_t> l(d.size());
        for (int j = 0; j <= r; ++j) {
            d[j] = 100.0 * r + j + 0.5;
            n[j] = 100 * r + j;
            l[j] = 100 * r + j;
        }
        const auto gd = W().gather(std::span<const double>(d), root);
        const auto gn = W().gather(std::span<const int>(n), root);
        const auto gl = W().gather(std::span<const std::int64_t>(l), root);
        if (r != root) {
            EXPECT_TRUE(gd.empty() && gn.empty() && gl.empty());
            continue;
        }
        ASSERT_EQ(gd.size(), static_cast<size_t>(p * (p + 1) / 2));
        ASSERT_EQ(gn.size(), gd.size());
        ASSERT_EQ(gl.size(), gd.size());
        size_t k = 0;
        for (int q = 0; q < p; ++q)
            for (int j = 0; j <= q; ++j, ++k) {
                EXPECT_DOUBLE_EQ(gd[k], 100.0 * q + j + 0.5);
                EXPECT_EQ(gn[k], 100 * q + j);
                EXPECT_EQ(gl[k], 100 * q + j);
            }
    }
}

TEST(World, AllgatherAndExclusiveSum) {
    const int p = W().size(), r = W().rank();
    std::vector<std::int64_t> l(static_cast<size_t>(r), r); // rank r: r copies of r
    const auto all = W().allgather(std::span<const std::int64_t>(l));
    ASSERT_EQ(all.size(), static_cast<size_t>(p * (p - 1) / 2));
    size_t k = 0;
    for (int q = 0; q < p; ++q)
        for (int j = 0; j < q; ++j)
            EXPECT_EQ(all[k++], q);
    const std::vector<double> d = {r + 0.5};
    const auto alld = W().allgather(std::span<const double>(d));
    ASSERT_EQ(alld.size(), static_cast<size_t>(p));
    for (int q = 0; q < p; ++q)
        EXPECT_DOUBLE_EQ(alld[q], q + 0.5);
    // Blocks of r + 1 indices: rank r starts at 1 + 2 + ... + r.
    EXPECT_EQ(W().exclusive_sum(r + 1), std::int64_t{r} * (r + 1) / 2);
}

TEST(World, BroadcastFromEveryRoot) {
    const int p = W().size(), r = W().rank();
    for (int root = 0; root < p; ++root) {
        std::vector<double> d = {1.0 * r, 2.0 * r};
        std::vector<int> n = {r, -r, r};
        std::vector<std::int64_t> l = {std::int64_t{r} << 33};
        W().broadcast(std::span<double>(d), root);
        W().broadcast(std::span<int>(n), root);
        W().broadcast(std::span<std::int64_t>(l), root);
        EXPECT_DOUBLE_EQ(d[0], root);
        EXPECT_DOUBLE_EQ(d[1], 2.0 * root);
        EXPECT_EQ(n, (std::vector<int>{root, -root, root}));
        EXPECT_EQ(l[0], std::int64_t{root} << 33);
    }
}

// Rank r sends to rank k the r + k values 1000 r + k: rank r receives from k the k + r values
// 1000 k + r.
TEST(World, ExchangeDeliversEachBufferToItsProcess) {
    const int p = W().size(), r = W().rank();
    std::vector<std::vector<std::int64_t>> send(static_cast<size_t>(p));
    std::vector<std::vector<double>> sendd(static_cast<size_t>(p));
    for (int k = 0; k < p; ++k) {
        send[k].assign(static_cast<size_t>(r + k), 1000 * r + k);
        sendd[k].assign(static_cast<size_t>(r + k), 0.5 + 1000 * r + k);
    }
    const auto recv = W().exchange(send);
    const auto recvd = W().exchange(sendd);
    ASSERT_EQ(recv.size(), static_cast<size_t>(p));
    ASSERT_EQ(recvd.size(), static_cast<size_t>(p));
    for (int k = 0; k < p; ++k) {
        EXPECT_EQ(recv[k], std::vector<std::int64_t>(static_cast<size_t>(k + r), 1000 * k + r));
        EXPECT_EQ(recvd[k], std::vector<double>(static_cast<size_t>(k + r), 0.5 + 1000 * k + r));
    }
    W().barrier();
}

TEST(World, BadArgumentsThrowOnEveryProcess) {
    const int p = W().size();
    std::vector<double> d = {1.0};
    EXPECT_THROW(W().broadcast(std::span<double>(d), p), mlc::InvalidInput);
    EXPECT_THROW((void)W().gather(std::span<const double>(d), -1), mlc::InvalidInput);
    EXPECT_THROW((void)W().exchange(std::vector<std::vector<double>>(static_cast<size_t>(p + 1))),
                 mlc::InvalidInput);
}
