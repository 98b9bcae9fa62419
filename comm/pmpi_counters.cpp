// SPDX-License-Identifier: MIT
/// @file A PMPI profiling library (`mlcontact bench comm`): loaded with LD_PRELOAD under mpirun, it
/// counts what this process sends through MPI, whoever calls it (our comm layer or hypre), and
/// passes every call on to the MPI library by its PMPI_ name. comm::mpi_counters()
/// (comm/counters.hpp) reads the counts through mlc_pmpi_counters when this library is loaded.
///
/// Three kinds, as the scaling model of docs/parallel.md#cluster-model counts them:
///   point-to-point: messages sent (Send, Isend, Irsend, Rsend, Ssend, Issend, and each started
///     persistent send) and their bytes;
///   reductions: Allreduce, Reduce, Scan, Exscan calls and their bytes (the reduced vector);
///   gathers: Allgather(v), Gather(v), Alltoall(v), Bcast, Scatter(v) calls and the bytes this
///     process receives (for Bcast and Scatter(v) the bytes it receives or, at the root, sends);
/// plus Barrier calls. Not thread-safe (mlcontact communicates from its main thread only,
/// MPI_THREAD_FUNNELED).
#include <mpi.h>

#include <cstdint>
#include <unordered_map>

namespace {

enum Counter : int {
    p2p_messages,
    p2p_bytes,
    reductions,
    reduction_bytes,
    gathers,
    gather_bytes,
    barriers,
    n_counters
};

std::int64_t counts[n_counters] = {};
/// Persistent send requests (MPI_Send_init) and their bytes, counted when started.
std::unordered_map<MPI_Request, std::int64_t>& persistent() {
    static std::unordered_map<MPI_Request, std::int64_t> map;
    return map;
}

std::int64_t bytes(int count, MPI_Datatype type) {
    int size = 0;
    PMPI_Type_size(type, &size);
    return static_cast<std::int64_t>(count) * size;
}

void send(int count, MPI_Datatype type) {
    ++counts[p2p_messages];
    counts[p2p_bytes] += bytes(count, type);
}

/// A started persistent request: a message when it is a send (MPI_Send_init).
void count_started(MPI_Request req) {
    const auto it = persistent().find(req);
    if (it == persistent().end()) return;
    ++counts[p2p_messages];
    counts[p2p_bytes] += it->second;
}

void reduce(int count, MPI_Datatype type) {
    ++counts[reductions];
    counts[reduction_bytes] += bytes(count, type);
}

void gather(std::int64_t received) {
    ++counts[gathers];
    counts[gather_bytes] += received;
}

int size_of(MPI_Comm comm) {
    int n = 1;
    PMPI_Comm_size(comm, &n);
    return n;
}

int rank_of(MPI_Comm comm) {
    int r = 0;
    PMPI_Comm_rank(comm, &r);
    return r;
}

std::int64_t sum_counts(const int* counts_, int n, MPI_Datatype type) {
    std::int64_t s = 0;
    for (int q = 0; q < n; ++q)
        s += counts_[q];
    return bytes(1, type) * s;
}

} // namespace

extern "C" {

/// The counts so far, in the order p2p_messages, p2p_bytes, reductions, reduction_bytes, gathers,
/// gather_bytes, barriers (at most n of them are written). Returns how many exist.
__attribute__((visibility("default"))) int mlc_pmpi_counters(std::int64_t* out, int n) {
    for (int k = 0; k < n && k < n_counters; ++k)
        out[k] = counts[k];
    return n_counters;
}

int MPI_Send(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
    send(count, type);
    return PMPI_Send(buf, count, type, dest, tag, comm);
}
int MPI_Rsend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
    send(count, type);
    return PMPI_Rsend(buf, count, type, dest, tag, comm);
}
int MPI_Ssend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
    send(count, type);
    return PMPI_Ssend(buf, count, type, dest, tag, comm);
}
int MPI_Isend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm,
              MPI_Request* req) {
    send(count, type);
    return PMPI_Isend(buf, count, type, dest, tag, comm, req);
}
int MPI_Irsend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm,
               MPI_Request* req) {
    send(count, type);
    return PMPI_Irsend(buf, count, type, dest, tag, comm, req);
}
int MPI_Issend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm,
               MPI_Request* req) {
    send(count, type);
    return PMPI_Issend(buf, count, type, dest, tag, comm, req);
}
int MPI_Send_init(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm,
                  MPI_Request* req) {
    const int rc = PMPI_Send_init(buf, count, type, dest, tag, comm, req);
    if (rc == MPI_SUCCESS) persistent()[*req] = bytes(count, type);
    return rc;
}
int MPI_Start(MPI_Request* req) {
    count_started(*req);
    return PMPI_Start(req);
}
int MPI_Startall(int n, MPI_Request reqs[]) {
    for (int k = 0; k < n; ++k)
        count_started(reqs[k]);
    return PMPI_Startall(n, reqs);
}
int MPI_Request_free(MPI_Request* req) {
    persistent().erase(*req);
    return PMPI_Request_free(req);
}

