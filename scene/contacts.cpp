// SPDX-License-Identifier: MIT
// The [[contact]] pairs of a scene: what every pair has (name, contactor, friction, augmentation,
// region), then either a target tag (two bodies) or a rigid obstacle.
#include "contact/obstacle.hpp"
#include "levels/diagnoses.hpp"
#include "scene/reader.hpp"

#include <iomanip>
#include <set>

namespace mlc::scene::detail {

namespace {

/// Empty, or why obstacle `o` of a pair whose contactor tag is `tag` faces away from the body:
/// more than half of the area of a body holding a contactor vertex lies on the obstacle's far
/// side (behind a line, against its normal; inside a circle the body should be outside of, or
/// the reverse). Its contact would then hold the body from the wrong side.
std::string obstacle_faces_away(const levels::Problem& p, const std::string& tag,
                                const contact::Obstacle& o) {
    const mesh::Mesh& m = p.mesh0;
    const auto tid = m.find_tag(tag);
    if (!tid) return {};
    const auto body_of = [&](int t) {
        return m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
    };
    std::vector<int> vbody(static_cast<size_t>(m.n_vertices()), -1);
    for (int t = 0; t < m.n_cells(); ++t)
        for (int v : m.cells[static_cast<size_t>(t)])
            vbody[static_cast<size_t>(v)] = body_of(t);
    std::set<int> bodies;
    for (int v : m.vertices_with_tag(*tid))
        bodies.insert(vbody[static_cast<size_t>(v)]);
    for (int b : bodies) {
        double total = 0.0, behind = 0.0;
        for (int t = 0; t < m.n_cells(); ++t) {
            if (body_of(t) != b) continue;
            const auto& tri = m.cells[static_cast<size_t>(t)];
            const Vec2 c =
                (m.vertices[static_cast<size_t>(tri[0])] + m.vertices[static_cast<size_t>(tri[1])] +
                 m.vertices[static_cast<size_t>(tri[2])]) /
                3.0;
            double gap = 0.0;
            if (o.kind == contact::Obstacle::Kind::line)
                gap = o.normal.dot(c - o.point);
            else
                gap = o.body_outside ? (c - o.center).norm() - o.radius
                                     : o.radius - (c - o.center).norm();
            const double a = std::abs(m.signed_measure(t));
            total += a;
            if (gap < 0) behind += a;
        }
        if (!(total > 0) || behind <= 0.5 * total) continue;
        const std::string name = b >= 0 && b < static_cast<int>(p.bodies.size())
                                     ? p.bodies[static_cast<size_t>(b)].name
                                     : std::to_string(b);
        std::ostringstream os;
        os << std::setprecision(3) << 100.0 * behind / total << "% of the area of body '" << name
           << "' lies ";
        if (o.kind == contact::Obstacle::Kind::line)
            os << "behind the line (against its normal [" << o.normal.x() << ", " << o.normal.y()
               << "]): the normal points away from the body; it must point from the obstacle "
                  "into the body: normal = ["
               << -o.normal.x() + 0.0 << ", " << -o.normal.y() + 0.0 << "]";
        else
            os << (o.body_outside ? "inside" : "outside") << " the circle, but side = \""
               << (o.body_outside ? "outside" : "inside")
               << "\" puts the body there: the obstacle's normal points away from the body; use "
                  "side = \""
               << (o.body_outside ? "inside" : "outside") << "\"";
        return os.str();
    }
    return {};
}

/// What every pair has: name, contactor, mu, r (or r_over_E x Emin) and region.
levels::ContactPair read_pair_common(const Reader& rd, const toml::table& ct, const std::string& w,
                                     const levels::Problem& p, double Emin) {
    rd.check_keys(ct,
                  {"name", "contactor", "region", "mu", "r", "r_over_E", "obstacle", "target",
                   "element", "integration", "search_radius", "match_tolerance"},
                  w);
    levels::ContactPair c;
    c.name = rd.string_or(ct, "name", "contact" + std::to_string(p.contacts.size() + 1), w);
    c.contactor = rd.string(ct, "contactor", w);
    if (!p.mesh0.find_tag(c.contactor))
        rd.fail(ct.get("contactor"), w + ": unknown contactor tag '" + c.contactor + "'");
    check_tag(rd, p.mesh0, ct, c.contactor, w, true, "contactor");
    c.mu = rd.number(ct, "mu", w);
    if (c.mu < 0)
        rd.fail(ct.get("mu"),
                w + ": friction coefficient mu must be >= 0, found " + std::to_string(c.mu));
    if (ct.get("r") && ct.get("r_over_E")) rd.fail(&ct, w + " takes r or r_over_E, not both");
    if (ct.get("r"))
        c.r = rd.number(ct, "r", w);
    else
        c.r = rd.number_or(ct, "r_over_E", 0.1, w) * Emin;
    if (!(c.r > 0))
        rd.fail(ct.get("r") ? ct.get("r") : ct.get("r_over_E"),
                w + ": augmentation parameter r must be > 0");
    if (const std::string why = levels::r_out_of_scale(c.r, Emin); !why.empty())
        rd.fail(ct.get("r") ? ct.get("r") : ct.get("r_over_E"), w + ": " + why);
    if (const toml::node* rn = ct.get("region")) {
        const toml::table& rt = rd.table(rn, w + ".region");
        rd.check_keys(rt, {"min", "max"}, w + ".region");
        levels::Box box;
        if (rt.get("min")) box.lo = rd.vec2(rt, "min", w + ".region");
        if (rt.get("max")) box.hi = rd.vec2(rt, "max", w + ".region");
        c.region = box;
    }
    if (ct.get("obstacle") && ct.get("target"))
        rd.fail(&ct, w + " takes an obstacle (rigid) or a target tag (two bodies), not both");
    if (!ct.get("obstacle") && !ct.get("target"))
        rd.fail(&ct, w + " needs an obstacle (rigid) or a target tag (two bodies)");
    return c;
}

/// A two-body pair: target tag, element kind, facet integration, search radius, match tolerance.
void read_target(const Reader& rd, const toml::table& ct, const std::string& w,
                 const levels::Problem& p, levels::ContactPair& c) {
    c.target = rd.string(ct, "target", w);
    if (!p.mesh0.find_tag(c.target))
        rd.fail(ct.get("target"), w + ": unknown target tag '" + c.target + "'");
    check_tag(rd, p.mesh0, ct, c.target, w, true, "target");
    if (c.target == c.contactor)
        rd.fail(ct.get("target"), w + ": the target tag is the contactor tag");
    read_two_body_keys(rd, ct, w, c);
}

/// A rigid obstacle: a line (point, normal) or a circle (center, radius, side), facing the body.
void read_obstacle(const Reader& rd, const toml::table& ct, const std::string& w,
                   const levels::Problem& p, levels::ContactPair& c) {
    for (const char* k : {"element", "integration", "search_radius", "match_tolerance"})
        if (ct.get(k))
            rd.fail(ct.get(k), w + ": '" + std::string(k) +
                                   "' applies to two-body pairs (with a target), not to an "
                                   "obstacle");
    const toml::table& ot = rd.table(rd.need(ct, "obstacle", w), w + ".obstacle");
    const std::string ow = w + ".obstacle";
    const std::string type = rd.string(ot, "type", ow);
    contact::Obstacle o;
    if (type == "line") {
        rd.check_keys(ot, {"type", "point", "normal"}, ow);
        o.kind = contact::Obstacle::Kind::line;
        o.point = rd.vec2(ot, "point", ow);
        o.normal = rd.vec2(ot, "normal", ow);
    } else if (type == "circle") {
        rd.check_keys(ot, {"type", "center", "radius", "side"}, ow);
        o.kind = contact::Obstacle::Kind::circle;
        o.center = rd.vec2(ot, "center", ow);
        o.radius = rd.number(ot, "radius", ow);
        const std::string side = rd.string_or(ot, "side", "outside", ow);
        if (side != "outside" && side != "inside")
            rd.fail(ot.get("side"), ow + ".side must be \"outside\" or \"inside\"");
        o.body_outside = side == "outside";
    } else {
        rd.fail(ot.get("type"),
                ow + ".type must be \"line\" or \"circle\", found \"" + type + "\"");
    }
    at(rd, &ot, [&] {
        o.validate();
        return 0;
    });
    if (const std::string why = obstacle_faces_away(p, c.contactor, o); !why.empty())
        rd.fail(&ot, ow + ": " + why);
    c.obstacle = o;
}

} // namespace

void parse_contacts(const Reader& rd, const toml::table& root, levels::Problem& p) {
    // Default augmentation: r = r_over_E x the smallest Young's modulus of the scene. The softer
    // body governs the compliance of a contact pair; scaling r with the stiffer one makes r many
    // times the soft body's stiffness when the moduli differ (at a contrast of 1e6 the statuses
    // cycle and Newton does not converge), while a smaller r only costs iterations.
    const double Emin = p.min_young_modulus();
    for (const toml::table* ct : rd.tables(root, "contact", "the scene")) {
        const std::string w = "[[contact]]";
        levels::ContactPair c = read_pair_common(rd, *ct, w, p, Emin);
        if (ct->get("target"))
            read_target(rd, *ct, w, p, c);
        else
            read_obstacle(rd, *ct, w, p, c);
        p.contacts.push_back(c);
    }
}

} // namespace mlc::scene::detail
