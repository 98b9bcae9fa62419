// SPDX-License-Identifier: MIT
// 3D scenes ([scene] dimension = 3): a box or a Gmsh tetrahedral mesh (its curved surfaces
// declared), bodies, face loads, supports, contact pairs with rigid obstacles, load steps (along
// a loading path: per-point load factors and support values, as in 2D) and Newton settings, read
// with the Reader of the 2D scenes; keys of 2D scenes are refused as 2D-only.
#include "scene/scene3.hpp"

#include "contact/obstacle.hpp"
#include "core/check.hpp"
#include "levels/diagnoses.hpp"
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/tet_mesh.hpp"
#include "mesh/transform.hpp"
#include "scene/reader.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace mlc::scene {

namespace {

using detail::at;
using detail::Reader;
using levels::ElasticProblem3;
using mesh::Vec3;

/// Fails on the first key of `t` that is one of `two_d` (keys of 2D scenes), naming it.
void refuse_2d_only(const Reader& rd, const toml::table& t,
                    std::initializer_list<std::string_view> two_d, const std::string& where,
                    const std::string& why = "") {
    for (auto&& [k, v] : t)
        for (auto key : two_d)
            if (k.str() == key) {
                const std::string name =
                    where.empty() ? std::string(key) : where + "." + std::string(key);
                rd.fail(&v, name + " is 2D-only: a 3D scene ([scene] dimension = 3) has no " +
                                std::string(key) + (why.empty() ? "" : " (" + why + ")"));
            }
}

Vec3 vec3(const Reader& rd, const toml::node* n, const std::string& what) {
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) rd.fail(n, what + " must be an array of three numbers [x, y, z]");
    return {rd.number(a->get(0), what + "[0]"), rd.number(a->get(1), what + "[1]"),
            rd.number(a->get(2), what + "[2]")};
}
Vec3 vec3(const Reader& rd, const toml::table& t, std::string_view key, const std::string& w) {
    return vec3(rd, rd.need(t, key, w), w + "." + std::string(key));
}

/// Whether some tagged line of m carries tag id.
bool is_line_tag(const mesh::TetMesh& m, int id) {
    return std::any_of(m.lines.begin(), m.lines.end(),
                       [id](const mesh::BoundaryEdge& l) { return l.tag == id; });
}

/// The boundary tags of m (and, with lines_too, its line tags), for messages.
std::string known_tags(const mesh::TetMesh& m, bool lines_too) {
    std::string s;
    for (const auto& [name, id] : m.tag_names)
        if (m.is_boundary_tag(id) || (lines_too && is_line_tag(m, id)))
            s += (s.empty() ? "" : ", ") + name;
    return s.empty() ? "none" : s;
}

/// Refuses a tag that no boundary face (or, with lines_too, no tagged line) of m carries.
void check_tag3(const Reader& rd, const mesh::TetMesh& m, const toml::table& t,
                const std::string& tag, const std::string& w, bool lines_too) {
    const auto id = m.find_tag(tag);
    if (!id || !(m.is_boundary_tag(*id) || (lines_too && is_line_tag(m, *id))))
        rd.fail(t.get("tag"), w + ": unknown " + (lines_too ? "boundary or line" : "boundary") +
                                  " tag '" + tag + "' (the mesh has: " + known_tags(m, lines_too) +
                                  ")");
}

/// [scene]: name, description, units, dimension, load_steps, levels.
void read_scene3_table(const Reader& rd, const toml::table& root, ElasticProblem3& p) {
    const toml::table& s = rd.table(rd.need(root, "scene", "the scene"), "[scene]");
    refuse_2d_only(rd, s, {"plane", "recover_levels"}, "[scene]");
    rd.check_keys(s, {"name", "description", "units", "dimension", "load_steps", "levels"},
                  "[scene]");
    p.name = rd.string(s, "name", "[scene]");
    p.description = rd.string_or(s, "description", "", "[scene]");
    p.units = rd.string_or(s, "units", "", "[scene]");
    p.load_steps = rd.integer_or(s, "load_steps", 1, "[scene]");
    if (p.load_steps < 1)
        rd.fail(s.get("load_steps"),
                "[scene].load_steps must be at least 1, found " + std::to_string(p.load_steps));
    p.levels = rd.integer_or(s, "levels", 0, "[scene]");
    if (p.levels < 0 || p.levels > levels::kMaxLevels3)
        rd.fail(s.get("levels"), "[scene].levels must lie in [0, 12]");
}

