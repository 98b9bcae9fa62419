// SPDX-License-Identifier: MIT
// Scene parsing with toml++; every key is checked against the schema documented in README.md.
#include "scene/scene.hpp"

#include "core/check.hpp"
#include "levels/diagnoses.hpp"
#include "levels/level.hpp"
#include "levels/resources.hpp"
#include "mesh/mesh.hpp"
#ifdef MLC_HAVE_CGAL
#include "mesh/cgal/domain_mesher.hpp"
#endif
#include "mesh/io/gmsh.hpp"
#include "mesh/transform.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <toml++/toml.h>

namespace mlc::scene {

namespace detail {
const std::map<std::string, std::string>& builtin_scenes(); // generated
const std::map<std::string, std::string>& builtin_files();  // generated: scenes/*.msh
} // namespace detail

namespace {

constexpr int kMaxLevels = 12; // [scene].levels and the levels a Gmsh mesh is read with

using levels::Problem;

/// Parsing context: the origin for messages and typed getters that fail with file:line.
class Reader {
public:
    explicit Reader(std::string origin, StopPoll stop = {})
        : origin_(std::move(origin)), stop_(std::move(stop)) {}

    [[noreturn]] void fail(const toml::node* n, const std::string& msg) const {
        std::ostringstream os;
        os << origin_;
        if (n && n->source().begin.line > 0) os << ":" << n->source().begin.line;
        os << ": " << msg;
        throw InvalidInput(os.str());
    }

    void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                    const std::string& where) const {
        for (auto&& [k, v] : t) {
            bool ok = false;
            for (auto a : allowed)
                ok = ok || k.str() == a;
            if (!ok) {
                std::string list;
                for (auto a : allowed)
                    list += (list.empty() ? "" : ", ") + std::string(a);
                std::ostringstream os;
                os << origin_ << ":" << k.source().begin.line << ": unknown key '" << k.str()
                   << "' in " << where << " (allowed: " << list << ")";
                throw InvalidInput(os.str());
            }
        }
    }

    const toml::node* need(const toml::table& t, std::string_view key,
                           const std::string& where) const {
        const toml::node* n = t.get(key);
        if (!n) fail(&t, "missing key '" + std::string(key) + "' in " + where);
        return n;
    }

