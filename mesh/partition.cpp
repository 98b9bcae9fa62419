// SPDX-License-Identifier: MIT
// METIS k-way partition of the dual graph of a triangle or tetrahedral mesh.
#include "mesh/partition.hpp"

#include "core/check.hpp"

#include <metis.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>

namespace mlc::mesh {

double Partition::imbalance() const {
    if (part_work.empty()) return 1.0;
    const double total = std::accumulate(part_work.begin(), part_work.end(), 0.0);
    const double mean = total / static_cast<double>(part_work.size());
    return mean > 0 ? *std::max_element(part_work.begin(), part_work.end()) / mean : 1.0;
}

namespace {

/// Whether every cell is reachable from cell 0 through shared facets.
bool dual_graph_connected(const std::vector<std::vector<idx_t>>& adj) {
    if (adj.empty()) return true;
    std::vector<char> seen(adj.size(), 0);
    std::vector<idx_t> stack{0};
    seen[0] = 1;
    size_t reached = 1;
    while (!stack.empty()) {
        const idx_t t = stack.back();
        stack.pop_back();
        for (idx_t u : adj[static_cast<size_t>(t)])
            if (!seen[static_cast<size_t>(u)]) {
                seen[static_cast<size_t>(u)] = 1;
                ++reached;
                stack.push_back(u);
            }
    }
    return reached == adj.size();
}

/// The facet of cell `cell` opposite its local vertex k (2D: the edge from vertex k + 1 to
/// k + 2; 3D: the face without vertex k), sorted.
template <int dim> std::array<int, dim> facet(const typename SimplexMesh<dim>::Cell& cell, int k) {
    std::array<int, dim> f{};
    for (int i = 0; i < dim; ++i)
        f[static_cast<size_t>(i)] = cell[static_cast<size_t>((k + 1 + i) % (dim + 1))];
    std::sort(f.begin(), f.end());
    return f;
}

/// partition_triangles and partition_tets: `cells` names the cells in messages.
template <int dim>
Partition partition_cells(const SimplexMesh<dim>& m, int parts, const std::vector<int>& weights,
                          const char* cells) {
    const int nt = m.n_cells();
    MLC_CHECK(parts >= 1, "a partition needs at least one part, found " << parts);
    MLC_CHECK(parts <= nt, "cannot split " << nt << " " << cells << " into " << parts << " parts");
    MLC_CHECK(weights.empty() || static_cast<int>(weights.size()) == nt,
              "partition weights: " << weights.size() << " for " << nt << " " << cells);
    for (int w : weights)
        MLC_CHECK(w > 0, "partition weights must be positive, found " << w);
    // Dual graph: cells sharing a facet (each facet seen from both sides).
    std::map<std::array<int, dim>, int> first_side;
    std::vector<std::vector<idx_t>> adj(static_cast<size_t>(nt));
    for (int t = 0; t < nt; ++t) {
        const auto& cell = m.cells[static_cast<size_t>(t)];
        for (int k = 0; k <= dim; ++k) {
            auto [it, fresh] = first_side.emplace(facet<dim>(cell, k), t);
            if (!fresh) {
                adj[static_cast<size_t>(t)].push_back(it->second);
                adj[static_cast<size_t>(it->second)].push_back(t);
            }
        }
    }
    Partition p;
    p.parts = parts;
    p.triangle_part.assign(static_cast<size_t>(nt), 0);
    if (parts > 1) {
        std::vector<idx_t> xadj(static_cast<size_t>(nt) + 1, 0), adjncy, vwgt;
        for (int t = 0; t < nt; ++t) {
            auto& a = adj[static_cast<size_t>(t)];
            std::sort(a.begin(), a.end());
            adjncy.insert(adjncy.end(), a.begin(), a.end());
            xadj[static_cast<size_t>(t) + 1] = static_cast<idx_t>(adjncy.size());
        }
        if (!weights.empty()) vwgt.assign(weights.begin(), weights.end());
        idx_t n = nt, ncon = 1, np = parts, objval = 0;
        idx_t options[METIS_NOPTIONS];
        METIS_SetDefaultOptions(options);
        // Connected parts (each process one piece) where the mesh is connected; METIS cannot
        // make them on a mesh of several bodies (it fails), so there the parts may be in pieces.
        options[METIS_OPTION_CONTIG] = dual_graph_connected(adj) ? 1 : 0;
        options[METIS_OPTION_SEED] = 1; // reproducible
        std::vector<idx_t> part(static_cast<size_t>(nt), 0);
        const int rc = METIS_PartGraphKway(&n, &ncon, xadj.data(), adjncy.data(),
                                           vwgt.empty() ? nullptr : vwgt.data(), nullptr, nullptr,
                                           &np, nullptr, nullptr, options, &objval, part.data());
        MLC_CHECK(rc == METIS_OK, "METIS could not partition the mesh into "
                                      << parts << " parts (status " << rc << ")");
        p.triangle_part.assign(part.begin(), part.end());
    }
    p.part_work.assign(static_cast<size_t>(parts), 0.0);
    for (int t = 0; t < nt; ++t)
        p.part_work[static_cast<size_t>(p.triangle_part[static_cast<size_t>(t)])] +=
            weights.empty() ? 1.0 : weights[static_cast<size_t>(t)];
    for (int t = 0; t < nt; ++t)
        for (idx_t u : adj[static_cast<size_t>(t)])
            if (u > t &&
                p.triangle_part[static_cast<size_t>(t)] != p.triangle_part[static_cast<size_t>(u)])
                ++p.cut_edges;
    // Vertex owners: the part with most cells around the vertex, ties to the lower part.
    const int nv = m.n_vertices();
    std::vector<std::map<int, int>> count(static_cast<size_t>(nv));
    for (int t = 0; t < nt; ++t)
        for (int v : m.cells[static_cast<size_t>(t)])
            ++count[static_cast<size_t>(v)][p.triangle_part[static_cast<size_t>(t)]];
    p.vertex_owner.assign(static_cast<size_t>(nv), 0);
    for (int v = 0; v < nv; ++v) {
        int best = -1, best_count = 0;
        for (const auto& [part, c] : count[static_cast<size_t>(v)]) // parts in increasing order
            if (c > best_count) {
                best = part;
                best_count = c;
            }
        MLC_CHECK(best >= 0, "vertex " << v << " belongs to no " << SimplexTraits<dim>::cell_name);
        p.vertex_owner[static_cast<size_t>(v)] = best;
    }
    return p;
}

} // namespace

Partition partition_triangles(const Mesh& m, int parts, const std::vector<int>& weights) {
    return partition_cells(m, parts, weights, "triangles");
}

Partition partition_tets(const TetMesh& m, int parts, const std::vector<int>& weights) {
    return partition_cells(m, parts, weights, "tetrahedra");
}

} // namespace mlc::mesh
