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

void abort_all(int code) {
    std::exit(code);
}

const Communicator& world() {
    static const SerialCommunicator serial;
    return serial;
}

} // namespace mlc::comm