    double number(const toml::node* n, const std::string& what) const {
        if (auto d = n->value_exact<double>()) return finite(*d, n, what);
        if (auto i = n->value_exact<int64_t>()) return static_cast<double>(*i);
        fail(n, what + " must be a number, found " + type_name(n));
    }
    double number(const toml::table& t, std::string_view key, const std::string& where) const {
        return number(need(t, key, where), where + "." + std::string(key));
    }
    double number_or(const toml::table& t, std::string_view key, double dflt,
                     const std::string& where) const {
        const toml::node* n = t.get(key);
        return n ? number(n, where + "." + std::string(key)) : dflt;
    }
    std::optional<double> optional_number(const toml::table& t, std::string_view key,
                                          const std::string& where) const {
        const toml::node* n = t.get(key);
        if (!n) return std::nullopt;
        return number(n, where + "." + std::string(key));
    }
    int integer(const toml::node* n, const std::string& what) const {
        if (auto i = n->value_exact<int64_t>()) {
            if (*i < -1000000000 || *i > 1000000000) fail(n, what + " is out of range");
            return static_cast<int>(*i);
        }
        fail(n, what + " must be an integer, found " + type_name(n));
    }
    int integer_or(const toml::table& t, std::string_view key, int dflt,
                   const std::string& where) const {
        const toml::node* n = t.get(key);
        return n ? integer(n, where + "." + std::string(key)) : dflt;
    }
    std::string string(const toml::node* n, const std::string& what) const {
        if (auto s = n->value_exact<std::string>()) return *s;
        fail(n, what + " must be a string, found " + type_name(n));
    }
    std::string string(const toml::table& t, std::string_view key, const std::string& where) const {
        return string(need(t, key, where), where + "." + std::string(key));
    }
    std::string string_or(const toml::table& t, std::string_view key, std::string dflt,
                          const std::string& where) const {
        const toml::node* n = t.get(key);
        return n ? string(n, where + "." + std::string(key)) : dflt;
    }
    bool boolean_or(const toml::table& t, std::string_view key, bool dflt,
                    const std::string& where) const {
        const toml::node* n = t.get(key);
        if (!n) return dflt;
        if (auto b = n->value_exact<bool>()) return *b;
        fail(n, where + "." + std::string(key) + " must be true or false, found " + type_name(n));
    }
    Vec2 vec2(const toml::node* n, const std::string& what) const {
        const toml::array* a = n->as_array();
        if (!a || a->size() != 2) fail(n, what + " must be an array of two numbers [x, y]");
        return {number(a->get(0), what + "[0]"), number(a->get(1), what + "[1]")};
    }
    Vec2 vec2(const toml::table& t, std::string_view key, const std::string& where) const {
        return vec2(need(t, key, where), where + "." + std::string(key));
    }
    /// A non-empty array of numbers.
    std::vector<double> numbers(const toml::node* n, const std::string& what) const {
        const toml::array* a = n->as_array();
        if (!a || a->empty()) fail(n, what + " must be a non-empty array of numbers");
        std::vector<double> out;
        for (size_t i = 0; i < a->size(); ++i)
            out.push_back(number(a->get(i), what + "[" + std::to_string(i) + "]"));
        return out;
    }
    const toml::table& table(const toml::node* n, const std::string& what) const {
        const toml::table* t = n->as_table();
        if (!t) fail(n, what + " must be a table, found " + type_name(n));
        return *t;
    }
    /// An array of tables ([[name]]) or a single table; empty when absent.
    std::vector<const toml::table*> tables(const toml::table& t, std::string_view key,
                                           const std::string& where) const {
        std::vector<const toml::table*> out;
        const toml::node* n = t.get(key);
        if (!n) return out;
        if (const toml::array* a = n->as_array()) {
            for (const auto& e : *a)
                out.push_back(&table(&e, where + "." + std::string(key)));
        } else {
            out.push_back(&table(n, where + "." + std::string(key)));
        }
        return out;
    }
    const std::string& origin() const { return origin_; }
    /// What the meshing of a domain polls (may be empty).
    const StopPoll& stop() const { return stop_; }

private:
    double finite(double d, const toml::node* n, const std::string& what) const {
        if (!std::isfinite(d)) fail(n, what + " must be finite");
        return d;
    }
    static std::string type_name(const toml::node* n) {
        switch (n->type()) {
        case toml::node_type::string:
            return "a string";
        case toml::node_type::integer:
            return "an integer";
        case toml::node_type::floating_point:
            return "a number";
        case toml::node_type::boolean:
            return "a boolean";
        case toml::node_type::array:
            return "an array";
        case toml::node_type::table:
            return "a table";
        default:
            return "a date/time";
        }
    }
    std::string origin_;
    StopPoll stop_;
};

/// Wraps a library InvalidInput with the scene position of the entry that caused it.
template <class F> auto at(const Reader& rd, const toml::node* n, F&& f) {
    try {
        return f();
    } catch (const InvalidInput& e) {
        rd.fail(n, e.what());
    }
}

#ifdef MLC_HAVE_CGAL
mesh::Segment parse_segment(const Reader& rd, const toml::table& t, const std::string& where) {
    rd.check_keys(t, {"type", "from", "to", "center", "ccw", "tag"}, where);
    mesh::Segment s;
    const std::string type = rd.string(t, "type", where);
    s.from = rd.vec2(t, "from", where);
    s.to = rd.vec2(t, "to", where);
    s.tag = rd.string(t, "tag", where);
    if (type == "line") {
        s.kind = mesh::Segment::Kind::line;
        if (t.get("center") || t.get("ccw")) rd.fail(&t, where + ": a line takes no center or ccw");
    } else if (type == "arc") {
        s.kind = mesh::Segment::Kind::arc;
        s.center = rd.vec2(t, "center", where);
        s.radius = (s.from - s.center).norm();
        s.ccw = rd.boolean_or(t, "ccw", true, where);
    } else {
        rd.fail(t.get("type"), where + ".type must be \"line\" or \"arc\", found \"" + type + "\"");
    }
    return s;
}
#endif

/// `transform = { rotate_deg = .., about = [x, y], translate = [x, y] }` of a mesh table.
std::optional<mesh::RigidMotion> parse_transform(const Reader& rd, const toml::table& t,
                                                 const std::string& where) {
    const toml::node* n = t.get("transform");
    if (!n) return std::nullopt;
    const std::string w = where + ".transform";
    const toml::table& tt = rd.table(n, w);
    rd.check_keys(tt, {"rotate_deg", "about", "translate"}, w);
    if (tt.empty()) rd.fail(n, w + " is empty: give rotate_deg and/or translate");
    mesh::RigidMotion m;
    m.rotate_deg = rd.number_or(tt, "rotate_deg", 0.0, w);
    if (std::abs(m.rotate_deg) > 3600)
        rd.fail(tt.get("rotate_deg"), w + ".rotate_deg must lie in [-3600, 3600]");
    if (tt.get("about")) m.about = rd.vec2(tt, "about", w);
    if (tt.get("translate")) m.translate = rd.vec2(tt, "translate", w);
    return m;
}

/// `arcs = [ { tag = "..", center = [x, y], radius = r } ]` of a Gmsh mesh (global frame): the
/// boundary edges with the tag get the circle, so that refinement puts new vertices on it.
void apply_arcs(const Reader& rd, const toml::table& t, const std::string& where, mesh::Mesh& m) {
    const toml::node* n = t.get("arcs");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a || a->empty())
        rd.fail(n, where + ".arcs must be a non-empty array of tables { tag, center, radius }");
    std::set<std::string> seen;
    for (size_t i = 0; i < a->size(); ++i) {
        const std::string w = where + ".arcs[" + std::to_string(i) + "]";
        const toml::table& at = rd.table(a->get(i), w);
        rd.check_keys(at, {"tag", "center", "radius"}, w);
        const std::string tag = rd.string(at, "tag", w);
        const Vec2 center = rd.vec2(at, "center", w);
        const double radius = rd.number(at, "radius", w);
        if (!(radius > 0)) rd.fail(at.get("radius"), w + ".radius must be > 0");
        const auto id = m.find_tag(tag);
        if (!id || !m.is_boundary_tag(*id)) {
            std::string known;
            for (const auto& [name, k] : m.tag_names)
                if (m.is_boundary_tag(k)) known += (known.empty() ? "" : ", ") + name;
            rd.fail(at.get("tag"),
                    w + ".tag: the mesh has no boundary tag '" + tag + "' (it has: " + known + ")");
        }
        if (!seen.insert(tag).second)
            rd.fail(at.get("tag"), w + ".tag '" + tag + "' is declared twice");
        // Every vertex of the tagged edges must lie on the circle (the mesher put it there).
        const double tol = 1e-6 * radius;
        for (int v : m.vertices_with_tag(*id)) {
            const Vec2& p = m.vertices[static_cast<size_t>(v)];
            const double off = std::abs((p - center).norm() - radius);
            if (off > tol) {
                std::ostringstream os;
                os << w << ": vertex (" << p.x() << ", " << p.y() << ") of tag '" << tag
                   << "' lies " << off << " off the circle (center (" << center.x() << ", "
                   << center.y() << "), radius " << radius
                   << "); the arc's center and radius are in the global frame (after any "
                      "transform)";
                rd.fail(at.get("center"), os.str());
            }
        }
        const int c = static_cast<int>(m.circles.size());
        m.circles.push_back({center, radius});
        for (auto& e : m.boundary)
            if (e.tag == *id) e.curve = c;
    }
}

