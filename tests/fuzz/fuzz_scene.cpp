// SPDX-License-Identifier: MIT
// libFuzzer target: the input bytes as scene TOML text for scene::parse_scene. mlc::InvalidInput is
// the expected answer to bad input; any other exception, a crash, a sanitizer report or a hang is
// a finding.
//
// The parser builds the level-0 meshes, so a few bytes can ask for a lot of work
// (divisions = [100000, 100000], a CGAL domain with max_size = 1e-9). Such inputs are legitimate
// scenes, only slow, and a fuzzer that spends seconds meshing one input learns nothing: this
// target estimates the triangle count from the TOML before calling the parser and skips inputs
// above a budget. The estimate only skips inputs; it never replaces a check of the library, which
// still sees every input under the budget, including every invalid size.
#include "core/check.hpp"
#include "scene/scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace {

/// Budget of one input, in estimated triangles over all bodies. A fuzz input should run in
/// milliseconds; the built-in scenes need 512 (square) and a few thousand (hertz).
constexpr double max_triangles = 2e4;
constexpr double too_many = std::numeric_limits<double>::infinity();

/// The tables under `key`: an array of tables or a single table (as the parser accepts them).
std::vector<const toml::table*> tables(const toml::table& t, std::string_view key) {
    std::vector<const toml::table*> out;
    const toml::node* n = t.get(key);
    if (!n) return out;
    if (const toml::array* a = n->as_array()) {
        for (const auto& e : *a)
            if (const toml::table* et = e.as_table()) out.push_back(et);
    } else if (const toml::table* nt = n->as_table()) {
        out.push_back(nt);
    }
    return out;
}

/// A point [x, y] with finite coordinates, if `n` is one.
std::optional<std::array<double, 2>> point(const toml::node* n) {
    const toml::array* a = n ? n->as_array() : nullptr;
    if (!a || a->size() != 2) return std::nullopt;
    const auto x = a->get(0)->value<double>(), y = a->get(1)->value<double>();
    if (!x || !y || !std::isfinite(*x) || !std::isfinite(*y)) return std::nullopt;
    return std::array<double, 2>{*x, *y};
}

/// Estimated triangles of one mesh table; 0 when the parser rejects the table before meshing.
double estimate(const toml::table& m) {
    const auto type = m["type"].value_exact<std::string>();
    if (!type) return 0;
    if (*type == "rectangle") {
        const toml::array* d = m["divisions"].as_array();
        if (!d || d->size() != 2) return 0;
        const auto nx = d->get(0)->value_exact<int64_t>(), ny = d->get(1)->value_exact<int64_t>();
        if (!nx || !ny || *nx < 1 || *ny < 1) return 0;
        return 2.0 * static_cast<double>(*nx) * static_cast<double>(*ny);
    }
    if (*type == "domain") {
        // Every edge is at least h_min = min(max_size, min_size) long, so the mesh has at most
        // about 2 (d / h_min)^2 triangles for a bounding box of diagonal d (circles included).
        const double max_size = m["max_size"].value<double>().value_or(0);
        const double min_size = m["min_size"].value<double>().value_or(max_size);
        const double h = min_size > 0 ? std::min(max_size, min_size) : max_size;
        if (!(h > 0) || !std::isfinite(h)) return 0; // SizeField::validate rejects it
        double lo[2] = {too_many, too_many}, hi[2] = {-too_many, -too_many};
        auto grow = [&](const std::array<double, 2>& p, double r) {
            for (int k = 0; k < 2; ++k) {
                lo[k] = std::min(lo[k], p[static_cast<std::size_t>(k)] - r);
                hi[k] = std::max(hi[k], p[static_cast<std::size_t>(k)] + r);
            }
        };
        for (const toml::table* loop : tables(m, "loop")) {
            const toml::array* segments = (*loop)["segments"].as_array();
            if (!segments) continue;
            for (const auto& s : *segments) {
                const toml::table* st = s.as_table();
                if (!st) continue;
                const auto from = point(st->get("from")), to = point(st->get("to")),
                           center = point(st->get("center"));
                if (from) grow(*from, 0);
                if (to) grow(*to, 0);
                if (from && center)
                    grow(*center, std::hypot((*from)[0] - (*center)[0], (*from)[1] - (*center)[1]));
            }
        }
        if (!(hi[0] >= lo[0] && hi[1] >= lo[1])) return 0; // no point: rejected
        const double d = std::hypot(hi[0] - lo[0], hi[1] - lo[1]);
        const double n = 2 * (d / h) * (d / h);
        return std::isfinite(n) ? n : too_many;
    }
    if (*type == "gmsh") {
        // Only the small meshes of tests/data: no absolute paths, no way out of the directory.
        // A scene may name any file; read_gmsh rejects devices and pipes (it once read /dev/zero
        // until memory ran out), but a large regular file is only slow.
        const auto file = m["file"].value_exact<std::string>();
        if (!file) return 0;
        const std::filesystem::path p(*file);
        if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) return too_many;
        for (const auto& part : p)
            if (part == "..") return too_many;
        return 0;
    }
    return 0;
}

/// Estimated triangles of all bodies of a scene; 0 for text that is not TOML (the parser rejects
/// it before meshing).
double estimate_scene(const std::string& text) {
    toml::table root;
    try {
        root = toml::parse(text);
    } catch (const toml::parse_error&) {
        return 0;
    }
    double total = 0;
    for (const toml::table* body : tables(root, "body"))
        if (const toml::table* m = (*body)["mesh"].as_table()) total += estimate(*m);
    return total;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    if (estimate_scene(text) > max_triangles) return -1; // skipped; not added to the corpus
    try {
        mlc::scene::parse_scene(text, "fuzz.toml", MLC_FUZZ_DATA_DIR);
    } catch (const mlc::InvalidInput&) {
        // The expected answer to bad input. Anything else propagates: libFuzzer reports it.
    }
    return 0;
}
