// SPDX-License-Identifier: MIT
/// @file Diagnoses that name the cause of a failed or doubtful solve: a load with no equilibrium
/// once contact opens, rotations and strains too large for small-displacement theory, and rigid
/// motions that every slipping contact node leaves free (a solution that is not unique).
#pragma once

#include "core/types.hpp"
#include "levels/level.hpp"
#include "levels/newton.hpp"
#include "levels/problem.hpp"

#include <string>
#include <vector>

namespace mlc::levels {

/// Rotations (radians, the skew part of an element's displacement gradient) and strains (the
/// largest principal strain in absolute value) above these are outside small-displacement theory:
/// a warning (RunResult::warnings). Not lower: the benchmark scenes stay below them (hertz's
/// elements at the contact edge turn by about a / R as the disc's surface flattens there; the
/// patch test's prescribed strain is half the limit).
inline constexpr double kSmallRotationLimit = 0.1;
inline constexpr double kSmallStrainLimit = 0.1;

/// The augmentation parameter r of a contact pair must lie within these multiples of the
/// smallest Young's modulus of the scene (r has the units of E in 2D; the default is 0.1 E):
/// far below, the contact holds rigid motions so weakly that the Newton matrices are
/// numerically singular; far above, statuses cycle.
inline constexpr double kMinROverE = 1e-6, kMaxROverE = 1e6;
/// Empty, or why r is out of scale for E (the smallest Young's modulus of the scene).
std::string r_out_of_scale(double r, double E);

/// The rigid-body motions of one body that the supports leave free. A motion is given by its
/// coefficients c = (a, b, w): at a point x it moves by (a - w (y - yc) / size, b + w (x - xc) /
/// size), with (xc, yc) the mean of the body's vertices and `size` its bounding-box diagonal.
struct FreeMotions {
    int body = 0;
    Vec2 centre = Vec2::Zero();
    double size = 1.0;
    std::vector<Eigen::Vector3d> basis; ///< orthonormal coefficient vectors; empty: held
    /// The displacement of the motion with coefficients c at x.
    Vec2 at(const Eigen::Vector3d& c, const Vec2& x) const;
    /// "translation along (x, y)" or "rotation about (x, y)".
    std::string describe(const Eigen::Vector3d& c) const;
};

/// Per body of level L: its free rigid motions under the supports of L (L.fixed).
std::vector<FreeMotions> free_rigid_motions(const Level& L);

/// Empty, or why the loads at load factor s have no equilibrium on level L: a body whose contacts
/// are all with rigid obstacles has a rigid motion that no support holds, on which the loads do
/// positive work, and which opens or slides every contact node within its friction cone (n.m >=
/// mu |t.m| at each node; then no contact force, which only pushes and resists sliding up to mu
/// times the pressure, can balance the loads). Exact for the node-on-rigid contact of the model.
std::string no_equilibrium(const Problem& p, const Level& L, double s);

/// The largest element rotation and principal strain of a displacement field, and where.
struct Deformation {
    double rotation = 0.0; ///< |skew part of grad u|, radians
    int rotation_triangle = -1;
    double strain = 0.0; ///< largest |principal strain|
    int strain_triangle = -1;
};
Deformation max_deformation(const Level& L, const Vector& u_full);

/// Empty, or the note that the converged state is not unique: a body whose contacts are all with
/// rigid obstacles has a free rigid motion that is tangential at every contact node, and every
/// node in contact slips (or is frictionless), so that the motion added to the solution gives
/// another.
std::string unheld_tangential_motion(const Problem& p, const Level& L,
                                     const std::vector<ContactNodeState>& nodes);

} // namespace mlc::levels
