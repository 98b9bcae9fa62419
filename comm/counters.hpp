// SPDX-License-Identifier: MIT
/// @file What this process has sent through MPI, as counted by the PMPI library
/// comm/pmpi_counters.cpp (libmlc_pmpi_counters.so, loaded with LD_PRELOAD under mpirun; `mlcontact
/// bench comm`). Without it loaded (or without MPI) mpi_counts() says so, and nothing else changes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace mlc::comm {

/// Counts of one process (see comm/pmpi_counters.cpp for what each kind holds).
struct MpiCounts {
    std::int64_t p2p_messages = 0, p2p_bytes = 0;     ///< point-to-point sends
    std::int64_t reductions = 0, reduction_bytes = 0; ///< Allreduce, Reduce, Scan, Exscan
    std::int64_t gathers = 0, gather_bytes = 0;       ///< Allgather(v), Alltoall(v), Bcast, ...
    std::int64_t barriers = 0;

    MpiCounts operator-(const MpiCounts& o) const {
        return {p2p_messages - o.p2p_messages, p2p_bytes - o.p2p_bytes,
                reductions - o.reductions,     reduction_bytes - o.reduction_bytes,
                gathers - o.gathers,           gather_bytes - o.gather_bytes,
                barriers - o.barriers};
    }
};

/// The counts so far when libmlc_pmpi_counters.so is loaded, nullopt otherwise.
std::optional<MpiCounts> mpi_counts();

/// Where the library of this build lies (next to bin/: <build>/lib/libmlc_pmpi_counters.so, from
/// the running executable's path), for the message that says how to load it.
std::string pmpi_counters_library();

} // namespace mlc::comm
