// SPDX-License-Identifier: MIT
// comm::world() in a build without MPI: always one process.
#include "comm/world.hpp"

namespace mlc::comm {

bool have_mpi() {
    return false;
}

const Communicator& world() {
    static const SerialCommunicator serial;
    return serial;
}

} // namespace mlc::comm
