// SPDX-License-Identifier: MIT
// The MGR entry points when built without hypre (MLC_WITH_HYPRE=OFF): they say so.
// solvers/CMakeLists.txt builds this file instead of mgr.cpp in that case.
#include "solvers/hypre/mgr.hpp"

#include "core/check.hpp"

namespace mlc::solvers {

struct MGRPreconditioner::Impl {};

void MGRParams::validate() const {}
std::ostream& operator<<(std::ostream& os, const MGRParams&) {
    return os << "MGRParams{}";
}
MGRPreconditioner::MGRPreconditioner(std::vector<int>, MGRParams) {
    throw InvalidInput("mgr (hypre MGR) is not available: this build has MLC_WITH_HYPRE=OFF "
                       "(install libhypre-dev and reconfigure)");
}
MGRPreconditioner::~MGRPreconditioner() = default;
void MGRPreconditioner::setup(const SparseMatrix&) {}
void MGRPreconditioner::apply(const Vector&, Vector&) const {}
SolveResult MGRPreconditioner::solve_fgmres(const SparseMatrix&, const Vector&, Vector&, double,
                                            int, int) const {
    return {};
}
std::string MGRPreconditioner::name() const {
    return "mgr";
}

} // namespace mlc::solvers
