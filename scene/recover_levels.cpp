// SPDX-License-Identifier: MIT
// The levels of a scene whose Gmsh meshes are uniform refinements (see reader.hpp).
#include "levels/level.hpp"
#include "mesh/mesh.hpp"
#include "scene/reader.hpp"

#include <algorithm>

namespace mlc::scene::detail {

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

} // namespace mlc::scene::detail
