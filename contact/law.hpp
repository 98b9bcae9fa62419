// SPDX-License-Identifier: MIT
/// @file The Alart–Curnier augmented Lagrangian contact law: statuses, the projection Phi of the
/// augmented multiplier sigma onto the Coulomb cone, and its generalized derivative M.
#pragma once

#include <Eigen/Dense>
#include <string_view>

namespace mlc::contact {

/// Contact status of one node: the region of the (sigma_t, sigma_n) plane where Phi is linear.
enum class Status : unsigned char {
    gap,          ///< sigma_n > 0: open, Phi = 0
    stick,        ///< sigma_n <= 0, |sigma_t| <= -mu sigma_n: Phi = sigma
    slip_forward, ///< |sigma_t| > -mu sigma_n, sigma_t > 0: Phi_t = +mu |sigma_n|
    slip_backward ///< |sigma_t| > -mu sigma_n, sigma_t < 0: Phi_t = -mu |sigma_n|
};

/// "gap", "stick", "slip_forward", "slip_backward".
std::string_view to_string(Status s);

/// Phi(sigma) and M = dPhi/dsigma in the local (t, n) frame.
struct Projection {
    Status status = Status::gap;
    Eigen::Vector2d phi = Eigen::Vector2d::Zero(); ///< (Phi_t, Phi_n)
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();   ///< rows/cols (t, n)
};

/// Projection of sigma = (sigma_t, sigma_n) for friction coefficient mu >= 0:
/// Phi_n = min(sigma_n, 0), Phi_t = clamp(sigma_t, -mu |Phi_n|, mu |Phi_n|) (docs/theory.md#theory-augmented-lagrangian).
/// M: gap 0; stick I; slip with eps = sign(sigma_t): [[0, -eps mu], [0, 1]].
/// The boundaries (sigma_n = 0, |sigma_t| = -mu sigma_n) belong to stick, as in the table.
Projection project(double sigma_t, double sigma_n, double mu);

} // namespace mlc::contact
