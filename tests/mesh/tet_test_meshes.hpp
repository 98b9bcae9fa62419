// SPDX-License-Identifier: MIT
/// @file What the tetrahedral mesh tests share: a small irregular Gmsh mesh written in both
/// formats, similarity of tetrahedra, and the expectation of an InvalidInput.
#pragma once

#include "core/check.hpp"
#include "mesh/tet_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace mlc::mesh::testing {

/// A mesh as a .msh file lists it: node ids from 1, elements with one physical tag each.
struct MshSpec {
    std::vector<Vec3> nodes;                                   ///< node id = index + 1
    std::vector<std::pair<int, std::array<int, 3>>> triangles; ///< (physical tag, node ids)
    std::vector<std::pair<int, std::array<int, 4>>> tets;      ///< (physical tag, node ids)
    std::vector<std::pair<int, std::array<int, 2>>> lines;     ///< (physical tag, node ids)
    std::vector<std::string> names; ///< "dim tag \"name\"" lines of $PhysicalNames
};

/// A slightly distorted cube cut into five tetrahedra: four corners (physical volume 3
/// "shell") around a central one (physical volume 4 "core"), each listed with positive volume.
/// Tagged triangles: the two of the bottom (physical surface 1 "bottom", listed turned into the
/// body), the two of the top (2 "top"), the two of the side x ~ 0 (5, unnamed).
inline MshSpec distorted_cube() {
    MshSpec s;
    s.nodes = {{0, 0, 0},     {1.1, 0, 0.05}, {0, 0.9, 0},    {1.05, 1.0, 0.1},
               {0, 0.1, 1.2}, {1, 0, 1},      {0.1, 1, 0.95}, {1.2, 1.1, 1.05}};
    // Vertex v = x + 2 y + 4 z of the cube is node v + 1.
    const std::array<std::array<int, 4>, 5> tets = {
        {{0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}, {1, 2, 4, 7}}};
    for (std::size_t t = 0; t < tets.size(); ++t) {
        std::array<int, 4> k = tets[t];
        const Vec3& a = s.nodes[static_cast<size_t>(k[0])];
        if ((s.nodes[static_cast<size_t>(k[1])] - a)
                .cross(s.nodes[static_cast<size_t>(k[2])] - a)
                .dot(s.nodes[static_cast<size_t>(k[3])] - a) < 0)
            std::swap(k[2], k[3]);
        for (int& v : k)
            ++v;
        s.tets.push_back({t < 4 ? 3 : 4, k});
    }
    s.triangles = {{1, {1, 2, 3}}, {1, {2, 4, 3}}, {2, {5, 6, 8}},
                   {2, {5, 7, 8}}, {5, {1, 3, 5}}, {5, {3, 5, 7}}};
    s.names = {"2 1 \"bottom\"", "2 2 \"top\"", "3 3 \"shell\"", "3 4 \"core\""};
    return s;
}

inline void write_names_and_format(std::ostream& os, const MshSpec& s, const char* version) {
    os << "$MeshFormat\n"
       << version << " 0 8\n$EndMeshFormat\n$PhysicalNames\n"
       << s.names.size() << "\n";
    for (const auto& n : s.names)
        os << n << "\n";
    os << "$EndPhysicalNames\n";
}

/// The .msh text of `s` in format 2.2.
inline std::string msh22(const MshSpec& s) {
    std::ostringstream os;
    os.precision(17);
    write_names_and_format(os, s, "2.2");
    os << "$Nodes\n" << s.nodes.size() << "\n";
    for (std::size_t i = 0; i < s.nodes.size(); ++i)
        os << i + 1 << " " << s.nodes[i].x() << " " << s.nodes[i].y() << " " << s.nodes[i].z()
           << "\n";
    os << "$EndNodes\n$Elements\n" << s.lines.size() + s.triangles.size() + s.tets.size() << "\n";
    int id = 1;
    for (const auto& [p, k] : s.lines)
        os << id++ << " 1 2 " << p << " " << p << " " << k[0] << " " << k[1] << "\n";
    for (const auto& [p, k] : s.triangles)
        os << id++ << " 2 2 " << p << " " << p << " " << k[0] << " " << k[1] << " " << k[2] << "\n";
    for (const auto& [p, k] : s.tets)
        os << id++ << " 4 2 " << p << " " << p << " " << k[0] << " " << k[1] << " " << k[2] << " "
           << k[3] << "\n";
    os << "$EndElements\n";
    return os.str();
}

