// SPDX-License-Identifier: MIT
// Rigid obstacle frames.
#include "contact/obstacle.hpp"

#include "core/check.hpp"

#include <cmath>

namespace mlc::contact {

void Obstacle::validate() {
    if (kind == Kind::line) {
        const double n = normal.norm();
        MLC_CHECK(std::isfinite(n) && n > 0, "a line obstacle needs a non-zero normal");
        normal /= n;
    } else {
        MLC_CHECK(std::isfinite(radius) && radius > 0,
                  "a circle obstacle needs a positive radius, found " << radius);
    }
}

void Obstacle::frame(const Vec2& x, Vec2& n, double& g0) const {
    if (kind == Kind::line) {
        n = normal;
        g0 = n.dot(x - point);
        return;
    }
    const Vec2 d = x - center;
    const double dist = d.norm();
    MLC_CHECK(dist > 0, "a contact node sits at the centre of a circle obstacle");
    if (body_outside) {
        n = d / dist;
        g0 = dist - radius;
    } else {
        n = -d / dist;
        g0 = radius - dist;
    }
}

std::ostream& operator<<(std::ostream& os, const Obstacle& o) {
    if (o.kind == Obstacle::Kind::line)
        return os << "line through (" << o.point.x() << ", " << o.point.y() << ") normal ("
                  << o.normal.x() << ", " << o.normal.y() << ")";
    return os << "circle centre (" << o.center.x() << ", " << o.center.y() << ") radius "
              << o.radius << (o.body_outside ? ", body outside" : ", body inside");
}

} // namespace mlc::contact
