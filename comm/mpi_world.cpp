// SPDX-License-Identifier: MIT
// comm::world() with MPI: MPI_COMM_WORLD behind the Communicator interface.
#include "comm/world.hpp"

#include "core/check.hpp"

#include <mpi.h>

#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>

namespace mlc::comm {

bool have_mpi() {
    return true;
}

namespace {

void check(int code, const char* call) {
    if (code == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(code, text, &len);
    throw std::runtime_error(std::string(call) + " failed: " + std::string(text, len));
}

template <class T> MPI_Datatype datatype();
template <> MPI_Datatype datatype<double>() {
    return MPI_DOUBLE;
}
template <> MPI_Datatype datatype<int>() {
    return MPI_INT;
}
template <> MPI_Datatype datatype<std::int64_t>() {
    return MPI_INT64_T;
}

MPI_Op mpi_op(ReduceOp op) {
    switch (op) {
    case ReduceOp::sum:
        return MPI_SUM;
    case ReduceOp::max:
        return MPI_MAX;
    case ReduceOp::min:
        return MPI_MIN;
    }
    return MPI_SUM;
}

int count_of(size_t n, const char* what) {
    MLC_CHECK(n <= static_cast<size_t>(INT32_MAX),
              "Communicator::" << what << ": " << n << " entries exceed MPI's int count");
    return static_cast<int>(n);
}

/// Displacements of consecutive blocks of the given counts; returns the total.
size_t displacements(const std::vector<int>& counts, std::vector<int>& displs) {
    displs.assign(counts.size(), 0);
    size_t total = 0;
    for (size_t k = 0; k < counts.size(); ++k) {
        displs[k] = count_of(total, "displacement");
        total += static_cast<size_t>(counts[k]);
    }
    count_of(total, "total");
    return total;
}

void finalize_mpi() {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

class MpiCommunicator final : public Communicator {
public:
    MpiCommunicator() {
        check(MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
        check(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
        check(MPI_Comm_size(comm_, &size_), "MPI_Comm_size");
    }
    int rank() const override { return rank_; }
    int size() const override { return size_; }
    void barrier() const override { check(MPI_Barrier(comm_), "MPI_Barrier"); }

    void allreduce(std::span<double> v, ReduceOp op) const override { allreduce_t(v, op); }
    void allreduce(std::span<int> v, ReduceOp op) const override { allreduce_t(v, op); }
    void allreduce(std::span<std::int64_t> v, ReduceOp op) const override { allreduce_t(v, op); }

    std::vector<double> gather(std::span<const double> v, int root) const override {
        return gather_t(v, root);
    }
    std::vector<int> gather(std::span<const int> v, int root) const override {
        return gather_t(v, root);
    }
    std::vector<std::int64_t> gather(std::span<const std::int64_t> v, int root) const override {
        return gather_t(v, root);
    }
    std::vector<double> allgather(std::span<const double> v) const override {
        return allgather_t(v);
    }
    std::vector<std::int64_t> allgather(std::span<const std::int64_t> v) const override {
        return allgather_t(v);
    }

    void broadcast(std::span<double> v, int root) const override { broadcast_t(v, root); }
    void broadcast(std::span<int> v, int root) const override { broadcast_t(v, root); }
    void broadcast(std::span<std::int64_t> v, int root) const override { broadcast_t(v, root); }

    std::vector<std::vector<std::int64_t>>
    exchange(const std::vector<std::vector<std::int64_t>>& send) const override {
        return exchange_t(send);
    }
    std::vector<std::vector<double>>
    exchange(const std::vector<std::vector<double>>& send) const override {
        return exchange_t(send);
    }

private:
    void check_root(int root) const {
        MLC_CHECK(root >= 0 && root < size_,
                  "Communicator: root " << root << " outside [0, " << size_ << ")");
    }

    template <class T> void allreduce_t(std::span<T> v, ReduceOp op) const {
        check(MPI_Allreduce(MPI_IN_PLACE, v.data(), count_of(v.size(), "allreduce"), datatype<T>(),
                            mpi_op(op), comm_),
              "MPI_Allreduce");
    }

    template <class T> std::vector<T> gather_t(std::span<const T> v, int root) const {
        check_root(root);
        const int n = count_of(v.size(), "gather");
        std::vector<int> counts(rank_ == root ? static_cast<size_t>(size_) : 0);
        check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm_), "MPI_Gather");
        std::vector<int> displs;
        std::vector<T> out;
        if (rank_ == root) out.resize(displacements(counts, displs));
        check(MPI_Gatherv(v.data(), n, datatype<T>(), out.data(), counts.data(), displs.data(),
                          datatype<T>(), root, comm_),
              "MPI_Gatherv");
        return out;
    }

    template <class T> std::vector<T> allgather_t(std::span<const T> v) const {
        const int n = count_of(v.size(), "allgather");
        std::vector<int> counts(static_cast<size_t>(size_));
        check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_), "MPI_Allgather");
        std::vector<int> displs;
        std::vector<T> out(displacements(counts, displs));
        check(MPI_Allgatherv(v.data(), n, datatype<T>(), out.data(), counts.data(), displs.data(),
                             datatype<T>(), comm_),
              "MPI_Allgatherv");
        return out;
    }

    template <class T> void broadcast_t(std::span<T> v, int root) const {
        check_root(root);
        check(MPI_Bcast(v.data(), count_of(v.size(), "broadcast"), datatype<T>(), root, comm_),
              "MPI_Bcast");
    }

    template <class T>
    std::vector<std::vector<T>> exchange_t(const std::vector<std::vector<T>>& send) const {
        MLC_CHECK(send.size() == static_cast<size_t>(size_),
                  "Communicator::exchange: " << send.size() << " send buffers for " << size_
                                             << " processes");
        std::vector<int> scounts(send.size()), rcounts(send.size());
        for (size_t k = 0; k < send.size(); ++k)
            scounts[k] = count_of(send[k].size(), "exchange");
        check(MPI_Alltoall(scounts.data(), 1, MPI_INT, rcounts.data(), 1, MPI_INT, comm_),
              "MPI_Alltoall");
        std::vector<int> sdispls, rdispls;
        std::vector<T> sbuf(displacements(scounts, sdispls));
        std::vector<T> rbuf(displacements(rcounts, rdispls));
        for (size_t k = 0; k < send.size(); ++k)
            std::copy(send[k].begin(), send[k].end(),
                      sbuf.begin() + static_cast<std::ptrdiff_t>(sdispls[k]));
        check(MPI_Alltoallv(sbuf.data(), scounts.data(), sdispls.data(), datatype<T>(), rbuf.data(),
                            rcounts.data(), rdispls.data(), datatype<T>(), comm_),
              "MPI_Alltoallv");
        std::vector<std::vector<T>> recv(send.size());
        for (size_t k = 0; k < recv.size(); ++k) {
            const auto b = rbuf.begin() + static_cast<std::ptrdiff_t>(rdispls[k]);
            recv[k].assign(b, b + rcounts[k]);
        }
        return recv;
    }

public:
    MPI_Comm comm() const { return comm_; }

private:
    MPI_Comm comm_ = MPI_COMM_WORLD;
    int rank_ = 0;
    int size_ = 1;
};

std::unique_ptr<Communicator> make_world() {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
        if (!launched_by_mpirun()) return std::make_unique<SerialCommunicator>();
        int provided = 0;
        int argc = 0;
        char** argv = nullptr;
        check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
        // Registered before hypre's finalisation (hypre initialises later and finds MPI ready),
        // so it runs after it, and finds MPI finalised if hypre did it.
        std::atexit(finalize_mpi);
    }
    return std::make_unique<MpiCommunicator>();
}

} // namespace

int mpi_handle(const Communicator& c) {
    if (const auto* m = dynamic_cast<const MpiCommunicator*>(&c)) return MPI_Comm_c2f(m->comm());
    MLC_CHECK(dynamic_cast<const SerialCommunicator*>(&c) != nullptr,
              "comm::mpi_handle: not a communicator of comm::world() or a SerialCommunicator");
    return MPI_Comm_c2f(MPI_COMM_SELF);
}

void abort_all(int code) {
    int up = 0, down = 0;
    MPI_Initialized(&up);
    MPI_Finalized(&down);
    if (up && !down) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

const Communicator& world() {
    static const std::unique_ptr<Communicator> w = make_world();
    return *w;
}

} // namespace mlc::comm
