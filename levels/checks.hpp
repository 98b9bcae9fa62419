// SPDX-License-Identifier: MIT
/// @file Physics checks of a converged state: global force balance, the Coulomb cone, slip,
/// complementarity, penetration and tension, each relative to the scale of the solution.
#pragma once

#include "core/types.hpp"
#include "levels/distributed_solve.hpp"
#include "levels/level.hpp"
#include "levels/newton.hpp"
#include "levels/problem.hpp"
#include "levels/solve.hpp"

#include <vector>

namespace mlc::levels {

/// Relative global force balance: |resultant of loads, contact forces and support reactions| /
/// sum of their magnitudes, per axis, the worse of the two.
double force_balance_error(const Level& level, double s, const Vector& u_full,
                           const std::vector<ContactNodeState>& nodes);

/// Quality figures of a converged state, all relative (docs/verification.md#verification-identities).
struct StateChecks {
    double force_balance =
        0.0; ///< |resultant of loads, contact forces, reactions| / sum of magnitudes
    double coulomb_excess = 0.0; ///< max (|lambda_t| - mu |lambda_n|)+ / max |lambda_n|
    double slip_equality =
        0.0; ///< max | |lambda_t| - mu |lambda_n| | at slipping nodes / max |lambda_n|
    double complementarity = 0.0; ///< max |lambda_n d_n| / (max |lambda_n| * max |u|)
    double penetration = 0.0;     ///< max (-d_n)+ / max |u|
    double tension = 0.0;         ///< max (lambda_n)+ / max |lambda_n|
    /// False when there is no force to balance: the loads, contact forces and reactions sum (in
    /// magnitude) to less than kNoForceRatio times the internal forces' own scale (sum over
    /// the elements of |K_e| |u_e|), i.e. to round-off, as for bodies moved rigidly by their
    /// supports without touching. force_balance is then round-off over round-off and means
    /// nothing; it is reported as not applicable.
    bool force_balance_applicable = true;
};

/// See StateChecks::force_balance_applicable.
inline constexpr double kNoForceRatio = 1e-12;

/// The checks of the final state of a run (r.u_full and r.nodes on the finest level, full load):
/// force balance as force_balance_error; the contact figures over all contact nodes, the Coulomb
/// excess only at nodes in contact and the slip equality only at slipping frictional nodes.
StateChecks check_state(const Problem& p, const RunResult& r);
/// Collective: the same checks of a distributed run's final state, each process summing (force
/// balance) or maximising (the contact figures) over what it owns, reduced over `comm`.
StateChecks check_state(const Problem& p, const DistributedRunResult& r, const Communicator& comm);

/// The resultant force the target exerts on the contactor nodes of contact pair `pair` in the
/// final state of a run (finest level, global axes): -sum (lambda_t t + lambda_n n) over the pair's
/// nodes. `in_contact`, if given, receives the number of those nodes not in gap.
Vec2 contact_resultant(const RunResult& r, int pair, int* in_contact = nullptr);
/// The same over the contact nodes `nodes` of level L (L.contacts order), e.g. a process's own.
Vec2 contact_resultant(const Level& L, const std::vector<ContactNodeState>& nodes, int pair,
                       int* in_contact = nullptr);

} // namespace mlc::levels
