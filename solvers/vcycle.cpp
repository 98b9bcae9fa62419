// SPDX-License-Identifier: MIT
// The multigrid V-cycle over a level's operator, smoother and transfer interfaces.
#include "solvers/vcycle.hpp"

namespace mlc::solvers {

void VCycle::cycle(int k, const Vector& r, Vector& z) const {
    if (k == 0) {
        coarse_solve(r, z);
        return;
    }
    const CycleLevel L = cycle_level(k);
    const bool from_zero = L.pre_sweeps == 0;
    if (!from_zero) {
        L.smoother.forward_from_zero(r, z, L.res);
        L.smoother.smooth(r, z, smoothers::Sweep::forward, L.pre_sweeps - 1);
        if (L.pre_sweeps > 1) L.op.residual(r, z, L.res);
    }
    L.transfer.restrict_residual(from_zero ? r : L.res, L.rc);
    cycle(k - 1, L.rc, L.ec);
    if (L.cycles > 1 && k > 1) {
        const CycleLevel below = cycle_level(k - 1);
        for (int c = 1; c < L.cycles; ++c) {
            below.op.residual(L.rc, L.ec, *L.rw);
            cycle(k - 1, *L.rw, *L.ew);
            L.ec += *L.ew;
        }
    }
    L.transfer.prolongate(L.ec, z, !from_zero);
    L.smoother.smooth(r, z, smoothers::Sweep::backward, L.post_sweeps);
}

} // namespace mlc::solvers