/// `type = "box"`: a structured box of Kuhn-split cubes, faces tagged xmin .. zmax.
mesh::TetMesh read_box(const Reader& rd, const toml::table& t, const std::string& w) {
    refuse_2d_only(rd, t, {"diagonal", "transform", "mirror_x", "arcs"}, w);
    rd.check_keys(t, {"type", "corner", "size", "divisions"}, w);
    const Vec3 corner = vec3(rd, t, "corner", w);
    const Vec3 size = vec3(rd, t, "size", w);
    if (!(size.minCoeff() > 0)) rd.fail(t.get("size"), w + ".size must be positive");
    const toml::node* dn = rd.need(t, "divisions", w);
    const toml::array* da = dn->as_array();
    if (!da || da->size() != 3) rd.fail(dn, w + ".divisions must be [nx, ny, nz]");
    int n[3];
    for (int k = 0; k < 3; ++k) {
        n[k] = rd.integer(da->get(static_cast<size_t>(k)),
                          w + ".divisions[" + std::to_string(k) + "]");
        if (n[k] < 1 || n[k] > 1000) rd.fail(dn, w + ".divisions must be between 1 and 1000");
    }
    return at(rd, &t, [&] { return mesh::structured_box(corner, size, n[0], n[1], n[2]); });
}

/// The text of a Gmsh file of a body (a built-in scene's compiled in), and its name.
std::pair<std::string, std::string> gmsh_text(const Reader& rd, const toml::table& t,
                                              const std::string& w,
                                              const std::filesystem::path& base_dir) {
    std::filesystem::path file = rd.string(t, "file", w);
    if (rd.origin().rfind("builtin:", 0) == 0 && file.is_relative() && base_dir.empty()) {
        const std::string text = builtin_file_text(file.string());
        if (!text.empty()) return {text, "builtin:" + file.string()};
    }
    if (file.is_relative() && !base_dir.empty()) file = base_dir / file;
    std::ifstream in(file);
    if (!in) rd.fail(t.get("file"), w + ".file: cannot read '" + file.string() + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    return {ss.str(), file.string()};
}

/// A curved surface a Gmsh mesh table declares (`surface`), attached once the mesh is read.
struct DeclaredSurface {
    const toml::node* node = nullptr; ///< its entry, for messages
    std::string tag;
    mesh::CurvedSurface surface;
};

/// `surface = [{ tag, type = "sphere" | "cylinder", center, radius (, axis) }, ...]` of a Gmsh
/// mesh table, appended to `out`.
void read_surfaces(const Reader& rd, const toml::table& mt, const std::string& mw,
                   std::vector<DeclaredSurface>& out) {
    const toml::node* n = mt.get("surface");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a)
        rd.fail(n, mw + ".surface declares the curved faces of a 3D mesh: an array of tables "
                        "{ tag, type = \"sphere\" or \"cylinder\", center, radius (, axis) } (a "
                        "3D body selects its physical volume with `volume`)");
    for (size_t i = 0; i < a->size(); ++i) {
        const std::string w = mw + ".surface[" + std::to_string(i) + "]";
        const toml::table& t = rd.table(a->get(i), w);
        DeclaredSurface d;
        d.node = a->get(i);
        d.tag = rd.string(t, "tag", w);
        const std::string type = rd.string(t, "type", w);
        if (type == "sphere") {
            rd.check_keys(t, {"tag", "type", "center", "radius"}, w);
            d.surface.kind = mesh::CurvedSurface::Kind::sphere;
        } else if (type == "cylinder") {
            rd.check_keys(t, {"tag", "type", "center", "axis", "radius"}, w);
            d.surface.kind = mesh::CurvedSurface::Kind::cylinder;
            d.surface.axis = vec3(rd, t, "axis", w);
        } else {
            rd.fail(t.get("type"),
                    w + ".type must be \"sphere\" or \"cylinder\", found \"" + type + "\"");
        }
        d.surface.center = vec3(rd, t, "center", w);
        d.surface.radius = rd.number(t, "radius", w);
        if (!(d.surface.radius > 0))
            rd.fail(t.get("radius"),
                    w + ".radius must be > 0, found " + std::to_string(d.surface.radius));
        out.push_back(std::move(d));
    }
}

