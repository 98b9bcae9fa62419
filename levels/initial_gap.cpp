// SPDX-License-Identifier: MIT
// Initial penetration and gap of the contact pairs, against the contactor body's size.
#include "levels/initial_gap.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace mlc::levels {

std::vector<std::string> initial_gap_warnings(const Problem& problem, const Level& level) {
    const mesh::Mesh& m = level.mesh;
    std::vector<std::string> out;
    if (level.contacts.empty()) return out;
    // The body of every vertex (its first triangle's attribute) and each body's bounding box.
    std::vector<int> body(static_cast<size_t>(m.n_vertices()), 0);
    int n_bodies = 1;
    if (!m.attribute.empty())
        for (int t = m.n_cells() - 1; t >= 0; --t)
            for (int v : m.cells[static_cast<size_t>(t)]) {
                body[static_cast<size_t>(v)] = m.attribute[static_cast<size_t>(t)];
                n_bodies = std::max(n_bodies, m.attribute[static_cast<size_t>(t)] + 1);
            }
    std::vector<Vec2> lo(static_cast<size_t>(n_bodies),
                         Vec2::Constant(std::numeric_limits<double>::infinity()));
    std::vector<Vec2> hi(static_cast<size_t>(n_bodies), -lo.front());
    for (int v = 0; v < m.n_vertices(); ++v) {
        const auto b = static_cast<size_t>(body[static_cast<size_t>(v)]);
        lo[b] = lo[b].cwiseMin(m.vertices[static_cast<size_t>(v)]);
        hi[b] = hi[b].cwiseMax(m.vertices[static_cast<size_t>(v)]);
    }
    const size_t n_pairs = problem.contacts.size();
    std::vector<int> deepest(n_pairs, -1); // per pair: the element of smallest g0
    for (size_t e = 0; e < level.contacts.size(); ++e) {
        const auto& c = level.contacts[e];
        const auto pr = static_cast<size_t>(c.pair);
        if (pr >= n_pairs) continue;
        if (deepest[pr] < 0 || c.g0 < level.contacts[static_cast<size_t>(deepest[pr])].g0)
            deepest[pr] = static_cast<int>(e);
    }
    for (size_t pr = 0; pr < n_pairs; ++pr) {
        if (deepest[pr] < 0) continue;
        const auto& c = level.contacts[static_cast<size_t>(deepest[pr])];
        const int v = c.vertex[0];
        const auto b = static_cast<size_t>(body[static_cast<size_t>(v)]);
        const double size = (hi[b] - lo[b]).norm();
        if (!(size > 0) || std::abs(c.g0) <= kInitialGapWarningFraction * size) continue;
        const Vec2& x = m.vertices[static_cast<size_t>(v)];
        const std::string body_name = b < problem.bodies.size() && !problem.bodies[b].name.empty()
                                          ? "body '" + problem.bodies[b].name + "'"
                                          : "the contactor body";
        std::ostringstream os;
        os << std::setprecision(4) << "contact '" << problem.contacts[pr].name << "': ";
        if (c.g0 < 0)
            os << "initial penetration " << -c.g0 << " at the contact node (" << x.x() << ", "
               << x.y() << "), " << 100 * -c.g0 / size << " % of the size of " << body_name
               << " (its bounding-box diagonal " << size << "; warned above "
               << 100 * kInitialGapWarningFraction
               << " %): the body starts overlapping its target and is pushed out by the first "
                  "load step; check the obstacle's point and normal or the bodies' positions";
        else
            os << "initial gap " << c.g0 << " at the closest contact node (" << x.x() << ", "
               << x.y() << "), " << 100 * c.g0 / size << " % of the size of " << body_name
               << " (its bounding-box diagonal " << size << "; warned above "
               << 100 * kInitialGapWarningFraction
               << " %): no node starts in contact; check the obstacle's point or the bodies' "
                  "positions";
        out.push_back(os.str());
    }
    return out;
}

} // namespace mlc::levels
