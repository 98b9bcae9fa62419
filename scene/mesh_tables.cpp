// SPDX-License-Identifier: MIT
// A body's mesh table of a scene: rectangle, domain (meshed by CGAL) or Gmsh file, with its
// transform, mirror and arcs.
#include "levels/resources.hpp"
#include "mesh/mesh.hpp"
#ifdef MLC_HAVE_CGAL
#include "mesh/cgal/domain_mesher.hpp"
#endif
#include "mesh/io/gmsh.hpp"
#include "mesh/transform.hpp"
#include "scene/reader.hpp"

#include <array>
#include <iomanip>
#include <set>

namespace mlc::scene::detail {

namespace {

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
        const int c = static_cast<int>(m.shapes.size());
        m.shapes.push_back({center, radius});
        for (auto& e : m.boundary)
            if (e.tag == *id) e.shape = c;
    }
}

/// `type = "rectangle"`: a structured rectangle (corner, size, divisions, diagonal).
mesh::Mesh read_rectangle(const Reader& rd, const toml::table& t, const std::string& where,
                          const std::filesystem::path& base_dir,
                          const std::optional<mesh::RigidMotion>& motion) {
    (void)base_dir;
    (void)motion;
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

/// `type = "domain"`: loops of segments meshed by CGAL along a size field (mesh/cgal).
mesh::Mesh read_domain(const Reader& rd, const toml::table& t, const std::string& where,
                       const std::filesystem::path& base_dir,
                       const std::optional<mesh::RigidMotion>& motion) {
    (void)base_dir;
    (void)motion; // used with CGAL only
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
        what << std::setprecision(3) << where << ": the mesh is predicted at about " << triangles
             << " triangles (" << mesh::kTrianglesPerUnitIntegral
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

/// `type = "gmsh"`: a Gmsh file (a built-in scene's compiled in), one physical surface or all.
mesh::Mesh read_gmsh_file(const Reader& rd, const toml::table& t, const std::string& where,
                          const std::filesystem::path& base_dir,
                          const std::optional<mesh::RigidMotion>& motion) {
    (void)motion;
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

/// The mesh types of a body's mesh table and their readers.
struct MeshType {
    std::string_view name;
    mesh::Mesh (*read)(const Reader&, const toml::table&, const std::string&,
                       const std::filesystem::path&, const std::optional<mesh::RigidMotion>&);
};
constexpr std::array<MeshType, 3> kMeshTypes{{
    {"rectangle", read_rectangle},
    {"domain", read_domain},
    {"gmsh", read_gmsh_file},
}};

mesh::Mesh parse_mesh_local(const Reader& rd, const toml::table& t, const std::string& where,
                            const std::filesystem::path& base_dir,
                            const std::optional<mesh::RigidMotion>& motion) {
    const std::string type = rd.string(t, "type", where);
    if (type != "gmsh" && t.get("arcs"))
        rd.fail(t.get("arcs"), where + ".arcs applies to type \"gmsh\" only (a \"domain\" "
                                       "declares its arcs in its loops)");
    for (const MeshType& mt : kMeshTypes)
        if (type == mt.name) return mt.read(rd, t, where, base_dir, motion);
    rd.fail(t.get("type"),
            where + ".type must be \"rectangle\", \"domain\" or \"gmsh\", found \"" + type + "\"");
}

} // namespace

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

} // namespace mlc::scene::detail
