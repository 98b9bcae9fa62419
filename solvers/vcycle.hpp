// SPDX-License-Identifier: MIT
/// @file The multigrid V-cycle, written once over three interfaces of a level (its operator,
/// smoother and transfer from the level below) and a coarse solve, after MFEM's MultigridBase
/// (fem/multigrid.hpp). The one-process multigrid (solvers/mg.hpp) supplies sparse matrices
/// with their smoothers and transfers; the distributed multigrid (levels/distributed_multigrid.hpp)
/// supplies each process's rows of ParCSR operators, smoothers of each process's diagonal block
/// with the halo exchange, and its gathered coarse solve.
///
/// One V-cycle on level k >= 1, A_k z = r (nu1 = pre, nu2 = post sweeps):
///
///     pre-smooth:  z = S_fwd r from z = 0, then nu1 - 1 more forward sweeps, res = r - A_k z
///     coarse:      z <- z + T_k B_{k-1} R_k res           (B_{k-1}: the cycle of level k-1)
///     post-smooth: nu2 backward sweeps z <- z + S_bwd (r - A_k z)
///
/// and on level 0 the coarse solve. Without pre-smoothing z is zero until the coarse correction:
/// r itself is restricted and the prolongation writes z = T e instead of adding it to zeros.
///
/// A W-cycle (CycleLevel::cycles = 2) solves the coarse problem by two cycles of level k-1
/// instead of one: e = B_{k-1} rc, then e <- e + B_{k-1} (rc - A_{k-1} e). Level 0 is solved
/// once (its solve is exact). In 3D a level has an eighth of the unknowns of the one above, so
/// the W-cycle costs about 1.3 times the V-cycle's work (sum over k of 2^k / 8^k) for the
/// two-grid rate on every level.
#pragma once

#include "core/types.hpp"
#include "smoothers/block_sor.hpp"

namespace mlc::solvers {

/// A level's operator as the cycle uses it.
class CycleOperator {
public:
    virtual ~CycleOperator() = default;
    /// res = r - A z (res resized).
    virtual void residual(const Vector& r, const Vector& z, Vector& res) const = 0;
};

/// A level's smoother as the cycle uses it.
class CycleSmoother {
public:
    virtual ~CycleSmoother() = default;
    /// z = one forward sweep on A z = r from z = 0, and res = r - A z.
    virtual void forward_from_zero(const Vector& r, Vector& z, Vector& res) const = 0;
    /// `count` >= 0 sweeps on A z = r in `direction` (forward or backward), z updated.
    virtual void smooth(const Vector& r, Vector& z, smoothers::Sweep direction,
                        int count) const = 0;
};

/// The transfer between a level and the one below it.
class CycleTransfer {
public:
    virtual ~CycleTransfer() = default;
    /// rc = R res (R the restriction to the level below).
    virtual void restrict_residual(const Vector& res, Vector& rc) const = 0;
    /// z = T e, or z += T e when `add` (T the prolongation from the level below).
    virtual void prolongate(const Vector& e, Vector& z, bool add) const = 0;
};

/// What the cycle needs of one level above the coarsest: its pieces, sweep counts and work
/// vectors (res on the level, rc and ec on the level below).
struct CycleLevel {
    const CycleOperator& op;
    const CycleSmoother& smoother;
    const CycleTransfer& transfer;
    int pre_sweeps = 1;
    int post_sweeps = 1;
    Vector& res;
    Vector& rc;
    Vector& ec;
    /// Cycles of the level below per visit: 1 (V-cycle) or 2 (W-cycle; then rw and ew, work
    /// vectors of the level below, are set).
    int cycles = 1;
    Vector* rw = nullptr;
    Vector* ew = nullptr;
};

/// The V-cycle over the levels a derived class gives (`cycle_level`, level 0 by `coarse_solve`).
class VCycle {
public:
    virtual ~VCycle() = default;
    /// One cycle (V, or W where the levels say so) from level k on A_k z = r (z overwritten).
    void cycle(int k, const Vector& r, Vector& z) const;

protected:
    /// Level k >= 1 (the cycle calls it once per visit of the level).
    virtual CycleLevel cycle_level(int k) const = 0;
    /// z = B_0 r on level 0.
    virtual void coarse_solve(const Vector& r, Vector& z) const = 0;
};

} // namespace mlc::solvers