/// The bodies' meshes: boxes (faces renamed by `tags`, merged in body order), or the physical
/// volumes of one Gmsh file (a body each), with the curved surfaces their tables declare attached.
void read_bodies3(const Reader& rd, const toml::table& root, const std::filesystem::path& base,
                  ElasticProblem3& p) {
    const auto bodies = rd.tables(root, "body", "the scene");
    if (bodies.empty()) rd.fail(&root, "the scene defines no [[body]]");
    std::string file_text, file_name;
    std::map<int, int> body_of_volume; // physical volume tag -> body index
    std::vector<DeclaredSurface> surfaces;
    bool boxes = false; // some body is a box (then all are)
    for (size_t i = 0; i < bodies.size(); ++i) {
        const toml::table& b = *bodies[i];
        const std::string w = "[[body]] " + std::to_string(i + 1);
        rd.check_keys(b, {"name", "E", "nu", "body_force", "mesh", "tags"}, w);
        levels::Body3 body;
        body.name = rd.string_or(b, "name", "body" + std::to_string(i + 1), w);
        body.material.E = rd.number(b, "E", w);
        body.material.nu = rd.number(b, "nu", w);
        at(rd, b.get("E"), [&] {
            body.material.validate();
            return 0;
        });
        if (b.get("body_force")) body.body_force = vec3(rd, b, "body_force", w);
        const std::string mw = w + ".mesh";
        const toml::table& mt = rd.table(rd.need(b, "mesh", w), mw);
        const std::string type = rd.string(mt, "type", mw);
        if (type == "rectangle" || type == "domain")
            rd.fail(mt.get("type"), mw + ".type \"" + type +
                                        "\" is 2D-only: a 3D body's mesh is \"box\" or \"gmsh\"");
        if ((type == "box" && !file_name.empty()) || (type == "gmsh" && boxes))
            rd.fail(mt.get("type"), mw + ": the bodies of a 3D scene are either boxes or the "
                                         "physical volumes of one Gmsh file, not both");
        if (type == "box") {
            mesh::TetMesh m = read_box(rd, mt, mw);
            if (const toml::node* tn = b.get("tags")) rename_tags(rd, tn, w, m);
            if (bodies.size() == 1)
                p.mesh0 = std::move(m);
            else
                mesh::merge_into(p.mesh0, m, static_cast<int>(i));
            boxes = true;
        } else if (type == "gmsh") {
            if (b.get("tags"))
                rd.fail(b.get("tags"), w + ".tags renames a box's faces; a Gmsh body's faces "
                                           "are named by the file's physical surfaces");
            refuse_2d_only(rd, mt, {"transform", "arcs"}, mw,
                           "a 3D body selects a physical volume with `volume` and declares its "
                           "curved faces with `surface`");
            rd.check_keys(mt, {"type", "file", "volume", "surface"}, mw);
            read_surfaces(rd, mt, mw, surfaces);
            const auto file = gmsh_text(rd, mt, mw, base);
            std::string text = file.first, name = file.second;
            if (!file_name.empty() && name != file_name)
                rd.fail(mt.get("file"), mw +
                                            ".file: the bodies of a 3D scene are the physical "
                                            "volumes of one Gmsh file ('" +
                                            file_name + "')");
            const std::string volume = rd.string_or(mt, "volume", "", mw);
            if (volume.empty() && bodies.size() > 1)
                rd.fail(&mt, mw + " needs a volume: with several bodies, each is a physical "
                                  "volume of the file");
            if (!volume.empty()) {
                const mesh::TetMesh part = at(rd, mt.get("volume"), [&] {
                    return mesh::read_gmsh_tet_text(text, name, volume);
                });
                body_of_volume[part.attribute.at(0)] = static_cast<int>(i);
            }
            file_text = std::move(text);
            file_name = std::move(name);
        } else {
            rd.fail(mt.get("type"),
                    mw + ".type must be \"box\" or \"gmsh\", found \"" + type + "\"");
        }
        p.bodies.push_back(body);
    }
    if (boxes && bodies.size() > 1)
        at(rd, &root, [&] {
            mesh::check_quality(p.mesh0);
            return 0;
        });
    if (file_name.empty()) return;
    p.mesh0 = at(rd, &root, [&] { return mesh::read_gmsh_tet_text(file_text, file_name, ""); });
    for (const DeclaredSurface& d : surfaces)
        at(rd, d.node, [&] {
            mesh::attach_surface(p.mesh0, d.tag, d.surface);
            return 0;
        });
    if (body_of_volume.empty()) {
        p.mesh0.attribute.clear();
        return;
    }
    for (int& a : p.mesh0.attribute) {
        const auto it = body_of_volume.find(a);
        if (it == body_of_volume.end())
            rd.fail(bodies[0], "[[body]]: the tetrahedra of physical volume tag " +
                                   std::to_string(a) + " of '" + file_name +
                                   "' belong to no body: give a [[body]] with its volume");
        a = it->second;
    }
}

