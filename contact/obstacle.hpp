// SPDX-License-Identifier: MIT
/// @file Rigid obstacles (a line, a circle) and the local contact frame they give a point.
#pragma once

#include "core/types.hpp"

#include <ostream>

namespace mlc::contact {

/// A fixed rigid obstacle. The frame at a body point x: n the unit normal of the obstacle
/// pointing toward the body, t = (n_y, -n_x), and the initial gap g0 = signed distance (>= 0
/// when apart), all evaluated at the reference position (small strain).
struct Obstacle {
    enum class Kind { line, circle };
    Kind kind = Kind::line;
    Vec2 point = Vec2::Zero();    ///< line: a point on the line
    Vec2 normal = Vec2(0.0, 1.0); ///< line: normal toward the body (normalized on validate)
    Vec2 center = Vec2::Zero();   ///< circle: centre
    double radius = 0.0;          ///< circle: radius > 0
    bool body_outside = true; ///< circle: body outside the disc (a rigid cylinder) or inside a hole

    /// Throws InvalidInput for a zero normal or a non-positive radius; normalizes the normal.
    void validate();
    /// Normal (toward the body) and initial gap at reference point x.
    void frame(const Vec2& x, Vec2& n, double& g0) const;
};

std::ostream& operator<<(std::ostream& os, const Obstacle& o);

} // namespace mlc::contact
