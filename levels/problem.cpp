// SPDX-License-Identifier: MIT
// Problem validation.
#include "levels/problem.hpp"

#include "core/check.hpp"

#include <cmath>

namespace mlc::levels {

void NewtonParams::validate() const {
    MLC_CHECK(rel_tol > 0 && rel_tol < 1, "newton.rel_tol must lie in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "newton.max_iter must be at least 1, found " << max_iter);
}

std::ostream& operator<<(std::ostream& os, const NewtonParams& p) {
    return os << "rel_tol = " << p.rel_tol << ", max_iter = " << p.max_iter;
}

void Problem::validate() const {
    MLC_CHECK(!bodies.empty(), "the scene defines no body");
    for (const auto& b : bodies) {
        try {
            b.material.validate();
        } catch (const InvalidInput& e) {
            throw InvalidInput("body '" + b.name + "': " + e.what());
        }
    }
    MLC_CHECK(load_steps >= 1, "load steps must be at least 1, found " << load_steps);
    MLC_CHECK(levels >= 0 && levels <= 12, "levels must lie in [0, 12], found " << levels);
    for (const auto& c : contacts) {
        MLC_CHECK(std::isfinite(c.mu) && c.mu >= 0,
                  "contact '" << c.name << "': friction coefficient mu must be >= 0, found "
                              << c.mu);
        MLC_CHECK(std::isfinite(c.r) && c.r > 0,
                  "contact '" << c.name << "': augmentation parameter r must be > 0, found "
                              << c.r);
        MLC_CHECK(c.obstacle.has_value(), "contact '" << c.name << "' has no target");
    }
    newton.validate();
}

double Problem::max_young_modulus() const {
    double e = 0;
    for (const auto& b : bodies)
        e = std::max(e, b.material.E);
    return e;
}

} // namespace mlc::levels