/// A per-point list of the loading path (a load's factors, a support's ux/uy/uz list) as read:
/// where it stands, what it belongs to (levels::check_path_length's `what`) and its length.
struct PathList {
    const toml::node* node = nullptr;
    std::string what;
    size_t n = 0;
};

/// Refuses the first per-point list whose length differs from the lists before it, at its line,
/// with the 2D message (levels::check_path_length).
void check_path_lists3(const Reader& rd, const std::vector<PathList>& lists) {
    int K = 0;
    for (const PathList& l : lists)
        at(rd, l.node, [&] {
            levels::check_path_length(K, l.n, l.what);
            return 0;
        });
}

/// [[load]]: pressure and/or traction on a boundary tag, with optional factors per path point
/// (appended to `lists`).
void read_loads3(const Reader& rd, const toml::table& root, ElasticProblem3& p,
                 std::vector<PathList>& lists) {
    for (const toml::table* lt : rd.tables(root, "load", "the scene")) {
        const std::string w = "[[load]]";
        rd.check_keys(*lt, {"tag", "pressure", "traction", "factors"}, w);
        levels::FaceLoad3 ld;
        ld.tag = rd.string(*lt, "tag", w);
        check_tag3(rd, p.mesh0, *lt, ld.tag, w, false);
        ld.pressure = rd.number_or(*lt, "pressure", 0.0, w);
        if (lt->get("traction")) ld.traction = vec3(rd, *lt, "traction", w);
        if (!lt->get("pressure") && !lt->get("traction"))
            rd.fail(lt, w + " needs a pressure or a traction");
        if (const toml::node* fn = lt->get("factors")) {
            ld.factors = rd.numbers(fn, w + ".factors");
            lists.push_back({fn, "load on '" + ld.tag + "'", ld.factors.size()});
        }
        p.loads.push_back(ld);
    }
}

