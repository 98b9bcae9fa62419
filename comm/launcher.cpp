// SPDX-License-Identifier: MIT
// Whether an MPI launcher started this process (both builds).
#include "comm/world.hpp"

#include <cstdlib>

namespace mlc::comm {

bool launched_by_mpirun() {
    return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") ||
           std::getenv("PMIX_RANK");
}

int processes_on_this_machine() {
    for (const char* name : {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS", "MPI_LOCAL_NRANKS"})
        if (const char* v = std::getenv(name)) {
            const int n = std::atoi(v);
            if (n >= 1) return n;
        }
    return launched_by_mpirun() ? world().size() : 1;
}

} // namespace mlc::comm
