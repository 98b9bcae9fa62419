// SPDX-License-Identifier: MIT
// The nodal P of a 1->4 or 1->8 refinement, its component expansion and its restriction to free
// unknowns (docs/theory.md#theory-transfer).
#include "transfer/prolongation.hpp"

#include "core/check.hpp"

#include <algorithm>

namespace mlc::transfer {

template <int dim> MovableSparseMatrix vertex_prolongation(const mesh::SimplexMesh<dim>& fine) {
    const int nf = fine.n_vertices();
    const int nc = fine.n_coarse_vertices;
    MLC_CHECK(nc > 0 && static_cast<int>(fine.parents.size()) == nf - nc,
              "vertex_prolongation: the fine mesh must come from mesh::refine; found "
                  << nc << " coarse vertices, " << nf << " vertices and " << fine.parents.size()
                  << " parent pairs");
    MovableSparseMatrix P;
    P.resize(nf, nc);
    P.resizeNonZeros(nc + 2 * (nf - nc));
    int* outer = P.outerIndexPtr();
    int* inner = P.innerIndexPtr();
    double* value = P.valuePtr();
    int k = 0;
    outer[0] = 0;
    for (int v = 0; v < nf; ++v) {
        if (v < nc) {
            inner[k] = v;
            value[k++] = 1.0;
        } else {
            std::array<int, 2> pr = fine.parents[static_cast<size_t>(v - nc)];
            MLC_CHECK(pr[0] >= 0 && pr[0] < nc && pr[1] >= 0 && pr[1] < nc && pr[0] != pr[1],
                      "vertex_prolongation: new vertex "
                          << v << " has parents (" << pr[0] << ", " << pr[1]
                          << "), expected two distinct coarse vertices in 0.." << nc - 1);
            if (pr[1] < pr[0]) std::swap(pr[0], pr[1]);
            for (int p : pr) {
                inner[k] = p;
                value[k++] = 0.5;
            }
        }
        outer[v + 1] = k;
    }
    return P;
}

template MovableSparseMatrix vertex_prolongation(const mesh::SimplexMesh<2>&);
template MovableSparseMatrix vertex_prolongation(const mesh::SimplexMesh<3>&);

MovableSparseMatrix expand_components(const SparseMatrix& P_vertex, int dim) {
    MLC_CHECK(dim >= 1 && dim <= 3,
              "expand_components: " << dim << " components per vertex; expected 1, 2 or 3");
    const auto d = static_cast<Index>(dim);
    MovableSparseMatrix P;
    P.resize(d * P_vertex.rows(), d * P_vertex.cols());
    P.resizeNonZeros(d * P_vertex.nonZeros());
    int* outer = P.outerIndexPtr();
    int* inner = P.innerIndexPtr();
    double* value = P.valuePtr();
    int k = 0;
    outer[0] = 0;
    for (Index i = 0; i < P_vertex.outerSize(); ++i)
        for (int c = 0; c < dim; ++c) {
            for (SparseMatrix::InnerIterator it(P_vertex, i); it; ++it) {
                inner[k] = dim * static_cast<int>(it.index()) + c;
                value[k++] = it.value();
            }
            outer[dim * i + c + 1] = k;
        }
    return P;
}

namespace {

/// Checks one level's unknowns: one entry per vertex, indices in 0..n-1, none used twice.
void check_unknowns(const VertexUnknowns& u, int dim, Index n_vertices, int n_unknowns,
                    const char* level) {
    MLC_CHECK(static_cast<Index>(u.size()) == n_vertices,
              "restrict_to_unknowns: the " << level << " numbering has " << u.size()
                                           << " vertices, P " << n_vertices);
    std::vector<char> used(static_cast<size_t>(std::max(n_unknowns, 0)), 0);
    for (size_t v = 0; v < u.size(); ++v)
        for (int c = 0; c < dim; ++c) {
            const int i = u[v][static_cast<size_t>(c)];
            if (i < 0) continue;
            MLC_CHECK(i < n_unknowns, "restrict_to_unknowns: component "
                                          << c << " of " << level << " vertex " << v
                                          << " has unknown " << i << ", outside 0.."
                                          << n_unknowns - 1);
            MLC_CHECK(!used[static_cast<size_t>(i)], "restrict_to_unknowns: " << level
                                                                              << " unknown " << i
                                                                              << " is used twice "
                                                                                 "(vertex "
                                                                              << v << ")");
            used[static_cast<size_t>(i)] = 1;
        }
}

} // namespace

MovableSparseMatrix restrict_to_unknowns(const SparseMatrix& P_vertex, int dim,
                                         const VertexUnknowns& coarse, int n_coarse_unknowns,
                                         const VertexUnknowns& fine, int n_fine_unknowns) {
    MLC_CHECK(dim >= 1 && dim <= 3,
              "restrict_to_unknowns: " << dim << " components per vertex; expected 1, 2 or 3");
    check_unknowns(coarse, dim, P_vertex.cols(), n_coarse_unknowns, "coarse");
    check_unknowns(fine, dim, P_vertex.rows(), n_fine_unknowns, "fine");
    std::vector<Triplet> t;
    t.reserve(static_cast<size_t>(dim * P_vertex.nonZeros()));
    for (Index v = 0; v < P_vertex.outerSize(); ++v) {
        const auto& fv = fine[static_cast<size_t>(v)];
        int entries = 0;
        Index p0 = -1;
        double w0 = 0.0;
        for (SparseMatrix::InnerIterator it(P_vertex, v); it; ++it, ++entries) {
            p0 = it.index();
            w0 = it.value();
        }
        const bool unit_row = entries == 1 && w0 == 1.0; // a coarse vertex kept
        for (int c = 0; c < dim; ++c) {
            const int row = fv[static_cast<size_t>(c)];
            if (unit_row) {
                const int col = coarse[static_cast<size_t>(p0)][static_cast<size_t>(c)];
                MLC_CHECK((row < 0) == (col < 0),
                          "restrict_to_unknowns: component "
                              << c << " of coarse vertex " << p0 << " is "
                              << (col < 0 ? "" : "not ") << "prescribed on the coarse level but "
                              << (row < 0 ? "" : "not ") << "on the fine one (fine vertex " << v
                              << "); supports must nest");
            }
            if (row < 0) continue;
            for (SparseMatrix::InnerIterator it(P_vertex, v); it; ++it) {
                const int col = coarse[static_cast<size_t>(it.index())][static_cast<size_t>(c)];
                if (col >= 0) t.emplace_back(row, col, it.value());
            }
        }
    }
    MovableSparseMatrix P;
    P.resize(n_fine_unknowns, n_coarse_unknowns);
    P.setFromTriplets(t.begin(), t.end());
    return P;
}

} // namespace mlc::transfer