/// [[support]]: a tag, a line or a point, and ux, uy and/or uz (numbers, or lists per path point
/// appended to `lists`).
void read_supports3(const Reader& rd, const toml::table& root, ElasticProblem3& p,
                    std::vector<PathList>& lists) {
    for (const toml::table* st : rd.tables(root, "support", "the scene")) {
        const std::string w = "[[support]]";
        refuse_2d_only(rd, *st, {"active"}, w,
                       "a 3D support holds in every load step: releasing it along the loading "
                       "path, which rebuilds the levels between steps, is 2D-only");
        rd.check_keys(*st, {"tag", "line", "point", "ux", "uy", "uz"}, w);
        levels::Support3 s;
        if (int(st->get("tag") != nullptr) + int(st->get("line") != nullptr) +
                int(st->get("point") != nullptr) >
            1)
            rd.fail(st, w + " takes one of a tag, a line or a point");
        if (st->get("tag")) {
            s.tag = rd.string(*st, "tag", w);
            check_tag3(rd, p.mesh0, *st, s.tag, w, true); // a support may hold a line
        } else if (const toml::node* ln = st->get("line")) {
            const toml::array* a = ln->as_array();
            if (!a || a->size() != 2)
                rd.fail(ln, w + ".line must be two points [[x, y, z], [x, y, z]]");
            s.line = std::array<Vec3, 2>{vec3(rd, a->get(0), w + ".line[0]"),
                                         vec3(rd, a->get(1), w + ".line[1]")};
        } else if (st->get("point")) {
            s.point = vec3(rd, *st, "point", w);
        } else {
            rd.fail(st, w + " needs a tag, a line or a point");
        }
        // A number (proportional to the path parameter) or a list of values per path point.
        const std::string where = !s.tag.empty() ? "support on '" + s.tag + "'"
                                  : s.line       ? std::string("support along a line")
                                                 : std::string("support at a point");
        const char* keys[3] = {"ux", "uy", "uz"};
        for (size_t c = 0; c < 3; ++c) {
            const toml::node* n = st->get(keys[c]);
            if (!n) continue;
            if (n->is_array()) {
                s.u_path[c] = rd.numbers(n, w + "." + keys[c]);
                s.u[c] = s.u_path[c].back();
                lists.push_back({n, where + " (" + keys[c] + ")", s.u_path[c].size()});
            } else {
                s.u[c] = rd.number(n, w + "." + keys[c]);
            }
        }
        if (!s.u[0] && !s.u[1] && !s.u[2]) rd.fail(st, w + " fixes nothing: give ux, uy and/or uz");
        if (s.point || s.line)
            at(rd, st->get(s.point ? "point" : "line"), [&] {
                levels::ElasticProblem3 probe;
                probe.mesh0 = p.mesh0;
                probe.bodies = p.bodies;
                probe.supports = {s};
                probe.validate();
                return 0;
            });
        p.supports.push_back(s);
    }
}

/// The signed distance of x from obstacle o, positive on the side its normal points to (the
/// body's side).
double obstacle_side(const contact::BasicObstacle<3>& o, const Vec3& x) {
    using Kind = contact::BasicObstacle<3>::Kind;
    if (o.kind == Kind::plane) return o.normal.dot(x - o.point);
    Vec3 d = x - o.center;
    if (o.kind == Kind::cylinder) d -= d.dot(o.axis) * o.axis;
    return o.body_outside ? d.norm() - o.radius : o.radius - d.norm();
}

/// Empty, or why obstacle `o` (validated) of a pair whose contactor tag is `tag` faces away from
/// the body: more than half of the volume of a body holding a contactor vertex lies on the
/// obstacle's far side (behind a plane, against its normal; inside a sphere or cylinder the body
/// should be outside of, or the reverse). Its contact would then hold the body from the wrong
/// side.
std::string obstacle_faces_away(const ElasticProblem3& p, const std::string& tag,
                                const contact::BasicObstacle<3>& o) {
    const mesh::TetMesh& m = p.mesh0;
    const int tid = m.tag(tag);
    const auto body_of = [&](int t) {
        return m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
    };
    std::vector<int> vbody(static_cast<size_t>(m.n_vertices()), -1);
    for (int t = 0; t < m.n_cells(); ++t)
        for (int v : m.cells[static_cast<size_t>(t)])
            vbody[static_cast<size_t>(v)] = body_of(t);
    std::set<int> bodies;
    for (int v : m.vertices_with_tag(tid))
        bodies.insert(vbody[static_cast<size_t>(v)]);
    for (int b : bodies) {
        double total = 0.0, behind = 0.0;
        for (int t = 0; t < m.n_cells(); ++t) {
            if (body_of(t) != b) continue;
            Vec3 c = Vec3::Zero();
            for (int v : m.cells[static_cast<size_t>(t)])
                c += m.vertices[static_cast<size_t>(v)] / 4.0;
            const double vol = std::abs(m.signed_measure(t));
            total += vol;
            if (obstacle_side(o, c) < 0) behind += vol;
        }
        if (!(total > 0) || behind <= 0.5 * total) continue;
        const std::string name = b >= 0 && b < static_cast<int>(p.bodies.size())
                                     ? p.bodies[static_cast<size_t>(b)].name
                                     : std::to_string(b);
        std::ostringstream os;
        os << std::setprecision(3) << 100.0 * behind / total << "% of the volume of body '" << name
           << "' lies ";
        if (o.kind == contact::BasicObstacle<3>::Kind::plane)
            os << "behind the plane (against its normal [" << o.normal.x() << ", " << o.normal.y()
               << ", " << o.normal.z()
               << "]): the normal points away from the body; it must point from the obstacle "
                  "into the body: normal = ["
               << -o.normal.x() + 0.0 << ", " << -o.normal.y() + 0.0 << ", " << -o.normal.z() + 0.0
               << "]";
        else
            os << (o.body_outside ? "inside" : "outside") << " the "
               << (o.kind == contact::BasicObstacle<3>::Kind::sphere ? "sphere" : "cylinder")
               << ", but side = \"" << (o.body_outside ? "outside" : "inside")
               << "\" puts the body there: the obstacle's normal points away from the body; use "
                  "side = \""
               << (o.body_outside ? "inside" : "outside") << "\"";
        return os.str();
    }
    return {};
}

