// SPDX-License-Identifier: MIT
// Whether an MPI launcher started this process (both builds).
#include "comm/world.hpp"

#include <cstdlib>

namespace mlc::comm {

bool launched_by_mpirun() {
    return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") ||
           std::getenv("PMIX_RANK");
}

} // namespace mlc::comm
