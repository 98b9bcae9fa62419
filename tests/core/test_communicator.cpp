// SPDX-License-Identifier: MIT
// The one-process communicator: identities with the same argument checks as MPI's.
#include "core/check.hpp"
#include "core/communicator.hpp"

#include <gtest/gtest.h>

TEST(SerialCommunicator, IsRankZeroOfOne) {
    const mlc::SerialCommunicator c;
    EXPECT_EQ(c.rank(), 0);
    EXPECT_EQ(c.size(), 1);
    EXPECT_DOUBLE_EQ(c.sum(2.5), 2.5);
    EXPECT_EQ(c.max(-3), -3);
    EXPECT_EQ(c.min(std::int64_t{1} << 40), std::int64_t{1} << 40);
    EXPECT_EQ(c.exclusive_sum(17), 0);
    std::vector<double> v = {1, 2, 3};
    c.allreduce(std::span<double>(v), mlc::ReduceOp::sum);
    EXPECT_EQ(v, (std::vector<double>{1, 2, 3}));
    EXPECT_EQ(c.gather(std::span<const double>(v), 0), v);
    EXPECT_EQ(c.allgather(std::span<const double>(v)), v);
    const std::vector<std::vector<std::int64_t>> send = {{4, 5}};
    EXPECT_EQ(c.exchange(send), send);
}

TEST(SerialCommunicator, RejectsRootsAndBuffersForOtherProcesses) {
    const mlc::SerialCommunicator c;
    std::vector<int> v = {1};
    EXPECT_THROW(c.broadcast(std::span<int>(v), 1), mlc::InvalidInput);
    EXPECT_THROW((void)c.gather(std::span<const int>(v), -1), mlc::InvalidInput);
    EXPECT_THROW((void)c.exchange(std::vector<std::vector<double>>(2)), mlc::InvalidInput);
}
