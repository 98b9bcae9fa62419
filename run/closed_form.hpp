// SPDX-License-Identifier: MIT
/// @file Closed-form references and how a discrete contact state is compared to them.
#pragma once

#include "levels/newton.hpp"

#include <vector>

namespace mlc::apps {

/// Hertz line contact of a cylinder (radius R) on a rigid plane under a load P per unit
/// thickness: a = sqrt(4 P R / (pi E*)), p(x) = (2 P / (pi a^2)) sqrt(a^2 - x^2), p0 = E* a / (2R).
struct Hertz {
    double P = 0.0;      ///< resultant per unit thickness (full cylinder)
    double R = 1.0;      ///< radius
    double E_star = 1.0; ///< plane-strain modulus of the contact pair
    double half_width() const;
    double peak_pressure() const;
    double pressure(double x) const;
};

/// A discrete contact pressure profile along x: nodes in x order with p = -lambda_n / tributary
/// length (half the x-distance to each neighbour on the contact boundary; the node on a symmetry
/// axis at the start gets only its right half).
struct PressureProfile {
    std::vector<double> x;
    std::vector<double> p;
    /// Half-width estimate: midway between the last node in contact (status not gap) and the next.
    double half_width = 0.0;
    /// Spacing of the nodes around the contact edge (uncertainty of half_width is half of it).
    double edge_spacing = 0.0;
};
PressureProfile pressure_profile(std::vector<levels::ContactNodeState> nodes);

/// Errors of a profile against Hertz, relative: half-width, peak (the first node), and the
/// root-mean-square pressure error over the nodes with |x| < 0.9 a divided by p0.
struct HertzErrors {
    double half_width = 0.0;
    double peak = 0.0;
    double profile_rms = 0.0;
};
HertzErrors compare(const PressureProfile& prof, const Hertz& h);

} // namespace mlc::apps
