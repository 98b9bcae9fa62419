// SPDX-License-Identifier: MIT
/// @file Total area and volume of the test meshes.
#pragma once

#include "mesh/mesh.hpp"
#include "mesh/tet_mesh.hpp"

#include <cmath>

namespace mlc::mesh::testing {

/// Sum of the triangles' signed areas.
inline double total_area(const Mesh& m) {
    double a = 0;
    for (int t = 0; t < m.n_cells(); ++t)
        a += m.signed_measure(t);
    return a;
}

/// Sum of the tetrahedra's volumes (either orientation).
inline double total_volume(const TetMesh& m) {
    double v = 0;
    for (int t = 0; t < m.n_cells(); ++t)
        v += std::abs(m.signed_measure(t));
    return v;
}

} // namespace mlc::mesh::testing