mesh::Mesh parse_mesh_local(const Reader& rd, const toml::table& t, const std::string& where,
                            const std::filesystem::path& base_dir,
                            const std::optional<mesh::RigidMotion>& motion);

/// A body's mesh: built in its own frame, mirrored (mirror_x), moved (transform), then the arcs
/// of a Gmsh mesh declared (in the global frame).
mesh::Mesh parse_mesh(const Reader& rd, const toml::table& t, const std::string& where,
                      const std::filesystem::path& base_dir) {
    const auto motion = parse_transform(rd, t, where);
    mesh::Mesh m = parse_mesh_local(rd, t, where, base_dir, motion);
    if (motion) {
        if (const toml::node* mx = t.get("mirror_x"); mx && !motion->keeps_axes()) {
            std::ostringstream os;
            os << where << ".transform: rotate_deg = " << motion->rotate_deg
               << " turns the mirror line x = " << rd.number(mx, where + ".mirror_x")
               << " of mirror_x off the coordinate axes, where supports act (ux, uy); rotate by "
                  "a multiple of 90 degrees, or mesh the whole body without mirror_x";
            rd.fail(t.get("transform"), os.str());
        }
        mesh::transform_mesh(m, *motion);
    }
    if (t.get("arcs")) apply_arcs(rd, t, where, m);
    return m;
}