/// A pair's rigid obstacle: a plane (point, normal), a sphere (center, radius, side) or a
/// cylinder (center, axis, radius, side), validated and facing the body.
contact::BasicObstacle<3> read_obstacle3(const Reader& rd, const toml::table& ct,
                                         const std::string& w, const ElasticProblem3& p,
                                         const std::string& contactor) {
    using Kind = contact::BasicObstacle<3>::Kind;
    const std::string ow = w + ".obstacle";
    const toml::table& ot = rd.table(rd.need(ct, "obstacle", w), ow);
    const std::string type = rd.string(ot, "type", ow);
    contact::BasicObstacle<3> o;
    const toml::node* bad = &ot; // where validate's complaint points
    if (type == "plane") {
        rd.check_keys(ot, {"type", "point", "normal"}, ow);
        o.kind = Kind::plane;
        o.point = vec3(rd, ot, "point", ow);
        o.normal = vec3(rd, ot, "normal", ow);
        bad = ot.get("normal");
    } else if (type == "sphere" || type == "cylinder") {
        if (type == "sphere") {
            rd.check_keys(ot, {"type", "center", "radius", "side"}, ow);
            o.kind = Kind::sphere;
        } else {
            rd.check_keys(ot, {"type", "center", "axis", "radius", "side"}, ow);
            o.kind = Kind::cylinder;
            o.axis = vec3(rd, ot, "axis", ow);
        }
        o.center = vec3(rd, ot, "center", ow);
        o.radius = rd.number(ot, "radius", ow);
        const std::string side = rd.string_or(ot, "side", "outside", ow);
        if (side != "outside" && side != "inside")
            rd.fail(ot.get("side"),
                    ow + ".side must be \"outside\" or \"inside\", found \"" + side + "\"");
        o.body_outside = side == "outside";
        bad = o.radius > 0 && type == "cylinder" ? ot.get("axis") : ot.get("radius");
    } else if (type == "line" || type == "circle") {
        rd.fail(ot.get("type"), ow + ".type \"" + type + "\" is 2D-only: a 3D obstacle is " +
                                    (type == "line" ? "a \"plane\" (point, normal)"
                                                    : "a \"sphere\" or a \"cylinder\"") +
                                    " (a 3D scene, [scene] dimension = 3)");
    } else {
        rd.fail(ot.get("type"), ow +
                                    ".type must be \"plane\", \"sphere\" or \"cylinder\", "
                                    "found \"" +
                                    type + "\"");
    }
    at(rd, bad, [&] {
        o.validate();
        return 0;
    });
    if (const std::string why = obstacle_faces_away(p, contactor, o); !why.empty())
        rd.fail(&ot, ow + ": " + why);
    return o;
}

