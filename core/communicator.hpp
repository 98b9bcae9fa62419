// SPDX-License-Identifier: MIT
/// @file The communicator that mesh, contact and levels code sees: the processes of a run, their
/// reductions, gathers, broadcasts and personalised exchanges, without MPI.
///
/// This interface is all the distributed code above core/ uses; the MPI implementation lives in
/// comm/ (the only folder besides solvers/hypre/ that includes mpi.h) and comm::world() picks it
/// under mpirun. SerialCommunicator below is the one-process implementation: every operation is
/// the identity on one process, with the same argument checks, so code written against the
/// interface runs unchanged without MPI.
///
/// All operations are collective: every process of the communicator must call them in the same
/// order with compatible arguments (the same length for allreduce and broadcast, the same root),
/// as with MPI. Results are deterministic: sums are formed by the engine in rank order for a
/// given process count (MPI's reductions on one communicator are reproducible run to run; they
/// are not bit-identical across process counts, which the callers' tolerances allow for).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace mlc {

/// Elementwise reduction over the processes.
enum class ReduceOp { sum, max, min };

/// The processes of a run. Not thread-safe: call from one thread of each process (the thread
/// pool of core/parallel.hpp never communicates).
class Communicator {
public:
    virtual ~Communicator() = default;

    /// This process's number, in [0, size()).
    virtual int rank() const = 0;
    /// Number of processes (>= 1).
    virtual int size() const = 0;
    /// Returns when every process has called it.
    virtual void barrier() const = 0;

    /// In place: v[i] <- op over the processes of v[i]. Every process passes the same length.
    virtual void allreduce(std::span<double> v, ReduceOp op) const = 0;
    virtual void allreduce(std::span<int> v, ReduceOp op) const = 0;
    virtual void allreduce(std::span<std::int64_t> v, ReduceOp op) const = 0;

    /// The concatenation, in rank order, of every process's v (lengths may differ) on `root`;
    /// an empty vector on the other processes. Throws InvalidInput for a root outside [0, size).
    virtual std::vector<double> gather(std::span<const double> v, int root) const = 0;
    virtual std::vector<int> gather(std::span<const int> v, int root) const = 0;
    virtual std::vector<std::int64_t> gather(std::span<const std::int64_t> v, int root) const = 0;

    /// The concatenation, in rank order, of every process's v (lengths may differ), on every
    /// process.
    virtual std::vector<double> allgather(std::span<const double> v) const = 0;
    virtual std::vector<std::int64_t> allgather(std::span<const std::int64_t> v) const = 0;

    /// In place: v <- root's v on every process. Every process passes the same length.
    virtual void broadcast(std::span<double> v, int root) const = 0;
    virtual void broadcast(std::span<int> v, int root) const = 0;
    virtual void broadcast(std::span<std::int64_t> v, int root) const = 0;

    /// Personalised exchange: send[k] goes to process k (send.size() == size()); returns recv with
    /// recv[k] = what process k sent to this one (send[rank()] comes back as recv[rank()]).
    virtual std::vector<std::vector<std::int64_t>>
    exchange(const std::vector<std::vector<std::int64_t>>& send) const = 0;
    virtual std::vector<std::vector<double>>
    exchange(const std::vector<std::vector<double>>& send) const = 0;

    /// Scalar forms of allreduce: op over the processes of x.
    double sum(double x) const { return reduce_one(x, ReduceOp::sum); }
    double max(double x) const { return reduce_one(x, ReduceOp::max); }
    double min(double x) const { return reduce_one(x, ReduceOp::min); }
    int sum(int x) const { return reduce_one(x, ReduceOp::sum); }
    int max(int x) const { return reduce_one(x, ReduceOp::max); }
    int min(int x) const { return reduce_one(x, ReduceOp::min); }
    std::int64_t sum(std::int64_t x) const { return reduce_one(x, ReduceOp::sum); }
    std::int64_t max(std::int64_t x) const { return reduce_one(x, ReduceOp::max); }
    std::int64_t min(std::int64_t x) const { return reduce_one(x, ReduceOp::min); }

    /// Sum of x over the processes of lower rank (0 on rank 0): the first global index of this
    /// process's block when every process owns x consecutive indices in rank order (hypre's
    /// contiguous row partition).
    std::int64_t exclusive_sum(std::int64_t x) const;

private:
    template <class T> T reduce_one(T x, ReduceOp op) const {
        allreduce(std::span<T>(&x, 1), op);
        return x;
    }
};

/// One process: rank 0 of size 1; reductions, gathers and broadcasts return the input, exchange
/// returns send. Used when MPI is not built or the program was not started by mpirun.
class SerialCommunicator final : public Communicator {
public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    void barrier() const override {}
    void allreduce(std::span<double> v, ReduceOp op) const override;
    void allreduce(std::span<int> v, ReduceOp op) const override;
    void allreduce(std::span<std::int64_t> v, ReduceOp op) const override;
    std::vector<double> gather(std::span<const double> v, int root) const override;
    std::vector<int> gather(std::span<const int> v, int root) const override;
    std::vector<std::int64_t> gather(std::span<const std::int64_t> v, int root) const override;
    std::vector<double> allgather(std::span<const double> v) const override;
    std::vector<std::int64_t> allgather(std::span<const std::int64_t> v) const override;
    void broadcast(std::span<double> v, int root) const override;
    void broadcast(std::span<int> v, int root) const override;
    void broadcast(std::span<std::int64_t> v, int root) const override;
    std::vector<std::vector<std::int64_t>>
    exchange(const std::vector<std::vector<std::int64_t>>& send) const override;
    std::vector<std::vector<double>>
    exchange(const std::vector<std::vector<double>>& send) const override;
};

} // namespace mlc
