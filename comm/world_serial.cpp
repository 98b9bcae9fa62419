// SPDX-License-Identifier: MIT
// comm::world() in a build without MPI: always one process.
#include "comm/world.hpp"

#include "core/check.hpp"

#include <cstdlib>

namespace mlc::comm {

bool have_mpi() {
    return false;
}

int mpi_handle(const Communicator&) {
    MLC_CHECK(false, "comm::mpi_handle: this build has no MPI (configure with MLC_WITH_HYPRE=ON)");
    return 0;
}

int processes_on_this_machine() {
    for (const char* name : {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS", "MPI_LOCAL_NRANKS"})
        if (const char* v = std::getenv(name)) {
            const int n = std::atoi(v);
            if (n >= 1) return n;
        }
    return launched_by_mpirun() ? world().size() : 1;
}

void abort_all(int code) {
    std::exit(code);
}

const Communicator& world() {
    static const SerialCommunicator serial;
    return serial;
}

} // namespace mlc::comm