int MPI_Allreduce(const void* s, void* r, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
    reduce(count, type);
    return PMPI_Allreduce(s, r, count, type, op, comm);
}
int MPI_Reduce(const void* s, void* r, int count, MPI_Datatype type, MPI_Op op, int root,
               MPI_Comm comm) {
    reduce(count, type);
    return PMPI_Reduce(s, r, count, type, op, root, comm);
}
int MPI_Scan(const void* s, void* r, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
    reduce(count, type);
    return PMPI_Scan(s, r, count, type, op, comm);
}
int MPI_Exscan(const void* s, void* r, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
    reduce(count, type);
    return PMPI_Exscan(s, r, count, type, op, comm);
}

int MPI_Allgather(const void* s, int sc, MPI_Datatype st, void* r, int rc, MPI_Datatype rt,
                  MPI_Comm comm) {
    gather(bytes(rc, rt) * size_of(comm));
    return PMPI_Allgather(s, sc, st, r, rc, rt, comm);
}
int MPI_Allgatherv(const void* s, int sc, MPI_Datatype st, void* r, const int rc[],
                   const int displs[], MPI_Datatype rt, MPI_Comm comm) {
    gather(sum_counts(rc, size_of(comm), rt));
    return PMPI_Allgatherv(s, sc, st, r, rc, displs, rt, comm);
}
int MPI_Gather(const void* s, int sc, MPI_Datatype st, void* r, int rc, MPI_Datatype rt, int root,
               MPI_Comm comm) {
    gather(rank_of(comm) == root ? bytes(rc, rt) * size_of(comm) : 0);
    return PMPI_Gather(s, sc, st, r, rc, rt, root, comm);
}
int MPI_Gatherv(const void* s, int sc, MPI_Datatype st, void* r, const int rc[], const int displs[],
                MPI_Datatype rt, int root, MPI_Comm comm) {
    gather(rank_of(comm) == root ? sum_counts(rc, size_of(comm), rt) : 0);
    return PMPI_Gatherv(s, sc, st, r, rc, displs, rt, root, comm);
}
int MPI_Alltoall(const void* s, int sc, MPI_Datatype st, void* r, int rc, MPI_Datatype rt,
                 MPI_Comm comm) {
    gather(bytes(rc, rt) * size_of(comm));
    return PMPI_Alltoall(s, sc, st, r, rc, rt, comm);
}
int MPI_Alltoallv(const void* s, const int sc[], const int sd[], MPI_Datatype st, void* r,
                  const int rc[], const int rd[], MPI_Datatype rt, MPI_Comm comm) {
    gather(sum_counts(rc, size_of(comm), rt));
    return PMPI_Alltoallv(s, sc, sd, st, r, rc, rd, rt, comm);
}
int MPI_Bcast(void* buf, int count, MPI_Datatype type, int root, MPI_Comm comm) {
    gather(bytes(count, type));
    return PMPI_Bcast(buf, count, type, root, comm);
}
int MPI_Scatter(const void* s, int sc, MPI_Datatype st, void* r, int rc, MPI_Datatype rt, int root,
                MPI_Comm comm) {
    gather(bytes(rc, rt));
    return PMPI_Scatter(s, sc, st, r, rc, rt, root, comm);
}
int MPI_Scatterv(const void* s, const int sc[], const int displs[], MPI_Datatype st, void* r,
                 int rc, MPI_Datatype rt, int root, MPI_Comm comm) {
    gather(bytes(rc, rt));
    return PMPI_Scatterv(s, sc, displs, st, r, rc, rt, root, comm);
}
int MPI_Barrier(MPI_Comm comm) {
    ++counts[barriers];
    return PMPI_Barrier(comm);
}

} // extern "C"
