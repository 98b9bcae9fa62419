// SPDX-License-Identifier: MIT
// Gmsh .msh reader for tetrahedral meshes: selects tetrahedra and tagged boundary triangles
// from what the shared parser (mesh/io/gmsh_parse.hpp) collected.
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/io/gmsh_parse.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>

namespace mlc::mesh {

namespace {

using gmsh_io::MshData;

/// The physical tag of the volume named `volume` ("tag<N>" for an unnamed one); lists the
/// physical volumes of the file if there is none.
int wanted_volume(const MshData& d, const std::string& volume, const std::string& where) {
    std::set<int> volumes;
    for (std::size_t e = 0; e < d.n_elements(); ++e)
        if (gmsh_io::msh_element_type(d.elem_type[e]).dim == 3)
            for (std::size_t k = d.phys_begin[e]; k < d.phys_begin[e + 1]; ++k)
                volumes.insert(d.phys[k]);
    for (const auto& [key, name] : d.names)
        if (key.first == 3 && name == volume) return key.second;
    for (int v : volumes)
        if (volume == "tag" + std::to_string(v) && !d.names.count({3, v})) return v;
    std::ostringstream known;
    for (int v : volumes) {
        auto it = d.names.find({3, v});
        known << " '" << (it == d.names.end() ? "tag" + std::to_string(v) : it->second) << "'";
    }
    MLC_CHECK(false, where << ": no physical volume '" << volume << "'; expected one of:"
                           << (volumes.empty() ? " none (the file has no physical volumes)" : "")
                           << known.str());
    return -1;
}

/// "the element on line L, nodes a b c d".
std::string element_text(const MshData& d, std::size_t e) {
    std::ostringstream os;
    os << "the element on line " << d.elem_line[e] << ", nodes";
    for (std::size_t k = d.node_begin[e]; k < d.node_begin[e + 1]; ++k)
        os << " " << d.node_ids[k];
    return os.str();
}

/// Physical volumes are bodies: either every selected tetrahedron is in one, or none is (then
/// all are body 0). Names the first tetrahedron in none.
void check_every_tetrahedron_has_a_volume(const MshData& d, const std::vector<int>& tet_phys,
                                          const std::vector<std::size_t>& tet_element,
                                          const std::string& where) {
    const auto in_volume = [](int p) { return p != 0; };
    const std::size_t in =
        static_cast<std::size_t>(std::count_if(tet_phys.begin(), tet_phys.end(), in_volume));
    if (in == 0 || in == tet_phys.size()) return;
    const std::size_t i =
        static_cast<std::size_t>(std::find(tet_phys.begin(), tet_phys.end(), 0) - tet_phys.begin());
    std::set<int> volumes(tet_phys.begin(), tet_phys.end());
    volumes.erase(0);
    std::ostringstream known;
    for (int v : volumes) {
        auto it = d.names.find({3, v});
        known << " '" << (it == d.names.end() ? "tag" + std::to_string(v) : it->second) << "'";
    }
    MLC_CHECK(false, where << ":" << d.elem_line[tet_element[i]] << ": tetrahedron " << i << " ("
                           << element_text(d, tet_element[i]) << ") is in no physical volume, but "
                           << in << " of the " << tet_phys.size() << " tetrahedra are (in"
                           << known.str()
                           << "); a physical volume is a body: put every volume of the model "
                              "in a Physical Volume, or select one volume by name");
}

/// Tagged triangles of the file that are boundary faces of m become its BoundaryFaces.
void add_boundary_faces(TetMesh& m, const MshData& d, const std::vector<std::size_t>& triangles,
                        const std::vector<int>& new_index,
                        const std::unordered_map<std::int64_t, int>& node_index) {
    // Every face of every tetrahedron: (sorted vertices, opposite vertex).
    std::vector<std::tuple<std::array<int, 3>, int>> faces;
    faces.reserve(4 * m.cells.size());
    for (const auto& k : m.cells)
        for (int skip = 0; skip < 4; ++skip) {
            std::array<int, 3> f{};
            int n = 0;
            for (int i = 0; i < 4; ++i)
                if (i != skip) f[static_cast<size_t>(n++)] = k[static_cast<size_t>(i)];
            std::sort(f.begin(), f.end());
            faces.emplace_back(f, k[static_cast<size_t>(skip)]);
        }
    std::sort(faces.begin(), faces.end());
    std::set<std::array<int, 3>> tagged;
    for (std::size_t e : triangles) {
        std::array<int, 3> v{};
        for (std::size_t k = 0; k < 3; ++k)
            v[k] = new_index[static_cast<size_t>(node_index.at(d.node_ids[d.node_begin[e] + k]))];
        if (std::min({v[0], v[1], v[2]}) < 0) continue;
        std::array<int, 3> key = v;
        std::sort(key.begin(), key.end());
        const auto lo = std::lower_bound(faces.begin(), faces.end(), std::make_tuple(key, -1));
        auto hi = lo;
        while (hi != faces.end() && std::get<0>(*hi) == key)
            ++hi;
        if (hi - lo != 1 || !tagged.insert(key).second) continue;
        const Vec3& a = m.vertices[static_cast<size_t>(v[0])];
        const double side = (m.vertices[static_cast<size_t>(v[1])] - a)
                                .cross(m.vertices[static_cast<size_t>(v[2])] - a)
                                .dot(m.vertices[static_cast<size_t>(std::get<1>(*lo))] - a);
        if (side > 0) std::swap(v[1], v[2]); // the normal away from the tetrahedron
        const int p = d.phys[d.phys_begin[e]];
        const auto name = d.names.find({2, p});
        m.boundary.push_back(
            {v, m.add_tag(name == d.names.end() ? "tag" + std::to_string(p) : name->second)});
    }
}

/// The 2-node lines of physical curves whose nodes are both vertices of the mesh become its
/// tagged lines, named as Gmsh names the curve ("tag<N>" for an unnamed one), each edge once per
/// tag; check_quality refuses one that is no edge of a tetrahedron.
void add_lines(TetMesh& m, const MshData& d, const std::vector<std::size_t>& segments,
               const std::vector<int>& new_index,
               const std::unordered_map<std::int64_t, int>& node_index) {
    std::set<std::array<int, 3>> seen; // (smaller vertex, larger vertex, tag)
    for (std::size_t e : segments) {
        std::array<int, 2> v{};
        for (std::size_t k = 0; k < 2; ++k)
            v[k] = new_index[static_cast<size_t>(node_index.at(d.node_ids[d.node_begin[e] + k]))];
        if (std::min(v[0], v[1]) < 0) continue;
        const int p = d.phys[d.phys_begin[e]];
        const auto name = d.names.find({1, p});
        const int tag = m.add_tag(name == d.names.end() ? "tag" + std::to_string(p) : name->second);
        if (!seen.insert({std::min(v[0], v[1]), std::max(v[0], v[1]), tag}).second) continue;
        m.lines.push_back({v[0], v[1], tag, -1});
    }
}

} // namespace

TetMesh read_gmsh_tet(const std::filesystem::path& file, const std::string& volume) {
    return read_gmsh_tet_text(gmsh_io::read_msh_file(file), file, volume);
}

TetMesh read_gmsh_tet_text(const std::string& text, const std::filesystem::path& file,
                           const std::string& volume) {
    const MshData d = gmsh_io::parse_msh(file, text);
    const std::string where = "read_gmsh: " + file.string();
    std::unordered_map<std::int64_t, int> node_index;
    node_index.reserve(d.node_id.size());
    for (std::size_t i = 0; i < d.node_id.size(); ++i)
        MLC_CHECK(node_index.emplace(d.node_id[i], static_cast<int>(i)).second,
                  where << ":" << d.node_line[i] << ": node id " << d.node_id[i]
                        << " appears twice");
    const int wanted = volume.empty() ? 0 : wanted_volume(d, volume, where);
    auto has_phys = [&](std::size_t e, int p) {
        for (std::size_t k = d.phys_begin[e]; k < d.phys_begin[e + 1]; ++k)
            if (d.phys[k] == p) return true;
        return false;
    };
    // Selected tetrahedra (in node indices of the file) and candidate boundary triangles.
    std::vector<std::array<int, 4>> tets;
    std::vector<int> tet_phys;
    std::vector<std::size_t> tet_element, triangles, segments;
    for (std::size_t e = 0; e < d.n_elements(); ++e) {
        const int type = d.elem_type[e];
        const gmsh_io::ElementType et = gmsh_io::msh_element_type(type);
        std::array<int, 4> nodes{};
        for (std::size_t k = 0; k < static_cast<std::size_t>(et.n_nodes); ++k) {
            const std::int64_t id = d.node_ids[d.node_begin[e] + k];
            const auto it = node_index.find(id);
            MLC_CHECK(it != node_index.end(), where << ":" << d.elem_line[e]
                                                    << ": element refers to node id " << id
                                                    << ", which is not in $Nodes");
            if (k < 4) nodes[k] = it->second;
        }
        if (type == 2 && d.phys_begin[e + 1] > d.phys_begin[e]) triangles.push_back(e);
        if (type == 1 && d.phys_begin[e + 1] > d.phys_begin[e]) segments.push_back(e);
        if (et.dim != 3 || (!volume.empty() && !has_phys(e, wanted))) continue;
        MLC_CHECK(type == 4, where << ":" << d.elem_line[e] << ": element type " << type << " ("
                                   << et.name
                                   << ") is not supported; expected 4-node tetrahedra (type 4) "
                                      "only: set Gmsh's Mesh.ElementOrder = 1 and do not "
                                      "recombine or extrude into prisms or hexahedra");
        tets.push_back(nodes);
        tet_element.push_back(e);
        tet_phys.push_back(d.phys_begin[e + 1] > d.phys_begin[e] ? d.phys[d.phys_begin[e]] : 0);
    }
    MLC_CHECK(!tets.empty(), where << ": no 4-node tetrahedra found"
                                   << (volume.empty() ? "" : " in physical volume '" + volume + "'")
                                   << "; expected a 3D mesh (Gmsh: Mesh 3)");
    // Keep the used nodes, in file order.
    TetMesh m;
    std::vector<int> new_index(d.node_id.size(), -1);
    for (const auto& t : tets)
        for (int v : t)
            new_index[static_cast<size_t>(v)] = 0;
    for (std::size_t i = 0; i < new_index.size(); ++i)
        if (new_index[i] == 0) {
            new_index[i] = m.n_vertices();
            m.vertices.push_back(d.node_x[i]);
        }
    for (std::size_t i = 0; i < tets.size(); ++i) {
        std::array<int, 4> t{};
        for (std::size_t k = 0; k < 4; ++k)
            t[k] = new_index[static_cast<size_t>(tets[i][k])];
        m.cells.push_back(t);
        // A flat one is left to check_quality, which says so.
        const double v = m.signed_measure(static_cast<int>(i));
        const double longest = [&] {
            double l = 0;
            for (int a = 0; a < 4; ++a)
                for (int b = a + 1; b < 4; ++b)
                    l = std::max(l, (m.vertices[static_cast<size_t>(t[static_cast<size_t>(a)])] -
                                     m.vertices[static_cast<size_t>(t[static_cast<size_t>(b)])])
                                        .norm());
            return l;
        }();
        MLC_CHECK(v >= 0 || 6 * std::abs(v) <= kFlatTetrahedronTol * longest * longest * longest,
                  where << ":" << d.elem_line[tet_element[i]] << ": inverted tetrahedron " << i
                        << " (" << element_text(d, tet_element[i]) << ") has volume " << v
                        << "; expected a positive volume (Gmsh's order: x3 - x0 on the side of "
                           "(x1 - x0) x (x2 - x0)): the element is turned inside out; remesh, "
                           "or if the file lists every tetrahedron the other way, swap two of "
                           "the nodes of each");
    }
    check_every_tetrahedron_has_a_volume(d, tet_phys, tet_element, where);
    if (std::any_of(tet_phys.begin(), tet_phys.end(), [](int p) { return p != 0; }))
        m.attribute = tet_phys;
    add_boundary_faces(m, d, triangles, new_index, node_index);
    add_lines(m, d, segments, new_index, node_index);
    try {
        check_quality(m, [&](int t) {
            return "tetrahedron " + std::to_string(t) + " (" +
                   element_text(d, tet_element[static_cast<size_t>(t)]) + ")";
        });
    } catch (const InvalidInput& e) {
        throw InvalidInput(where + ": " + e.what());
    }
    return m;
}

} // namespace mlc::mesh
