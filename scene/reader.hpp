// SPDX-License-Identifier: MIT
/// @file The pieces of the scene parser (scene.cpp reads the sections in order, mesh_tables.cpp a
/// body's mesh table, contacts.cpp the contact pairs, recover_levels.cpp the levels of a refined
/// Gmsh file): the Reader with its typed getters, and what the pieces share. Internal to mlc_scene.
#pragma once

#include "core/check.hpp"
#include "levels/problem.hpp"
#include "mesh/mesh.hpp"
#include "scene/scene.hpp"

#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <toml++/toml.h>
#include <vector>

namespace mlc::scene::detail {

const std::map<std::string, std::string>& builtin_scenes(); // generated
const std::map<std::string, std::string>& builtin_files();  // generated: scenes/*.msh

constexpr int kMaxLevels = 12; // [scene].levels and the levels a Gmsh mesh is read with

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
        check_keys(t, std::span<const std::string_view>(allowed.begin(), allowed.size()), where);
    }
    void check_keys(const toml::table& t, std::span<const std::string_view> allowed,
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

/// A body's mesh table: built in its own frame, mirrored (mirror_x), moved (transform), then the
/// arcs of a Gmsh mesh declared (in the global frame). mesh_tables.cpp.
mesh::Mesh parse_mesh(const Reader& rd, const toml::table& t, const std::string& where,
                      const std::filesystem::path& base_dir);

/// Fails unless `tag` names boundary edges of `m` (or, with boundary_only false, also a tagged
/// interior line, Mesh::lines); the message points at t[key] (or at t) and lists the known tags.
void check_tag(const Reader& rd, const mesh::Mesh& m, const toml::table& t, const std::string& tag,
               const std::string& where, bool boundary_only = true, const char* key = "tag");

/// The [[contact]] pairs of the scene, appended to p.contacts (the bodies and their mesh read).
/// contacts.cpp.
void parse_contacts(const Reader& rd, const toml::table& root, levels::Problem& p);

/// A Gmsh mesh that is a uniform 1->4 refinement (Gmsh's RefineMesh, `gmsh -refine`, `mlcontact
//// show --msh-level`) is read as a coarse ancestor and the levels between: coarse-to-fine Newton
//// and the multigrid then have the hierarchy a built-in scene has. The ancestors are found by
//// mesh::unrefine (its vertices within tol of the file's: exact for a file written with 17
//// digits; tol also allows the rounding of coordinates far from the origin); the coarsest one on
//// which the scene's level 0 builds (its support points are vertices, every contact pair finds
//// contactor nodes, matching node pairs match) becomes mesh0. Called on a parsed, valid problem.
void recover_levels(levels::Problem& p);

/// A 2D parse of a scene whose [scene] table (`scene_table`) states a dimension: 3 is refused
/// naming what runs 3D scenes, anything but 2 is refused, and `dimension = 2` is removed from
/// the table (a 2D scene may state it). scene3.cpp.
void refuse_3d_scene(const Reader& rd, const toml::table& root, toml::table& scene_table);

/// The TOML table of a scene's text; malformed TOML throws InvalidInput "origin:line: malformed
/// TOML: ...".
inline toml::table parse_toml(const std::string& text, const std::string& origin) {
    try {
        return toml::parse(text, origin);
    } catch (const toml::parse_error& e) {
        std::ostringstream os;
        os << origin << ":" << e.source().begin.line << ": malformed TOML: " << e.description();
        throw InvalidInput(os.str());
    }
}

/// A body's `tags = { old = "new" }` (2D or 3D mesh): renames its tags before merging (tags merge
/// by name).
template <class MeshT>
void rename_tags(const Reader& rd, const toml::node* tn, const std::string& w, MeshT& m) {
    const toml::table& tt = rd.table(tn, w + ".tags");
    std::map<int, std::string> new_name; // tag id -> new name
    for (auto&& [k, v] : tt) {
        const std::string from(k.str());
        const std::string to = rd.string(&v, w + ".tags." + from);
        if (!m.find_tag(from)) {
            std::string known;
            for (const auto& [n, id] : m.tag_names)
                known += (known.empty() ? "" : ", ") + n;
            rd.fail(&v,
                    w + ".tags: the body's mesh has no tag '" + from + "' (it has: " + known + ")");
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
    const auto retag = [&](auto& facets) {
        for (auto& e : facets)
            if (const auto it = merged.find(e.tag); it != merged.end()) e.tag = it->second;
    };
    retag(m.boundary);
    retag(m.lines);
    m.tag_names = std::move(names);
}

/// The keys of a two-body pair besides its target tag (2D or 3D pair): element kind, facet
/// integration, search radius, match tolerance.
template <class Pair>
void read_two_body_keys(const Reader& rd, const toml::table& ct, const std::string& w, Pair& c) {
    const std::string el = rd.string_or(ct, "element", "node_on_facet", w);
    if (el == "node_on_facet")
        c.element = levels::ContactElementKind::node_on_facet;
    else if (el == "node_on_node")
        c.element = levels::ContactElementKind::node_on_node;
    else
        rd.fail(ct.get("element"), w +
                                       ".element must be \"node_on_facet\" or "
                                       "\"node_on_node\", found \"" +
                                       el + "\"");
    const std::string integ = rd.string_or(ct, "integration", "nodal", w);
    if (integ == "nodal")
        c.integration = contact::FacetIntegration::nodal;
    else if (integ == "segment")
        c.integration = contact::FacetIntegration::segment;
    else if (integ == "dual")
        c.integration = contact::FacetIntegration::dual;
    else
        rd.fail(ct.get("integration"), w +
                                           ".integration must be \"nodal\", "
                                           "\"segment\" or \"dual\", found \"" +
                                           integ + "\"");
    if (c.integration != contact::FacetIntegration::nodal &&
        c.element != levels::ContactElementKind::node_on_facet)
        rd.fail(ct.get("integration"),
                w + ".integration = \"" + integ +
                    "\" applies to element = \"node_on_facet\" only, not to \"" + el + "\"");
    c.search_radius = rd.number_or(ct, "search_radius", c.search_radius, w);
    if (!(c.search_radius > 0)) rd.fail(ct.get("search_radius"), w + ".search_radius must be > 0");
    c.match_tolerance = rd.number_or(ct, "match_tolerance", c.match_tolerance, w);
    if (!(c.match_tolerance > 0 && c.match_tolerance < 0.5))
        rd.fail(ct.get("match_tolerance"), w + ".match_tolerance must lie in (0, 0.5)");
}

} // namespace mlc::scene::detail
