// SPDX-License-Identifier: MIT
// Alart–Curnier projection (Alart & Lebon 1995, eqs. 5-8;
// docs/theory.md#theory-augmented-lagrangian).
#include "contact/law.hpp"

#include <cmath>

namespace mlc::contact {

std::string_view to_string(Status s) {
    switch (s) {
    case Status::gap:
        return "gap";
    case Status::stick:
        return "stick";
    case Status::slip_forward:
        return "slip_forward";
    case Status::slip_backward:
        return "slip_backward";
    case Status::slip:
        return "slip";
    }
    return "unknown";
}

template <int dim>
LawProjection<dim> project(const Eigen::Matrix<double, dim - 1, 1>& sigma_t, double sigma_n,
                           double mu) {
    constexpr int nt = dim - 1; // tangential components
    LawProjection<dim> p;
    if (sigma_n > 0) return p; // gap: Phi = 0, M = 0
    // mu |Phi_n|, written as the 2D law always has (the sign of a zero bound reaches Phi_t).
    const double bound = -mu * sigma_n;
    double norm_t = 0.0;
    if constexpr (nt == 1)
        norm_t = std::abs(sigma_t[0]);
    else
        norm_t = std::hypot(sigma_t[0], sigma_t[1]);
    if (norm_t <= bound) {
        p.status = Status::stick;
        p.phi << sigma_t, sigma_n;
        p.M.setIdentity();
        return p;
    }
    // Slip: norm_t > bound >= 0.
    Eigen::Matrix<double, nt, 1> s;
    if constexpr (nt == 1) {
        s[0] = sigma_t[0] > 0 ? 1.0 : -1.0;
        p.status = s[0] > 0 ? Status::slip_forward : Status::slip_backward;
    } else {
        s = sigma_t / norm_t;
        p.status = Status::slip;
    }
    p.slip_direction = s;
    p.phi.template head<nt>() = bound * s;
    p.phi[nt] = sigma_n;
    // The tangential block rho (I - s s^T); with one tangent it is exactly 0 (s = +-1).
    if constexpr (nt > 1) {
        const double rho = bound / norm_t;
        p.M.template topLeftCorner<nt, nt>() =
            rho * (Eigen::Matrix<double, nt, nt>::Identity() - s * s.transpose());
    }
    p.M.template topRightCorner<nt, 1>() = (-s) * mu;
    p.M(nt, nt) = 1.0;
    return p;
}

template LawProjection<2> project<2>(const Eigen::Matrix<double, 1, 1>&, double, double);
template LawProjection<3> project<3>(const Eigen::Matrix<double, 2, 1>&, double, double);

Projection project(double sigma_t, double sigma_n, double mu) {
    const LawProjection<2> q = project<2>(Eigen::Matrix<double, 1, 1>(sigma_t), sigma_n, mu);
    Projection p;
    p.status = q.status;
    p.phi = q.phi;
    p.M = q.M;
    return p;
}

} // namespace mlc::contact
