// SPDX-License-Identifier: MIT
// The BoomerAMG entry points when built without hypre (MLC_WITH_HYPRE=OFF): they say so.
// solvers/CMakeLists.txt builds this file instead of boomeramg.cpp in that case.
#include "solvers/hypre/boomeramg.hpp"

#include "core/check.hpp"

namespace mlc::solvers {

namespace {
[[noreturn]] void no_hypre() {
    throw InvalidInput("BoomerAMG is not available: this build has MLC_WITH_HYPRE=OFF "
                       "(install libhypre-dev and reconfigure)");
}
} // namespace

struct BoomerAMGPreconditioner::Impl {};

void BoomerAMGParams::validate() const {}
std::ostream& operator<<(std::ostream& os, const BoomerAMGParams&) {
    return os << "BoomerAMGParams{}";
}
bool have_hypre() {
    return false;
}
void ensure_hypre_initialized() {
    no_hypre();
}
BoomerAMGPreconditioner::BoomerAMGPreconditioner(BoomerAMGParams params) : params_(params) {
    no_hypre();
}
BoomerAMGPreconditioner::~BoomerAMGPreconditioner() = default;
void BoomerAMGPreconditioner::setup(const SparseMatrix&) {
    no_hypre();
}
void BoomerAMGPreconditioner::apply(const Vector&, Vector&) const {
    no_hypre();
}
std::string BoomerAMGPreconditioner::name() const {
    return "amg";
}
int hypre_threads() {
    return 1;
}
SolveResult boomeramg_pcg(const SparseMatrix&, const Vector&, Vector&, double, int,
                          const BoomerAMGParams&, const std::vector<int>&,
                          const std::vector<Vector>&) {
    no_hypre();
}
SolveResult boomeramg_pcg_par(const ParMatrix&, const Vector&, Vector&, double, int,
                              const BoomerAMGParams&, const std::vector<int>&) {
    no_hypre();
}

} // namespace mlc::solvers