mesh::Mesh parse_mesh_local(const Reader& rd, const toml::table& t, const std::string& where,
                            const std::filesystem::path& base_dir,
                            const std::optional<mesh::RigidMotion>& motion) {
    const std::string type = rd.string(t, "type", where);
    if (type != "gmsh" && t.get("arcs"))
        rd.fail(t.get("arcs"), where + ".arcs applies to type \"gmsh\" only (a \"domain\" "
                                       "declares its arcs in its loops)");
    if (type == "rectangle") {
        rd.check_keys(t, {"type", "corner", "size", "divisions", "diagonal", "transform"}, where);
        const Vec2 corner = rd.vec2(t, "corner", where);
        const Vec2 size = rd.vec2(t, "size", where);
        const toml::node* dn = rd.need(t, "divisions", where);
        const toml::array* da = dn->as_array();
        if (!da || da->size() != 2) rd.fail(dn, where + ".divisions must be [nx, ny]");
        const int nx = rd.integer(da->get(0), where + ".divisions[0]");
        const int ny = rd.integer(da->get(1), where + ".divisions[1]");
        const std::string diag = rd.string_or(t, "diagonal", "right", where);
        mesh::Diagonal d = mesh::Diagonal::right;
        if (diag == "left")
            d = mesh::Diagonal::left;
        else if (diag == "alternate")
            d = mesh::Diagonal::alternate;
        else if (diag != "right")
            rd.fail(t.get("diagonal"),
                    where + ".diagonal must be \"right\", \"left\" or \"alternate\"");
        if (nx < 1 || ny < 1 || nx > 100000 || ny > 100000)
            rd.fail(dn, where + ".divisions must be between 1 and 100000");
        return at(rd, &t, [&] { return mesh::structured_rectangle(corner, size, nx, ny, d); });
    }
    if (type == "domain") {
#ifdef MLC_HAVE_CGAL
        rd.check_keys(t,
                      {"type", "max_size", "min_size", "focus", "grading", "loop", "mirror_x",
                       "transform", "lines"},
                      where);
        mesh::SizeField sf;
        sf.max_size = rd.number(t, "max_size", where);
        sf.min_size = rd.number_or(t, "min_size", sf.max_size, where);
        sf.grading = rd.number_or(t, "grading", sf.grading, where);
        if (const toml::node* f = t.get("focus")) {
            const toml::array* fa = f->as_array();
            if (!fa) rd.fail(f, where + ".focus must be an array of points");
            // Focus points are global (after the transform): back to the domain's own frame.
            // With mirror_x the half is meshed and reflected: it is refined toward a focus
            // point and toward the point's image, which keeps the mesh mirror-symmetric.
            for (const auto& p : *fa) {
                const Vec2 q = motion ? motion->inverse(rd.vec2(&p, where + ".focus[]"))
                                      : rd.vec2(&p, where + ".focus[]");
                sf.focus.push_back(q);
                if (const toml::node* mx = t.get("mirror_x"); mx && motion) {
                    const double x0 = rd.number(mx, where + ".mirror_x");
                    if (q.x() != x0) sf.focus.emplace_back(2.0 * x0 - q.x(), q.y());
                }
            }
        }
        std::vector<std::vector<mesh::Segment>> loops;
        const auto loop_tables = rd.tables(t, "loop", where);
        if (loop_tables.empty()) rd.fail(&t, where + " needs at least one [[...loop]]");
        for (size_t i = 0; i < loop_tables.size(); ++i) {
            const std::string lw = where + ".loop[" + std::to_string(i) + "]";
            rd.check_keys(*loop_tables[i], {"segments"}, lw);
            const toml::node* sn = rd.need(*loop_tables[i], "segments", lw);
            const toml::array* sa = sn->as_array();
            if (!sa || sa->empty()) rd.fail(sn, lw + ".segments must be a non-empty array");
            std::vector<mesh::Segment> loop;
            for (size_t j = 0; j < sa->size(); ++j) {
                const std::string sw = lw + ".segments[" + std::to_string(j) + "]";
                loop.push_back(parse_segment(rd, rd.table(sa->get(j), sw), sw));
            }
            loops.push_back(std::move(loop));
        }
        // Constrained interior segments, in the domain's own frame like the loops.
        std::vector<mesh::Segment> lines;
        if (const toml::node* ln = t.get("lines")) {
            const toml::array* la = ln->as_array();
            if (!la || la->empty())
                rd.fail(ln, where + ".lines must be a non-empty array of tables { from, to, tag }");
            for (size_t j = 0; j < la->size(); ++j) {
                const std::string lw = where + ".lines[" + std::to_string(j) + "]";
                const toml::table& lt = rd.table(la->get(j), lw);
                rd.check_keys(lt, {"from", "to", "tag"}, lw);
                lines.push_back(mesh::Segment::line(rd.vec2(lt, "from", lw), rd.vec2(lt, "to", lw),
                                                    rd.string(lt, "tag", lw)));
                if (lines.back().tag.empty()) rd.fail(lt.get("tag"), lw + ".tag is empty");
            }
        }
        const toml::node* where_lines = t.get("lines")      ? t.get("lines")
                                        : t.get("mirror_x") ? t.get("mirror_x")
                                                            : &t;
        // The size of the mesh, predicted before meshing: a size field that cannot fit is
        // refused at once rather than after minutes of meshing.
        at(rd, &t, [&] {
            const mesh::MeshPrediction pred = mesh::predict_mesh_size(loops, sf);
            const double triangles = (t.get("mirror_x") ? 2 : 1) * pred.triangles;
            std::ostringstream what, fix;
            what << std::setprecision(3) << where << ": the mesh is predicted at about "
                 << triangles << " triangles (" << mesh::kTrianglesPerUnitIntegral
                 << " x the integral of 1/h^2 over the domain of area " << pred.area
                 << (t.get("mirror_x") ? ", mirrored" : "") << ", max_size = " << sf.max_size
                 << ", min_size = " << sf.min_size << ", grading = " << sf.grading << ", "
                 << sf.focus.size() << " focus point(s))";
            fix << "raise min_size and max_size"
                << (sf.min_size < sf.max_size && !sf.focus.empty() ? " (or the grading)" : "");
            levels::check_meshing_fits(triangles, what.str(), fix.str(),
                                       levels::process_memory_limit());
            return 0;
        });
        if (const toml::node* mx = t.get("mirror_x")) {
            const double x0 = rd.number(mx, where + ".mirror_x");
            const mesh::Mesh half =
                at(rd, where_lines, [&] { return mesh::mesh_domain(loops, sf, lines, rd.stop()); });
            return at(rd, mx, [&] { return mesh::mirror_about_x(half, x0); });
        }
        return at(rd, where_lines, [&] { return mesh::mesh_domain(loops, sf, lines, rd.stop()); });
#else
        rd.fail(&t, where + ": type \"domain\" needs CGAL (this build has MLC_WITH_CGAL=OFF)");
#endif
    }
    if (type == "gmsh") {
        rd.check_keys(t, {"type", "file", "surface", "transform", "arcs"}, where);
        std::filesystem::path file = rd.string(t, "file", where);
        const std::string surface = rd.string_or(t, "surface", "", where);
        // A built-in scene's mesh is compiled in with it (scenes/*.msh).
        if (rd.origin().rfind("builtin:", 0) == 0 && file.is_relative() && base_dir.empty()) {
            const auto& files = detail::builtin_files();
            if (const auto it = files.find(file.string()); it != files.end())
                return at(rd, &t, [&] {
                    return mesh::read_gmsh_text(it->second, "builtin:" + file.string(), surface);
                });
        }
        if (file.is_relative() && !base_dir.empty()) file = base_dir / file;
        return at(rd, &t, [&] { return mesh::read_gmsh(file, surface); });
    }
    rd.fail(t.get("type"),
            where + ".type must be \"rectangle\", \"domain\" or \"gmsh\", found \"" + type + "\"");
}