/// The pair's augmentation parameter: r, or r_over_E (default 0.1) times E h0, E the smallest
/// Young's modulus of the scene and h0 the mean level-0 edge of the contactor's faces (a 3D
/// multiplier is a nodal force: r is a force per length); refused when not > 0 or out of the
/// scale of E h0 (levels::kMinROverE .. kMaxROverE).
double read_r3(const Reader& rd, const toml::table& ct, const std::string& w, double Emin,
               double h0) {
    if (ct.get("r") && ct.get("r_over_E")) rd.fail(&ct, w + " takes r or r_over_E, not both");
    const toml::node* n = ct.get("r") ? ct.get("r") : ct.get("r_over_E");
    const std::string units =
        " (in 3D a multiplier is a nodal force and r a force per length: r_over_E gives r = "
        "r_over_E E h0, E the smallest Young's modulus of the scene and h0 the mean length of the "
        "level-0 edges of the contactor's faces)";
    const double r =
        ct.get("r") ? rd.number(ct, "r", w) : rd.number_or(ct, "r_over_E", 0.1, w) * Emin * h0;
    if (!(r > 0))
        rd.fail(n, w + ": augmentation parameter " + (ct.get("r") ? "r" : "r_over_E") +
                       " must be > 0" + units);
    const double ratio = r / (Emin * h0);
    if (!(ratio >= levels::kMinROverE && ratio <= levels::kMaxROverE)) {
        std::ostringstream os;
        os << std::setprecision(3) << w << ": augmentation parameter r = " << r << " is " << ratio
           << " times E h0 = " << Emin * h0 << " (E = " << Emin << ", h0 = " << h0 << ")" << units
           << ", outside [" << levels::kMinROverE << ", " << levels::kMaxROverE
           << "] E h0: use r of the order of E h0 (r_over_E = 0.1, the default)";
        rd.fail(n, os.str());
    }
    return r;
}

/// [[contact]]: a contactor tag (inside a region) against a rigid obstacle, or against the
/// faces of a target tag (two bodies: the keys of 2D pairs).
void read_contacts3(const Reader& rd, const toml::table& root, ElasticProblem3& p) {
    double Emin = std::numeric_limits<double>::infinity();
    for (const levels::Body3& b : p.bodies)
        Emin = std::min(Emin, b.material.E);
    for (const toml::table* ct : rd.tables(root, "contact", "the scene")) {
        const std::string w = "[[contact]]";
        rd.check_keys(*ct,
                      {"name", "contactor", "region", "mu", "r", "r_over_E", "obstacle", "target",
                       "element", "integration", "search_radius", "match_tolerance"},
                      w);
        if (ct->get("obstacle") && ct->get("target"))
            rd.fail(ct, w + " takes an obstacle (rigid) or a target tag (two bodies), not both");
        if (!ct->get("obstacle") && !ct->get("target"))
            rd.fail(ct, w + " needs an obstacle (rigid) or a target tag (two bodies)");
        levels::ContactPair3 c;
        c.name = rd.string_or(*ct, "name", "contact" + std::to_string(p.contacts.size() + 1), w);
        c.contactor = rd.string(*ct, "contactor", w);
        const auto id = p.mesh0.find_tag(c.contactor);
        if (!id || !p.mesh0.is_boundary_tag(*id))
            rd.fail(ct->get("contactor"), w + ": unknown contactor tag '" + c.contactor +
                                              "': no boundary face carries it (the boundary "
                                              "face tags are: " +
                                              known_tags(p.mesh0, false) + ")");
        c.mu = rd.number(*ct, "mu", w);
        if (c.mu < 0)
            rd.fail(ct->get("mu"),
                    w + ": friction coefficient mu must be >= 0, found " + std::to_string(c.mu));
        c.r = read_r3(rd, *ct, w, Emin, levels::mean_face_edge_length(p.mesh0, c.contactor));
        if (const toml::node* rn = ct->get("region")) {
            const toml::table& rt = rd.table(rn, w + ".region");
            rd.check_keys(rt, {"min", "max"}, w + ".region");
            levels::Box3 box;
            if (rt.get("min")) box.lo = vec3(rd, rt, "min", w + ".region");
            if (rt.get("max")) box.hi = vec3(rd, rt, "max", w + ".region");
            if (!(box.lo.array() <= box.hi.array()).all())
                rd.fail(rn, w + ".region: its min exceeds its max in some coordinate");
            c.region = box;
        }
        if (ct->get("target")) {
            c.target = rd.string(*ct, "target", w);
            if (const auto tid = p.mesh0.find_tag(c.target); !tid || !p.mesh0.is_boundary_tag(*tid))
                rd.fail(ct->get("target"),
                        w + ": unknown target tag '" + c.target + "' (the " +
                            "boundary face tags are: " + known_tags(p.mesh0, false) + ")");
            if (c.target == c.contactor)
                rd.fail(ct->get("target"), w + ": the target tag is the contactor tag");
            read_two_body_keys(rd, *ct, w, c);
        } else {
            for (const char* k : {"element", "integration", "search_radius", "match_tolerance"})
                if (const toml::node* n = ct->get(k))
                    rd.fail(n, w + "." + k +
                                   " applies to two-body pairs (with a target), not to an "
                                   "obstacle");
            c.obstacle = read_obstacle3(rd, *ct, w, p, c.contactor);
        }
        p.contacts.push_back(std::move(c));
    }
}