/// The .msh text of `s` in format 4.1: one entity per physical group (entity tag = physical
/// tag), all nodes in one block of volume 1.
inline std::string msh41(const MshSpec& s) {
    std::vector<int> curves, surfaces, volumes;
    for (const auto& t : s.lines)
        curves.push_back(t.first);
    for (const auto& t : s.triangles)
        surfaces.push_back(t.first);
    for (const auto& t : s.tets)
        volumes.push_back(t.first);
    for (auto* v : {&curves, &surfaces, &volumes}) {
        std::sort(v->begin(), v->end());
        v->erase(std::unique(v->begin(), v->end()), v->end());
    }
    std::ostringstream os;
    os.precision(17);
    write_names_and_format(os, s, "4.1");
    os << "$Entities\n0 " << curves.size() << " " << surfaces.size() << " " << volumes.size()
       << "\n";
    for (int p : curves)
        os << p << " -1 -1 -1 2 2 2 1 " << p << " 0\n";
    for (int p : surfaces)
        os << p << " -1 -1 -1 2 2 2 1 " << p << " 0\n";
    for (int p : volumes)
        os << p << " -1 -1 -1 2 2 2 1 " << p << " 0\n";
    os << "$EndEntities\n$Nodes\n1 " << s.nodes.size() << " 1 " << s.nodes.size() << "\n3 "
       << volumes.front() << " 0 " << s.nodes.size() << "\n";
    for (std::size_t i = 0; i < s.nodes.size(); ++i)
        os << i + 1 << "\n";
    for (const auto& x : s.nodes)
        os << x.x() << " " << x.y() << " " << x.z() << "\n";
    const std::size_t n_elements = s.lines.size() + s.triangles.size() + s.tets.size();
    os << "$EndNodes\n$Elements\n"
       << curves.size() + surfaces.size() + volumes.size() << " " << n_elements << " 1 "
       << n_elements << "\n";
    int id = 1;
    for (int p : curves) {
        std::vector<std::array<int, 2>> block;
        for (const auto& [q, k] : s.lines)
            if (q == p) block.push_back(k);
        os << "1 " << p << " 1 " << block.size() << "\n";
        for (const auto& k : block)
            os << id++ << " " << k[0] << " " << k[1] << "\n";
    }
    for (int p : surfaces) {
        std::vector<std::array<int, 3>> block;
        for (const auto& [q, k] : s.triangles)
            if (q == p) block.push_back(k);
        os << "2 " << p << " 2 " << block.size() << "\n";
        for (const auto& k : block)
            os << id++ << " " << k[0] << " " << k[1] << " " << k[2] << "\n";
    }
    for (int p : volumes) {
        std::vector<std::array<int, 4>> block;
        for (const auto& [q, k] : s.tets)
            if (q == p) block.push_back(k);
        os << "3 " << p << " 4 " << block.size() << "\n";
        for (const auto& k : block)
            os << id++ << " " << k[0] << " " << k[1] << " " << k[2] << " " << k[3] << "\n";
    }
    os << "$EndElements\n";
    return os.str();
}

/// The corners of tetrahedron t.
inline std::array<Vec3, 4> corners(const TetMesh& m, int t) {
    std::array<Vec3, 4> x;
    for (int i = 0; i < 4; ++i)
        x[static_cast<size_t>(i)] = m.vertices[static_cast<size_t>(
            m.cells[static_cast<size_t>(t)][static_cast<size_t>(i)])];
    return x;
}

/// The ratio r with a ~ r b (b scaled by r is congruent to a, mirror images allowed) if the two
/// tetrahedra are similar to `tol` (relative to the longest edge), or 0: some relabelling of
/// b's vertices makes its six squared edge lengths proportional to a's. Six distances fix a
/// tetrahedron up to an isometry.
inline double similarity_ratio(const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b,
                               double tol) {
    static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    double sa = 0, sb = 0, la = 0;
    for (const auto& e : kEdges) {
        sa += (a[e[0]] - a[e[1]]).squaredNorm();
        sb += (b[e[0]] - b[e[1]]).squaredNorm();
        la = std::max(la, (a[e[0]] - a[e[1]]).squaredNorm());
    }
    const double r2 = sa / sb;
    std::array<int, 4> p{0, 1, 2, 3};
    do {
        bool match = true;
        for (const auto& e : kEdges)
            match = match && std::abs((a[e[0]] - a[e[1]]).squaredNorm() -
                                      r2 * (b[p[e[0]]] - b[p[e[1]]]).squaredNorm()) <= tol * la;
        if (match) return std::sqrt(r2);
    } while (std::next_permutation(p.begin(), p.end()));
    return 0;
}

/// Runs `f`, expecting an InvalidInput whose message holds every one of `parts`.
template <class F> void expect_invalid(F&& f, const std::vector<std::string>& parts) {
    try {
        f();
        ADD_FAILURE() << "no exception; expected one mentioning '" << parts.front() << "'";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        for (const std::string& p : parts)
            EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
    }
}

} // namespace mlc::mesh::testing
