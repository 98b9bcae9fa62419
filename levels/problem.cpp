// SPDX-License-Identifier: MIT
// Problem validation.
#include "levels/problem.hpp"
#include "levels/diagnoses.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlc::levels {

void NewtonParams::validate() const {
    MLC_CHECK(rel_tol > 0 && rel_tol < 1, "newton.rel_tol must lie in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "newton.max_iter must be at least 1, found " << max_iter);
    MLC_CHECK(forcing >= 0 && forcing < 1, "newton.forcing must lie in [0, 1), found " << forcing);
}

std::ostream& operator<<(std::ostream& os, const NewtonParams& p) {
    return os << "rel_tol = " << p.rel_tol << ", max_iter = " << p.max_iter
              << ", forcing = " << p.forcing;
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
        MLC_CHECK(r_out_of_scale(c.r, min_young_modulus()).empty(),
                  "contact '" << c.name << "': " << r_out_of_scale(c.r, min_young_modulus()));
        if (c.element == ContactElementKind::node_on_rigid) {
            MLC_CHECK(c.obstacle.has_value(),
                      "contact '" << c.name << "' has no target: give an obstacle or a target tag");
        } else {
            MLC_CHECK(!c.obstacle.has_value(), "contact '" << c.name << "' is "
                                                           << to_string(c.element)
                                                           << " but also has a rigid obstacle");
            MLC_CHECK(!c.target.empty(), "contact '" << c.name << "' is " << to_string(c.element)
                                                     << " but names no target tag");
            MLC_CHECK(c.target != c.contactor, "contact '" << c.name << "': the target tag '"
                                                           << c.target
                                                           << "' is also the contactor tag");
        }
        MLC_CHECK(
            c.integration == contact::FacetIntegration::nodal ||
                c.element == ContactElementKind::node_on_facet,
            "contact '" << c.name << "': integration = \"" << contact::to_string(c.integration)
                        << "\" applies to node_on_facet only, not to " << to_string(c.element));
        MLC_CHECK(std::isfinite(c.search_radius) && c.search_radius > 0,
                  "contact '" << c.name << "': search_radius must be > 0, found "
                              << c.search_radius);
        MLC_CHECK(std::isfinite(c.match_tolerance) && c.match_tolerance > 0 &&
                      c.match_tolerance < 0.5,
                  "contact '" << c.name << "': match_tolerance must lie in (0, 0.5), found "
                              << c.match_tolerance);
    }
    // Loading path: every per-point list has the same length.
    int K = 0;
    auto check_len = [&](size_t n, const std::string& what) { check_path_length(K, n, what); };
    for (const auto& l : loads)
        check_len(l.factors.size(), "load on '" + l.tag + "'");
    for (const auto& s : supports) {
        const std::string where = s.point ? "support at a point" : "support on '" + s.tag + "'";
        check_len(s.ux_path.size(), where + " (ux)");
        check_len(s.uy_path.size(), where + " (uy)");
        MLC_CHECK(s.ux_path.empty() || (s.ux && *s.ux == s.ux_path.back()),
                  where << ": ux must equal the last entry of ux_path");
        MLC_CHECK(s.uy_path.empty() || (s.uy && *s.uy == s.uy_path.back()),
                  where << ": uy must equal the last entry of uy_path");
        check_len(s.active.size(), where + " (active)");
    }
    newton.validate();
}

void check_path_length(int& K, size_t n, const std::string& what) {
    if (n == 0) return;
    MLC_CHECK(K == 0 || static_cast<int>(n) == K,
              what << " has " << n << " path values but another list has " << K
                   << "; every per-step list must have the same length");
    K = static_cast<int>(n);
}

Problem Problem::at_step(int step) const {
    MLC_CHECK(step >= 1 && step <= load_steps,
              "load step " << step << " out of range 1.." << load_steps);
    Problem p = *this;
    p.supports.clear();
    for (const auto& s : supports)
        if (support_active(s, step)) {
            p.supports.push_back(s);
            p.supports.back().active.clear();
        }
    return p;
}

bool Problem::support_active(const Support& s, int step) const {
    if (s.active.empty()) return true;
    // The path segment ((k-1)/K, k/K] holding s = step / load_steps.
    const long K = static_cast<long>(s.active.size()), n = std::max(load_steps, 1);
    const long k = std::clamp((static_cast<long>(step) * K + n - 1) / n, 1L, K);
    return s.active[static_cast<size_t>(k - 1)];
}

bool Problem::same_supports(int a, int b) const {
    return std::all_of(supports.begin(), supports.end(), [&](const Support& s) {
        return support_active(s, a) == support_active(s, b);
    });
}

int Problem::n_path_points() const {
    for (const auto& l : loads)
        if (!l.factors.empty()) return static_cast<int>(l.factors.size());
    for (const auto& s : supports) {
        if (!s.ux_path.empty()) return static_cast<int>(s.ux_path.size());
        if (!s.uy_path.empty()) return static_cast<int>(s.uy_path.size());
    }
    for (const auto& s : supports)
        if (!s.active.empty()) return static_cast<int>(s.active.size());
    return 1;
}

double Problem::path_value(const std::vector<double>& path, double full, int k, int K) {
    if (path.empty()) return full * static_cast<double>(k) / static_cast<double>(K);
    return path[static_cast<size_t>(k - 1)];
}

std::string_view to_string(Problem::Numbering n) {
    return n == Problem::Numbering::lattice ? "lattice" : "hilbert";
}

Problem::Numbering parse_numbering(std::string_view name, std::string_view what) {
    MLC_CHECK(name == "hilbert" || name == "lattice",
              what << " must be hilbert or lattice, found '" << name << "'");
    return name == "lattice" ? Problem::Numbering::lattice : Problem::Numbering::hilbert;
}

std::string_view to_string(ContactElementKind k) {
    switch (k) {
    case ContactElementKind::node_on_rigid:
        return "node_on_rigid";
    case ContactElementKind::node_on_facet:
        return "node_on_facet";
    case ContactElementKind::node_on_node:
        return "node_on_node";
    }
    return "?";
}

double Problem::min_young_modulus() const {
    double e = std::numeric_limits<double>::infinity();
    for (const auto& b : bodies)
        e = std::min(e, b.material.E);
    return e;
}

double Problem::max_young_modulus() const {
    double e = 0;
    for (const auto& b : bodies)
        e = std::max(e, b.material.E);
    return e;
}

} // namespace mlc::levels