// A Gmsh mesh that is a uniform 1->4 refinement (Gmsh's RefineMesh, `gmsh -refine`, `mlcontact
// show --msh-level`) is read as a coarse ancestor and the levels between: coarse-to-fine Newton
// and the multigrid then have the hierarchy a built-in scene has. The ancestors are found by
// mesh::unrefine (its vertices within tol of the file's: exact for a file written with 17
// digits; tol also allows the rounding of coordinates far from the origin); the coarsest one on
// which the scene's level 0 builds (its support points are vertices, every contact pair finds
// contactor nodes, matching node pairs match) becomes mesh0. Called on a parsed, valid problem.
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
    for (int t = 0; t < m.n_triangles(); ++t)
        for (int v : m.triangles[static_cast<size_t>(t)])
            vbody[static_cast<size_t>(v)] = body_of(t);
    std::set<int> bodies;
    for (int v : m.vertices_with_tag(*tid))
        bodies.insert(vbody[static_cast<size_t>(v)]);
    for (int b : bodies) {
        double total = 0.0, behind = 0.0;
        for (int t = 0; t < m.n_triangles(); ++t) {
            if (body_of(t) != b) continue;
            const auto& tri = m.triangles[static_cast<size_t>(t)];
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
            const double a = std::abs(m.signed_area(t));
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

void recover_levels(levels::Problem& p) {
    Vec2 lo = p.mesh0.vertices.front(), hi = lo;
    double far = 0.0;
    for (const Vec2& v : p.mesh0.vertices) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
        far = std::max(far, v.cwiseAbs().maxCoeff());
    }
    const double tol = std::max(1e-10 * (hi - lo).norm(), 1e-14 * far);
    std::vector<mesh::Mesh> ancestors; // ancestors[i]: the file's mesh unrefined i + 1 times
    const mesh::Mesh* m = &p.mesh0;
    while (p.levels + static_cast<int>(ancestors.size()) < kMaxLevels) {
        std::optional<mesh::Mesh> c = mesh::unrefine(*m, tol);
        if (!c) break;
        try {
            mesh::check_quality(*c);
        } catch (const InvalidInput&) {
            break; // an ancestor our checks refuse is not used, nor are coarser ones
        }
        ancestors.push_back(std::move(*c));
        m = &ancestors.back();
    }
    for (auto k = static_cast<int>(ancestors.size()); k >= 1; --k) {
        mesh::Mesh& a = ancestors[static_cast<size_t>(k) - 1];
        std::swap(p.mesh0, a); // level 0 reads mesh0 too (the contact search's level-0 facets)
        try {
            (void)levels::build_level(p, p.mesh0);
        } catch (const InvalidInput&) {
            std::swap(p.mesh0, a);
            continue; // e.g. a support point that is no vertex of this ancestor: a finer one
        }
        p.levels += k;
        p.recovered_levels = k;
        return;
    }
}

} // namespace