/// [newton]: rel_tol, max_iter, forcing (as in 2D scenes).
void read_newton3(const Reader& rd, const toml::table& root, ElasticProblem3& p) {
    const toml::node* nn = root.get("newton");
    if (!nn) return;
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

std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    MLC_CHECK(in.good(), "cannot read scene file '" << path.string() << "'");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

} // namespace

namespace detail {

void refuse_3d_scene(const Reader& rd, const toml::table& root, toml::table& scene_table) {
    const toml::node* d = scene_table.get("dimension");
    if (!d) return;
    const int dim = rd.integer(d, "[scene].dimension");
    if (dim == 3)
        rd.fail(d, "this is a 3D scene ([scene].dimension = 3), which this command does not "
                   "solve: 3D scenes run with `mlcontact run` (on one or several processes), "
                   "`bench square`, `bench elastic` and every study but `preconditioners`");
    if (dim != 2) rd.fail(d, "[scene].dimension must be 2 or 3, found " + std::to_string(dim));
    (void)root;
    scene_table.erase("dimension");
}

} // namespace detail

int scene_text_dimension(const std::string& text) {
    try {
        const toml::table root = toml::parse(text);
        if (const auto d = root["scene"]["dimension"].value_exact<int64_t>(); d && *d == 3)
            return 3;
    } catch (const toml::parse_error&) {
    }
    return 2;
}

int scene_dimension(const std::string& name_or_path) {
    const std::filesystem::path path(name_or_path);
    const bool looks_like_file = path.extension() == ".toml" || path.has_parent_path();
    if (!looks_like_file || !std::filesystem::exists(path)) {
        const std::string text = builtin_scene_text(name_or_path);
        if (!text.empty()) return scene_text_dimension(text);
    }
    if (!std::filesystem::is_regular_file(path)) return 2;
    std::ifstream in(path);
    if (!in) return 2;
    std::stringstream ss;
    ss << in.rdbuf();
    return scene_text_dimension(ss.str());
}

levels::ElasticProblem3 parse_scene3(const std::string& text, const std::string& origin,
                                     const std::filesystem::path& base_dir) {
    Reader rd(origin);
    toml::table root = detail::parse_toml(text, origin);
    if (const toml::table* s = root["scene"].as_table()) {
        const toml::node* d = s->get("dimension");
        if (!d) rd.fail(s, "[scene].dimension = 3 is missing: this is no 3D scene");
        if (rd.integer(d, "[scene].dimension") != 3)
            rd.fail(d, "[scene].dimension of a 3D scene must be 3");
    }
    rd.check_keys(root, {"scene", "body", "load", "support", "contact", "newton"}, "the scene");
    ElasticProblem3 p;
    read_scene3_table(rd, root, p);
    read_bodies3(rd, root, base_dir, p);
    std::vector<PathList> path_lists;
    read_loads3(rd, root, p, path_lists);
    read_supports3(rd, root, p, path_lists);
    check_path_lists3(rd, path_lists);
    read_contacts3(rd, root, p);
    read_newton3(rd, root, p);
    at(rd, &root, [&] {
        p.validate();
        return 0;
    });
    return p;
}

levels::ElasticProblem3 load_scene3(const std::string& name_or_path) {
    const std::filesystem::path path(name_or_path);
    const bool looks_like_file = path.extension() == ".toml" || path.has_parent_path();
    if (!looks_like_file || !std::filesystem::exists(path)) {
        const std::string text = builtin_scene_text(name_or_path);
        if (!text.empty()) return parse_scene3(text, "builtin:" + name_or_path, {});
    }
    if (!std::filesystem::exists(path))
        throw InvalidInput("scene '" + name_or_path +
                           "' is neither a readable file nor a built-in scene");
    MLC_CHECK(std::filesystem::is_regular_file(path),
              "scene '" << name_or_path << "' is not a regular file");
    return parse_scene3(read_text(path), path.string(), path.parent_path());
}

} // namespace mlc::scene
