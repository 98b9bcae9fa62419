// SPDX-License-Identifier: MIT
/// @file The key of an unoriented edge (its two vertices, smaller first, in 64 bits), shared by
/// refinement of triangles (mesh.cpp) and tetrahedra (tet_refine.cpp), the conformity checks
/// (mesh_checks.cpp) and the CGAL mesher. Internal to mlc_mesh.
#pragma once

#include <cstdint>
#include <utility>

namespace mlc::mesh::detail {

inline std::uint64_t edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
}

} // namespace mlc::mesh::detail
