// SPDX-License-Identifier: MIT
/// @file The Alart–Curnier augmented Lagrangian contact law: statuses, the projection Phi of the
/// augmented multiplier sigma onto the Coulomb cone (2D) or the Coulomb disc (3D), and its
/// generalized derivative M.
#pragma once

#include <Eigen/Dense>
#include <string_view>

namespace mlc::contact {

/// Contact status of one node: the region of sigma-space where Phi has one smooth formula.
/// 2D slip is slip_forward or slip_backward; 3D slip is slip, with its direction given apart
/// (LawProjection::slip_direction). The numeric values are those the outputs write.
enum class Status : unsigned char {
    gap,           ///< sigma_n > 0: open, Phi = 0
    stick,         ///< sigma_n <= 0, |sigma_t| <= -mu sigma_n: Phi = sigma
    slip_forward,  ///< 2D, |sigma_t| > -mu sigma_n, sigma_t > 0: Phi_t = +mu |sigma_n|
    slip_backward, ///< 2D, |sigma_t| > -mu sigma_n, sigma_t < 0: Phi_t = -mu |sigma_n|
    slip           ///< 3D, |sigma_t| > -mu sigma_n: Phi_t = mu |sigma_n| sigma_t / |sigma_t|
};

/// "gap", "stick", "slip_forward", "slip_backward", "slip".
std::string_view to_string(Status s);

/// Phi(sigma), M = dPhi/dsigma and the status in the local frame of a contact node in dim
/// dimensions: the dim - 1 tangential components first, the normal last (2D: (t, n); 3D:
/// (t1, t2, n), see contact::tangent_basis).
template <int dim> struct LawProjection {
    static_assert(dim == 2 || dim == 3, "the contact law is for dim = 2 or 3");
    Status status = Status::gap;
    Eigen::Matrix<double, dim, 1> phi = Eigen::Matrix<double, dim, 1>::Zero();
    Eigen::Matrix<double, dim, dim> M = Eigen::Matrix<double, dim, dim>::Zero();
    /// In slip the unit vector sigma_t / |sigma_t| (2D: +1 forward, -1 backward); 0 otherwise.
    Eigen::Matrix<double, dim - 1, 1> slip_direction = Eigen::Matrix<double, dim - 1, 1>::Zero();
};

/// Projection of sigma = (sigma_t, sigma_n) for friction coefficient mu >= 0
/// (docs/theory.md#theory-augmented-lagrangian): Phi_n = min(sigma_n, 0) and Phi_t the
/// projection of sigma_t onto the ball of radius mu |Phi_n| (an interval in 2D, a disc in 3D).
/// - gap (sigma_n > 0): Phi = 0, M = 0;
/// - stick (|sigma_t| <= mu |Phi_n|): Phi = sigma, M = I;
/// - slip: with s = sigma_t / |sigma_t| and rho = mu |sigma_n| / |sigma_t| < 1,
///   Phi_t = mu |sigma_n| s and M = [[rho (I - s s^T), -mu s], [0, 1]]: the exact derivative
///   of the disc projection. With one tangent (2D) s = +-1 and I - s s^T = 0 exactly, so M is
///   [[0, -s mu], [0, 1]], the 2D slip Jacobian.
/// The boundaries (sigma_n = 0, |sigma_t| = mu |sigma_n|) belong to stick.
/// The status is slip_forward / slip_backward in 2D, slip in 3D.
/// Call as project<3>(sigma_t, sigma_n, mu): dim is not deduced from sigma_t.
template <int dim>
LawProjection<dim> project(const Eigen::Matrix<double, dim - 1, 1>& sigma_t, double sigma_n,
                           double mu);

extern template LawProjection<2> project<2>(const Eigen::Matrix<double, 1, 1>&, double, double);
extern template LawProjection<3> project<3>(const Eigen::Matrix<double, 2, 1>&, double, double);

/// Phi(sigma) and M = dPhi/dsigma in the local 2D (t, n) frame.
struct Projection {
    Status status = Status::gap;
    Eigen::Vector2d phi = Eigen::Vector2d::Zero(); ///< (Phi_t, Phi_n)
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();   ///< rows/cols (t, n)
};

/// The 2D projection of sigma = (sigma_t, sigma_n): project<2>, with its status, Phi and M.
/// Phi_t = clamp(sigma_t, -mu |Phi_n|, mu |Phi_n|); M: gap 0; stick I; slip with
/// eps = sign(sigma_t): [[0, -eps mu], [0, 1]].
Projection project(double sigma_t, double sigma_n, double mu);

} // namespace mlc::contact
