// SPDX-License-Identifier: MIT
// The one-process communicator and the convenience operations common to all communicators.
#include "core/communicator.hpp"

#include "core/check.hpp"

namespace mlc {

std::int64_t Communicator::exclusive_sum(std::int64_t x) const {
    const std::vector<std::int64_t> all = allgather(std::span<const std::int64_t>(&x, 1));
    std::int64_t s = 0;
    for (int k = 0; k < rank(); ++k)
        s += all[static_cast<size_t>(k)];
    return s;
}

namespace {

void check_root(int root) {
    MLC_CHECK(root == 0, "Communicator: root " << root << " outside [0, 1) (one process)");
}

template <class T> std::vector<T> copy(std::span<const T> v) {
    return {v.begin(), v.end()};
}

template <class T>
std::vector<std::vector<T>> exchange_self(const std::vector<std::vector<T>>& send) {
    MLC_CHECK(send.size() == 1,
              "Communicator::exchange: " << send.size() << " send buffers for 1 process");
    return send;
}

} // namespace

void SerialCommunicator::allreduce(std::span<double>, ReduceOp) const {}
void SerialCommunicator::allreduce(std::span<int>, ReduceOp) const {}
void SerialCommunicator::allreduce(std::span<std::int64_t>, ReduceOp) const {}

std::vector<double> SerialCommunicator::gather(std::span<const double> v, int root) const {
    check_root(root);
    return copy(v);
}
std::vector<int> SerialCommunicator::gather(std::span<const int> v, int root) const {
    check_root(root);
    return copy(v);
}
std::vector<std::int64_t> SerialCommunicator::gather(std::span<const std::int64_t> v,
                                                     int root) const {
    check_root(root);
    return copy(v);
}
std::vector<double> SerialCommunicator::allgather(std::span<const double> v) const {
    return copy(v);
}
std::vector<std::int64_t> SerialCommunicator::allgather(std::span<const std::int64_t> v) const {
    return copy(v);
}
void SerialCommunicator::broadcast(std::span<double>, int root) const {
    check_root(root);
}
void SerialCommunicator::broadcast(std::span<int>, int root) const {
    check_root(root);
}
void SerialCommunicator::broadcast(std::span<std::int64_t>, int root) const {
    check_root(root);
}

std::vector<std::vector<std::int64_t>>
SerialCommunicator::exchange(const std::vector<std::vector<std::int64_t>>& send) const {
    return exchange_self(send);
}
std::vector<std::vector<double>>
SerialCommunicator::exchange(const std::vector<std::vector<double>>& send) const {
    return exchange_self(send);
}

} // namespace mlc
