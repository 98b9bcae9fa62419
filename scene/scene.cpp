// SPDX-License-Identifier: MIT
// Scene parsing with toml++: the top-level tables are read in order by the readers of kSections,
// every key checked against the schema documented in docs/guide/scenes.md#scene-keys.
#include "scene/scene.hpp"

#include "core/check.hpp"
#include "mesh/mesh.hpp"
#include "mesh/transform.hpp"
#include "scene/reader.hpp"

#include <array>
#include <fstream>
#include <map>
#include <sstream>
#include <toml++/toml.h>

namespace mlc::scene {

namespace detail {

void check_tag(const Reader& rd, const mesh::Mesh& m, const toml::table& t, const std::string& tag,
               const std::string& w, bool boundary_only, const char* key) {
    const toml::node* n = t.get(key) ? t.get(key) : &t;
    const auto id = m.find_tag(tag);
    if (!id || (boundary_only && !m.is_boundary_tag(*id))) {
        std::string known;
        for (const auto& [name, k] : m.tag_names)
            if (!boundary_only || m.is_boundary_tag(k)) known += (known.empty() ? "" : ", ") + name;
        if (id)
            rd.fail(n, w + ": tag '" + tag + "' names interior lines only; " + key +
                           " needs a boundary tag (the mesh has: " + known + ")");
        rd.fail(n, w + ": unknown " + (boundary_only ? "boundary " : "") + "tag '" + tag +
                       "' (the mesh has: " + known + ")");
    }
}

} // namespace detail

namespace {

using detail::at;
using detail::kMaxLevels;
using detail::Reader;
using levels::Problem;

/// What the section readers fill and hand on to the next ones.
struct SceneParse {
    const Reader& rd;
    const std::filesystem::path& base_dir;
    Problem p;
    fem::Plane plane = fem::Plane::strain;
    bool recover = true;                      // [scene].recover_levels
    const toml::node* recover_node = nullptr; // where it was stated, if it was
    bool all_gmsh = true;                     // every body's mesh read from a Gmsh file
};

/// [scene]: name, description, units, plane, load_steps, levels, recover_levels.
void read_scene_table(SceneParse& sp, const toml::table& root) {
    const Reader& rd = sp.rd;
    Problem& p = sp.p;
    const toml::node* sn = rd.need(root, "scene", "the scene");
    const toml::table& s = rd.table(sn, "[scene]");
    rd.check_keys(
        s, {"name", "description", "units", "plane", "load_steps", "levels", "recover_levels"},
        "[scene]");
    if (const toml::node* rn = s.get("recover_levels")) {
        sp.recover_node = rn;
        sp.recover = rd.boolean_or(s, "recover_levels", true, "[scene]");
    }
    p.name = rd.string(s, "name", "[scene]");
    p.description = rd.string_or(s, "description", "", "[scene]");
    p.units = rd.string_or(s, "units", "", "[scene]");
    const std::string pl = rd.string_or(s, "plane", "strain", "[scene]");
    if (pl == "stress")
        sp.plane = fem::Plane::stress;
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

/// [[body]]: material, body force, mesh and tag renames; the bodies' meshes merged into mesh0.
void read_bodies(SceneParse& sp, const toml::table& root) {
    const Reader& rd = sp.rd;
    Problem& p = sp.p;
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
        body.material.plane = sp.plane;
        at(rd, b.get("E"), [&] {
            body.material.validate();
            return 0;
        });
        if (b.get("body_force")) body.body_force = rd.vec2(b, "body_force", w);
        const toml::node* mn = rd.need(b, "mesh", w);
        const toml::table& mt = rd.table(mn, w + ".mesh");
        if (mt["type"].value_or(std::string()) != "gmsh") sp.all_gmsh = false;
        mesh::Mesh m = detail::parse_mesh(rd, mt, w + ".mesh", sp.base_dir);
        if (const toml::node* tn = b.get("tags")) rename_tags(rd, tn, w, m);
        mesh::merge_into(p.mesh0, m, static_cast<int>(i));
        p.bodies.push_back(body);
    }
    at(rd, &root, [&] {
        mesh::check_quality(p.mesh0);
        return 0;
    });
    if (sp.recover_node != nullptr && sp.recover && !sp.all_gmsh)
        rd.fail(sp.recover_node, "[scene].recover_levels applies to meshes read from Gmsh files "
                                 "(type = \"gmsh\"), and a body here has another mesh");
}

/// [[load]]: a pressure and/or traction on a boundary tag, with optional factors per path point.
void read_loads(SceneParse& sp, const toml::table& root) {
    const Reader& rd = sp.rd;
    Problem& p = sp.p;
    for (const toml::table* lt : rd.tables(root, "load", "the scene")) {
        const std::string w = "[[load]]";
        rd.check_keys(*lt, {"tag", "pressure", "traction", "factors"}, w);
        levels::Load ld;
        ld.tag = rd.string(*lt, "tag", w);
        detail::check_tag(rd, p.mesh0, *lt, ld.tag, w);
        ld.pressure = rd.number_or(*lt, "pressure", 0.0, w);
        if (lt->get("traction")) ld.traction = rd.vec2(*lt, "traction", w);
        if (!lt->get("pressure") && !lt->get("traction"))
            rd.fail(lt, w + " needs a pressure or a traction");
        if (const toml::node* fn = lt->get("factors")) ld.factors = rd.numbers(fn, w + ".factors");
        p.loads.push_back(ld);
    }
}

/// One [[support]]: a tag or a point, ux/uy (numbers or lists per path point) and `active`.
levels::Support read_support(const Reader& rd, const toml::table& st, const Problem& p) {
    const std::string w = "[[support]]";
    rd.check_keys(st, {"tag", "point", "ux", "uy", "active"}, w);
    levels::Support s;
    if (st.get("tag") && st.get("point")) rd.fail(&st, w + " takes a tag or a point, not both");
    if (st.get("tag")) {
        s.tag = rd.string(st, "tag", w);
        detail::check_tag(rd, p.mesh0, st, s.tag, w, false);
    } else if (st.get("point")) {
        s.point = rd.vec2(st, "point", w);
    } else {
        rd.fail(&st, w + " needs a tag or a point");
    }
    // A number (proportional to the load parameter) or a list of values per path point.
    for (int c = 0; c < 2; ++c) {
        const char* key = c == 0 ? "ux" : "uy";
        const toml::node* n = st.get(key);
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
    if (!s.ux && !s.uy) rd.fail(&st, w + " fixes nothing: give ux and/or uy");
    if (const toml::node* an = st.get("active")) {
        // Per point of the loading path: true holds the support there, false releases it.
        const toml::array* a = an->as_array();
        if (!a || a->empty())
            rd.fail(an, w + ".active must be an array of true/false, one per point of the "
                            "loading path (per load step when load_steps is their number)");
        for (size_t k = 0; k < a->size(); ++k) {
            const auto b = a->get(k)->value_exact<bool>();
            if (!b)
                rd.fail(a->get(k), w + ".active[" + std::to_string(k) + "] must be true or false");
            s.active.push_back(*b);
        }
    }
    return s;
}

/// [[support]]: every support, then every `active` list checked against the loading path.
void read_supports(SceneParse& sp, const toml::table& root) {
    const Reader& rd = sp.rd;
    Problem& p = sp.p;
    std::vector<std::pair<size_t, const toml::node*>> active_nodes; // support index, its node
    for (const toml::table* st : rd.tables(root, "support", "the scene")) {
        if (const toml::node* an = st->get("active"))
            active_nodes.emplace_back(p.supports.size(), an);
        p.supports.push_back(read_support(rd, *st, p));
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
}

void read_contacts(SceneParse& sp, const toml::table& root) {
    detail::parse_contacts(sp.rd, root, sp.p);
}

/// [newton]: rel_tol, max_iter, forcing.
void read_newton(SceneParse& sp, const toml::table& root) {
    const Reader& rd = sp.rd;
    Problem& p = sp.p;
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

/// A top-level table of a scene and its reader.
struct Section {
    std::string_view key;
    void (*read)(SceneParse&, const toml::table& root);
};

/// The top-level tables, read in this order: the bodies need [scene] (plane), the loads,
/// supports and contacts the bodies' merged mesh, the supports' lists the loads' factors.
constexpr std::array<Section, 6> kSections{{
    {"scene", read_scene_table},
    {"body", read_bodies},
    {"load", read_loads},
    {"support", read_supports},
    {"contact", read_contacts},
    {"newton", read_newton},
}};

} // namespace

levels::Problem parse_scene(const std::string& text, const std::string& origin,
                            const std::filesystem::path& base_dir, const StopPoll& stop) {
    Reader rd(origin, stop);
    toml::table root = detail::parse_toml(text, origin);
    std::array<std::string_view, kSections.size()> keys;
    for (size_t i = 0; i < kSections.size(); ++i)
        keys[i] = kSections[i].key;
    if (toml::table* st = root["scene"].as_table()) detail::refuse_3d_scene(rd, root, *st);
    rd.check_keys(root, keys, "the scene");
    SceneParse sp{rd, base_dir, {}};
    for (const Section& s : kSections)
        s.read(sp, root);
    at(rd, &root, [&] {
        sp.p.validate();
        return 0;
    });
    if (sp.recover && sp.all_gmsh) detail::recover_levels(sp.p);
    return std::move(sp.p);
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