levels::Problem parse_scene(const std::string& text, const std::string& origin,
                            const std::filesystem::path& base_dir, const StopPoll& stop) {
    Reader rd(origin, stop);
    toml::table root;
    try {
        root = toml::parse(text, origin);
    } catch (const toml::parse_error& e) {
        std::ostringstream os;
        os << origin << ":" << e.source().begin.line << ": malformed TOML: " << e.description();
        throw InvalidInput(os.str());
    }
    rd.check_keys(root, {"scene", "body", "load", "support", "contact", "newton"}, "the scene");
    Problem p;
    fem::Plane plane = fem::Plane::strain;
    bool recover = true;                      // [scene].recover_levels
    const toml::node* recover_node = nullptr; // where it was stated, if it was
    bool all_gmsh = true;                     // every body's mesh read from a Gmsh file
    {
        const toml::node* sn = rd.need(root, "scene", "the scene");
        const toml::table& s = rd.table(sn, "[scene]");
        rd.check_keys(
            s, {"name", "description", "units", "plane", "load_steps", "levels", "recover_levels"},
            "[scene]");
        if (const toml::node* rn = s.get("recover_levels")) {
            recover_node = rn;
            recover = rd.boolean_or(s, "recover_levels", true, "[scene]");
        }
        p.name = rd.string(s, "name", "[scene]");
        p.description = rd.string_or(s, "description", "", "[scene]");
        p.units = rd.string_or(s, "units", "", "[scene]");
        const std::string pl = rd.string_or(s, "plane", "strain", "[scene]");
        if (pl == "stress")
            plane = fem::Plane::stress;
        else if (pl != "strain")
            rd.fail(s.get("plane"),
                    "[scene].plane must be \"strain\" or \"stress\", found \"" + pl + "\"");
        p.load_steps = rd.integer_or(s, "load_steps", 1, "[scene]");
        if (p.load_steps < 1)
            rd.fail(s.get("load_steps"),
                    "[scene].load_steps must be at least 1, found " + std::to_string(p.load_steps));
        p.levels = rd.integer_or(s, "levels", 0, "[scene]");
        if (p.levels < 0 || p.levels > kMaxLevels)
            rd.fail(s.get("levels"), "[scene].levels must lie in [0, 12]");
    }
    const auto bodies = rd.tables(root, "body", "the scene");
    if (bodies.empty()) rd.fail(&root, "the scene defines no [[body]]");
    for (size_t i = 0; i < bodies.size(); ++i) {
        const toml::table& b = *bodies[i];
        const std::string w = "[[body]] " + std::to_string(i + 1);
        rd.check_keys(b, {"name", "E", "nu", "body_force", "mesh", "tags"}, w);
        levels::Body body;
        body.name = rd.string_or(b, "name", "body" + std::to_string(i + 1), w);
        body.material.E = rd.number(b, "E", w);
        body.material.nu = rd.number(b, "nu", w);
        body.material.plane = plane;
        at(rd, b.get("E"), [&] {
            body.material.validate();
            return 0;
        });
        if (b.get("body_force")) body.body_force = rd.vec2(b, "body_force", w);
        const toml::node* mn = rd.need(b, "mesh", w);
        const toml::table& mt = rd.table(mn, w + ".mesh");
        if (mt["type"].value_or(std::string()) != "gmsh") all_gmsh = false;
        mesh::Mesh m = parse_mesh(rd, mt, w + ".mesh", base_dir);
        if (const toml::node* tn = b.get("tags")) {
            // Renames this body's boundary tags before merging (tags merge by name).
            const toml::table& tt = rd.table(tn, w + ".tags");
            std::map<int, std::string> new_name; // tag id -> new name
            for (auto&& [k, v] : tt) {
                const std::string from(k.str());
                const std::string to = rd.string(&v, w + ".tags." + from);
                if (!m.find_tag(from)) {
                    std::string known;
                    for (const auto& [n, id] : m.tag_names)
                        known += (known.empty() ? "" : ", ") + n;
                    rd.fail(&v, w + ".tags: the body's mesh has no tag '" + from +
                                    "' (it has: " + known + ")");
                }
                if (to.empty()) rd.fail(&v, w + ".tags." + from + ": the new name is empty");
                new_name[m.tag(from)] = to;
            }
            // Tags that end up with one name are merged (as tags of two bodies are).
            std::map<std::string, int> names;
            std::map<int, int> merged; // tag id -> id it merges into
            for (const auto& [name, id] : m.tag_names) {
                const auto it = new_name.find(id);
                const std::string n = it == new_name.end() ? name : it->second;
                const auto [pos, inserted] = names.emplace(n, id);
                if (!inserted) merged[id] = pos->second;
            }
            for (auto* edges : {&m.boundary, &m.lines})
                for (auto& e : *edges)
                    if (const auto it = merged.find(e.tag); it != merged.end()) e.tag = it->second;
            m.tag_names = std::move(names);
        }
        mesh::merge_into(p.mesh0, m, static_cast<int>(i));
        p.bodies.push_back(body);
    }
    at(rd, &root, [&] {
        mesh::check_quality(p.mesh0);
        return 0;
    });
    if (recover_node != nullptr && recover && !all_gmsh)
        rd.fail(recover_node, "[scene].recover_levels applies to meshes read from Gmsh files "
                              "(type = \"gmsh\"), and a body here has another mesh");
    // Loads and contact pairs need a tag on boundary edges; supports may also name a tagged
    // interior line (Mesh::lines).
    auto check_tag = [&](const toml::table& t, const std::string& tag, const std::string& w,
                         bool boundary_only = true, const char* key = "tag") {
        const toml::node* n = t.get(key) ? t.get(key) : &t;
        const auto id = p.mesh0.find_tag(tag);
        if (!id || (boundary_only && !p.mesh0.is_boundary_tag(*id))) {
            std::string known;
            for (const auto& [name, k] : p.mesh0.tag_names)
                if (!boundary_only || p.mesh0.is_boundary_tag(k))
                    known += (known.empty() ? "" : ", ") + name;
            if (id)
                rd.fail(n, w + ": tag '" + tag + "' names interior lines only; " + key +
                               " needs a boundary tag (the mesh has: " + known + ")");
            rd.fail(n, w + ": unknown " + (boundary_only ? "boundary " : "") + "tag '" + tag +
                           "' (the mesh has: " + known + ")");
        }
    };
    for (const toml::table* lt : rd.tables(root, "load", "the scene")) {
        const std::string w = "[[load]]";
        rd.check_keys(*lt, {"tag", "pressure", "traction", "factors"}, w);
        levels::Load ld;
        ld.tag = rd.string(*lt, "tag", w);
        check_tag(*lt, ld.tag, w);
        ld.pressure = rd.number_or(*lt, "pressure", 0.0, w);
        if (lt->get("traction")) ld.traction = rd.vec2(*lt, "traction", w);
        if (!lt->get("pressure") && !lt->get("traction"))
            rd.fail(lt, w + " needs a pressure or a traction");
        if (const toml::node* fn = lt->get("factors")) ld.factors = rd.numbers(fn, w + ".factors");
        p.loads.push_back(ld);
    }
    std::vector<std::pair<size_t, const toml::node*>> active_nodes; // support index, its node
    for (const toml::table* st : rd.tables(root, "support", "the scene")) {
        const std::string w = "[[support]]";
        rd.check_keys(*st, {"tag", "point", "ux", "uy", "active"}, w);
        levels::Support s;
        if (st->get("tag") && st->get("point"))
            rd.fail(st, w + " takes a tag or a point, not both");
        if (st->get("tag")) {
            s.tag = rd.string(*st, "tag", w);
            check_tag(*st, s.tag, w, false);
        } else if (st->get("point")) {
            s.point = rd.vec2(*st, "point", w);
        } else {
            rd.fail(st, w + " needs a tag or a point");
        }
        // A number (proportional to the load parameter) or a list of values per path point.
        for (int c = 0; c < 2; ++c) {
            const char* key = c == 0 ? "ux" : "uy";
            const toml::node* n = st->get(key);
            if (!n) continue;
            auto& full = c == 0 ? s.ux : s.uy;
            auto& path = c == 0 ? s.ux_path : s.uy_path;
            if (n->is_array()) {
                path = rd.numbers(n, w + "." + key);
                full = path.back();
            } else {
                full = rd.number(n, w + "." + key);
            }
        }
        if (!s.ux && !s.uy) rd.fail(st, w + " fixes nothing: give ux and/or uy");
        if (const toml::node* an = st->get("active")) {
            // Per point of the loading path: true holds the support there, false releases it.
            const toml::array* a = an->as_array();
            if (!a || a->empty())
                rd.fail(an, w + ".active must be an array of true/false, one per point of the "
                                "loading path (per load step when load_steps is their number)");
            active_nodes.emplace_back(p.supports.size(), an);
            for (size_t k = 0; k < a->size(); ++k) {
                const auto b = a->get(k)->value_exact<bool>();
                if (!b)
                    rd.fail(a->get(k),
                            w + ".active[" + std::to_string(k) + "] must be true or false");
                s.active.push_back(*b);
            }
        }
        p.supports.push_back(s);
    }
    // Every per-point list has the length K of the loading path; name the `active` that differs.
    for (const auto& [i, an] : active_nodes) {
        const int K = p.n_path_points();
        const size_t n = p.supports[i].active.size();
        if (static_cast<int>(n) != K)
            rd.fail(an, "[[support]].active has " + std::to_string(n) +
                            " entries but the loading path has " + std::to_string(K) +
                            " points (the length of the scene's other per-step lists: factors, "
                            "ux/uy lists, active); give one per point");
    }
    // Default augmentation: r = r_over_E x the smallest Young's modulus of the scene. The softer
    // body governs the compliance of a contact pair; scaling r with the stiffer one makes r many
    // times the soft body's stiffness when the moduli differ (extremes study, contrast 1e6: the
    // statuses cycle and Newton does not converge), while a smaller r only costs iterations.
    const double Emin = p.min_young_modulus();
    for (const toml::table* ct : rd.tables(root, "contact", "the scene")) {
        const std::string w = "[[contact]]";
        rd.check_keys(*ct,
                      {"name", "contactor", "region", "mu", "r", "r_over_E", "obstacle", "target",
                       "element", "integration", "search_radius", "match_tolerance"},
                      w);
        levels::ContactPair c;
        c.name = rd.string_or(*ct, "name", "contact" + std::to_string(p.contacts.size() + 1), w);
        c.contactor = rd.string(*ct, "contactor", w);
        if (!p.mesh0.find_tag(c.contactor))
            rd.fail(ct->get("contactor"), w + ": unknown contactor tag '" + c.contactor + "'");
        check_tag(*ct, c.contactor, w, true, "contactor");
        c.mu = rd.number(*ct, "mu", w);
        if (c.mu < 0)
            rd.fail(ct->get("mu"),
                    w + ": friction coefficient mu must be >= 0, found " + std::to_string(c.mu));
        if (ct->get("r") && ct->get("r_over_E")) rd.fail(ct, w + " takes r or r_over_E, not both");
        if (ct->get("r"))
            c.r = rd.number(*ct, "r", w);
        else
            c.r = rd.number_or(*ct, "r_over_E", 0.1, w) * Emin;
        if (!(c.r > 0))
            rd.fail(ct->get("r") ? ct->get("r") : ct->get("r_over_E"),
                    w + ": augmentation parameter r must be > 0");
        if (const std::string why = levels::r_out_of_scale(c.r, Emin); !why.empty())
            rd.fail(ct->get("r") ? ct->get("r") : ct->get("r_over_E"), w + ": " + why);
        if (const toml::node* rn = ct->get("region")) {
            const toml::table& rt = rd.table(rn, w + ".region");
            rd.check_keys(rt, {"min", "max"}, w + ".region");
            levels::Box box;
            if (rt.get("min")) box.lo = rd.vec2(rt, "min", w + ".region");
            if (rt.get("max")) box.hi = rd.vec2(rt, "max", w + ".region");
            c.region = box;
        }
        if (ct->get("obstacle") && ct->get("target"))
            rd.fail(ct, w + " takes an obstacle (rigid) or a target tag (two bodies), not both");
        if (!ct->get("obstacle") && !ct->get("target"))
            rd.fail(ct, w + " needs an obstacle (rigid) or a target tag (two bodies)");
        if (ct->get("target")) {
            c.target = rd.string(*ct, "target", w);
            if (!p.mesh0.find_tag(c.target))
                rd.fail(ct->get("target"), w + ": unknown target tag '" + c.target + "'");
            check_tag(*ct, c.target, w, true, "target");
            if (c.target == c.contactor)
                rd.fail(ct->get("target"), w + ": the target tag is the contactor tag");
            const std::string el = rd.string_or(*ct, "element", "node_on_facet", w);
            if (el == "node_on_facet")
                c.element = levels::ContactElementKind::node_on_facet;
            else if (el == "node_on_node")
                c.element = levels::ContactElementKind::node_on_node;
            else
                rd.fail(ct->get("element"), w +
                                                ".element must be \"node_on_facet\" or "
                                                "\"node_on_node\", found \"" +
                                                el + "\"");
            const std::string integ = rd.string_or(*ct, "integration", "nodal", w);
            if (integ == "nodal")
                c.integration = contact::FacetIntegration::nodal;
            else if (integ == "segment")
                c.integration = contact::FacetIntegration::segment;
            else if (integ == "dual")
                c.integration = contact::FacetIntegration::dual;
            else
                rd.fail(ct->get("integration"), w +
                                                    ".integration must be \"nodal\", "
                                                    "\"segment\" or \"dual\", found \"" +
                                                    integ + "\"");
            if (c.integration != contact::FacetIntegration::nodal &&
                c.element != levels::ContactElementKind::node_on_facet)
                rd.fail(ct->get("integration"),
                        w + ".integration = \"" + integ +
                            "\" applies to element = \"node_on_facet\" only, not to \"" + el +
                            "\"");
            c.search_radius = rd.number_or(*ct, "search_radius", c.search_radius, w);
            if (!(c.search_radius > 0))
                rd.fail(ct->get("search_radius"), w + ".search_radius must be > 0");
            c.match_tolerance = rd.number_or(*ct, "match_tolerance", c.match_tolerance, w);
            if (!(c.match_tolerance > 0 && c.match_tolerance < 0.5))
                rd.fail(ct->get("match_tolerance"), w + ".match_tolerance must lie in (0, 0.5)");
            p.contacts.push_back(c);
            continue;
        }
        for (const char* k : {"element", "integration", "search_radius", "match_tolerance"})
            if (ct->get(k))
                rd.fail(ct->get(k), w + ": '" + std::string(k) +
                                        "' applies to two-body pairs (with a target), not to an "
                                        "obstacle");
        const toml::table& ot = rd.table(rd.need(*ct, "obstacle", w), w + ".obstacle");
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
        p.contacts.push_back(c);
    }
    if (const toml::node* nn = root.get("newton")) {
        const toml::table& nt = rd.table(nn, "[newton]");
        rd.check_keys(nt, {"rel_tol", "max_iter", "forcing"}, "[newton]");
        p.newton.rel_tol = rd.number_or(nt, "rel_tol", p.newton.rel_tol, "[newton]");
        p.newton.max_iter = rd.integer_or(nt, "max_iter", p.newton.max_iter, "[newton]");
        p.newton.forcing = rd.number_or(nt, "forcing", p.newton.forcing, "[newton]");
        at(rd, nn, [&] {
            p.newton.validate();
            return 0;
        });
    }
    at(rd, &root, [&] {
        p.validate();
        return 0;
    });
    if (recover && all_gmsh) recover_levels(p);
    return p;
}

