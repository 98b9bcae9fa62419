// SPDX-License-Identifier: MIT
// Alart–Curnier projection (Alart & Lebon 1995, eqs. 5-8; docs/theory.md#theory-augmented-lagrangian).
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
    }
    return "unknown";
}

Projection project(double sigma_t, double sigma_n, double mu) {
    Projection p;
    if (sigma_n > 0) return p; // gap: Phi = 0, M = 0
    const double bound = -mu * sigma_n;
    if (std::abs(sigma_t) <= bound) {
        p.status = Status::stick;
        p.phi = {sigma_t, sigma_n};
        p.M.setIdentity();
        return p;
    }
    const double eps = sigma_t > 0 ? 1.0 : -1.0;
    p.status = eps > 0 ? Status::slip_forward : Status::slip_backward;
    p.phi = {eps * bound, sigma_n};
    p.M << 0.0, -eps * mu, 0.0, 1.0;
    return p;
}

} // namespace mlc::contact
