// SPDX-License-Identifier: MIT
// ParMatrix when built without hypre (MLC_WITH_HYPRE=OFF, the sanitizer tree): the constructors
// say so, so that code holding a ParMatrix links and one process never builds one.
// solvers/CMakeLists.txt builds this file instead of par_matrix.cpp in that case.
#include "solvers/hypre/par_matrix.hpp"

#include "core/check.hpp"

namespace mlc::solvers {

struct ParMatrix::Impl {};

namespace {
[[noreturn]] void unavailable() {
    throw InvalidInput("distributed matrices (hypre ParCSR) are not available: this build has "
                       "MLC_WITH_HYPRE=OFF (install libhypre-dev and reconfigure)");
}
} // namespace

ParMatrix::ParMatrix(const Communicator&, const DistributedRows&) {
    unavailable();
}
ParMatrix::ParMatrix(const Communicator&, const DistributedRows&, std::int64_t, int) {
    unavailable();
}
ParMatrix::ParMatrix(const Communicator&, RowBlocks&) {
    unavailable();
}
ParMatrix::~ParMatrix() = default;
std::int64_t ParMatrix::first_row() const {
    unavailable();
}
int ParMatrix::n_rows() const {
    unavailable();
}
std::int64_t ParMatrix::first_col() const {
    unavailable();
}
int ParMatrix::n_cols() const {
    unavailable();
}
std::int64_t ParMatrix::n_global() const {
    unavailable();
}
void* ParMatrix::hypre_handle() const {
    unavailable();
}
void ParMatrix::apply(const Vector&, Vector&) const {
    unavailable();
}
void ParMatrix::apply_transpose(const Vector&, Vector&) const {
    unavailable();
}
void ParMatrix::ghost_values(const Vector&, Vector&) const {
    unavailable();
}
void ParMatrix::subtract_offdiagonal(const Vector&, Vector&) const {
    unavailable();
}
void ParMatrix::apply(const Vector&, Vector&, const LinearOperator&) const {
    unavailable();
}
void ParMatrix::update_values(const std::vector<double>&) {
    unavailable();
}

} // namespace mlc::solvers