std::vector<std::string> builtin_scene_names() {
    std::vector<std::string> out;
    for (const auto& [n, t] : detail::builtin_scenes())
        out.push_back(n);
    return out;
}

std::string builtin_scene_text(const std::string& name) {
    const auto& s = detail::builtin_scenes();
    auto it = s.find(name);
    return it == s.end() ? std::string() : it->second;
}

std::string builtin_file_text(const std::string& name) {
    const auto& f = detail::builtin_files();
    auto it = f.find(name);
    return it == f.end() ? std::string() : it->second;
}

levels::Problem load_scene(const std::string& name_or_path, const StopPoll& stop) {
    const std::filesystem::path path(name_or_path);
    const bool looks_like_file = path.extension() == ".toml" || path.has_parent_path();
    if (!looks_like_file || !std::filesystem::exists(path)) {
        const std::string text = builtin_scene_text(name_or_path);
        if (!text.empty()) return parse_scene(text, "builtin:" + name_or_path, {}, stop);
    }
    if (!std::filesystem::exists(path)) {
        std::string names;
        for (const auto& n : builtin_scene_names())
            names += (names.empty() ? "" : ", ") + n;
        throw InvalidInput("scene '" + name_or_path +
                           "' is neither a readable file nor a built-in scene (built-in: " + names +
                           ")");
    }
    MLC_CHECK(std::filesystem::is_regular_file(path),
              "scene '" << name_or_path << "' is not a regular file");
    std::ifstream in(path);
    MLC_CHECK(in.good(), "cannot read scene file '" << name_or_path << "'");
    std::stringstream ss;
    ss << in.rdbuf();
    return parse_scene(ss.str(), path.string(), path.parent_path(), stop);
}

} // namespace mlc::scene
