// SPDX-License-Identifier: MIT
#include "mesh/lattice.hpp"

#include "core/check.hpp"

#include <array>

namespace mlc::mesh {

std::optional<MacroLattice> macro_lattice(const Mesh& fine, int depth) {
    MLC_CHECK(depth >= 0 && depth <= 14, "macro_lattice: depth " << depth << " out of [0, 14]");
    const long nt = fine.n_cells();
    const long per_macro = 1L << (2 * depth);
    if (nt == 0 || nt % per_macro != 0) return std::nullopt;
    MacroLattice L;
    L.n = 1 << depth;
    L.n_macros = static_cast<int>(nt / per_macro);
    const int n = L.n;
    const long np = MacroLattice::interior_points(n);
    L.vertex.assign(static_cast<size_t>(np * L.n_macros), -1);
    // Where each vertex sits: the first (macro, point) that claimed it, or a lattice point on a
    // macro's boundary (-2): a vertex is interior to one macro or on the boundary of all its ones.
    std::vector<long> claim(static_cast<size_t>(fine.n_vertices()), -1);
    using P = std::array<int, 2>;
    for (long t = 0; t < nt; ++t) {
        const long m = t / per_macro;
        std::array<P, 3> c{P{0, 0}, P{n, 0}, P{0, n}};
        for (int s = depth - 1; s >= 0; --s) {
            const int k = static_cast<int>((t >> (2 * s)) & 3);
            auto mid = [](P a, P b) { return P{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2}; };
            const P a = c[0], b = c[1], cc = c[2];
            const P ab = mid(a, b), bc = mid(b, cc), ca = mid(cc, a);
            if (k == 0)
                c = {a, ab, ca};
            else if (k == 1)
                c = {ab, b, bc};
            else if (k == 2)
                c = {ca, bc, cc};
            else
                c = {ab, bc, ca};
        }
        for (int q = 0; q < 3; ++q) {
            const int v = fine.cells[static_cast<size_t>(t)][static_cast<size_t>(q)];
            const int i = c[static_cast<size_t>(q)][0], j = c[static_cast<size_t>(q)][1];
            const bool interior = i >= 1 && j >= 1 && i + j <= n - 1;
            const long id = interior ? m * np + MacroLattice::point_index(n, i, j) : -2;
            long& cl = claim[static_cast<size_t>(v)];
            if (cl == -1)
                cl = id;
            else if (cl != id)
                return std::nullopt; // one vertex on two lattice points
            if (interior) {
                int& slot = L.vertex[static_cast<size_t>(id)];
                if (slot != -1 && slot != v) return std::nullopt; // two vertices on one point
                slot = v;
            }
        }
    }
    for (int v : L.vertex)
        if (v < 0) return std::nullopt;
    return L;
}

std::vector<int> lattice_vertex_order(const Mesh& fine, const MacroLattice& lattice) {
    const size_t nv = static_cast<size_t>(fine.n_vertices());
    const long per_macro = lattice.n_macros > 0 ? fine.n_cells() / lattice.n_macros : 1;
    std::vector<int> macro_of(nv, -1);
    for (long t = 0; t < fine.n_cells(); ++t) {
        const int m = static_cast<int>(t / per_macro);
        for (int v : fine.cells[static_cast<size_t>(t)]) {
            int& k = macro_of[static_cast<size_t>(v)];
            if (k < 0 || m < k) k = m;
        }
    }
    std::vector<char> interior(nv, 0);
    for (int v : lattice.vertex)
        interior[static_cast<size_t>(v)] = 1;
    std::vector<std::vector<int>> rim(static_cast<size_t>(lattice.n_macros) + 1);
    for (size_t v = 0; v < nv; ++v)
        if (!interior[v])
            rim[macro_of[v] < 0 ? rim.size() - 1 : static_cast<size_t>(macro_of[v])].push_back(
                static_cast<int>(v));
    std::vector<int> order;
    order.reserve(nv);
    const long np = MacroLattice::interior_points(lattice.n);
    for (int m = 0; m < lattice.n_macros; ++m) {
        order.insert(order.end(), lattice.vertex.begin() + m * np,
                     lattice.vertex.begin() + (m + 1) * np);
        order.insert(order.end(), rim[static_cast<size_t>(m)].begin(),
                     rim[static_cast<size_t>(m)].end());
    }
    order.insert(order.end(), rim.back().begin(), rim.back().end());
    return order;
}

} // namespace mlc::mesh
