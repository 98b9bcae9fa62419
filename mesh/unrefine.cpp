// SPDX-License-Identifier: MIT
// The inverse of the uniform 1->4 refinement (mesh::unrefine), in phases: the triangles'
// neighbours, the role of each triangle in its coarse one, the coarse vertices and triangles,
// the coarse boundary edges and lines, and the check that refining gives the mesh back.
#include "mesh/mesh.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <array>

namespace mlc::mesh {

namespace {

using Neighbours = std::vector<std::array<int, 3>>;

/// The neighbour across local edge e (opposite local vertex e) of every triangle, -1 on the
/// boundary; nothing when an edge has more than two triangles (no refinement of ours).
std::optional<Neighbours> neighbours(const Mesh& f, const VertexTriangles& vtri) {
    const int nt = f.n_cells();
    Neighbours nb(static_cast<size_t>(nt), {-1, -1, -1});
    for (int t = 0; t < nt; ++t)
        for (int e = 0; e < 3; ++e) {
            const auto& tri = f.cells[static_cast<size_t>(t)];
            const auto on = vtri.on_edge(f, tri[(e + 1) % 3], tri[(e + 2) % 3]);
            if (on.count > 2) return std::nullopt; // a third triangle on an edge
            if (on.count == 2)
                nb[static_cast<size_t>(t)][static_cast<size_t>(e)] =
                    on.first[0] == t ? on.first[1] : on.first[0];
        }
    return nb;
}

/// Labels per triangle: -2 unknown, -1 the middle child of its coarse triangle (its three
/// vertices are midpoints), 0..2 a corner child whose local vertex i is a coarse vertex.
/// Rules of the 1->4 split: across each edge of a middle child lies a corner child whose
/// vertex off that edge is coarse; across a corner child's edge opposite its coarse vertex
/// lies the middle child, across its two other edges corner children of the same vertex.
class ChildLabels {
public:
    ChildLabels(const Mesh& f, const Neighbours& nb)
        : f_(f), nb_(nb), label_(static_cast<size_t>(f.n_cells()), -2) {}

    /// Labels every connected component, trying the four roles of its first triangle; false if
    /// none fits the rules.
    bool label_all() {
        for (int t0 = 0; t0 < f_.n_cells(); ++t0) {
            if (label_[static_cast<size_t>(t0)] != -2) continue;
            bool ok = false;
            for (int guess : {-1, 0, 1, 2}) {
                if (propagate(t0, guess)) {
                    ok = true;
                    break;
                }
                for (int t : touched_)
                    label_[static_cast<size_t>(t)] = -2;
            }
            if (!ok) return false;
        }
        return true;
    }
    const std::vector<int>& labels() const { return label_; }

private:
    int local(int t, int v) const {
        const auto& tri = f_.cells[static_cast<size_t>(t)];
        for (int i = 0; i < 3; ++i)
            if (tri[i] == v) return i;
        return -1;
    }
    bool put(int t, int l) {
        int& cur = label_[static_cast<size_t>(t)];
        if (cur == -2) {
            cur = l;
            touched_.push_back(t);
            stack_.push_back(t);
            return true;
        }
        return cur == l;
    }
    /// Labels seed's component from seed_label by the rules; false at a contradiction.
    bool propagate(int seed, int seed_label) {
        touched_.clear();
        stack_.assign(1, seed);
        label_[static_cast<size_t>(seed)] = seed_label;
        touched_.push_back(seed);
        while (!stack_.empty()) {
            const int t = stack_.back();
            stack_.pop_back();
            const int l = label_[static_cast<size_t>(t)];
            const auto& tri = f_.cells[static_cast<size_t>(t)];
            for (int e = 0; e < 3; ++e) {
                const int n = nb_[static_cast<size_t>(t)][static_cast<size_t>(e)];
                if (l == -1 || e == l) { // a middle child's edge, or a corner's edge off its vertex
                    if (n < 0) return false;
                    if (l == -1) {
                        // n's vertex off the shared edge (tri[e+1], tri[e+2]) is coarse
                        const auto& tn = f_.cells[static_cast<size_t>(n)];
                        int off = -1;
                        for (int i = 0; i < 3; ++i)
                            if (tn[i] != tri[(e + 1) % 3] && tn[i] != tri[(e + 2) % 3]) off = i;
                        if (off < 0 || !put(n, off)) return false;
                    } else if (!put(n, -1)) {
                        return false;
                    }
                } else if (n >= 0) { // a corner's edge through its coarse vertex
                    const int i = local(n, tri[l]);
                    if (i < 0 || !put(n, i)) return false;
                }
            }
        }
        return true;
    }

    const Mesh& f_;
    const Neighbours& nb_;
    std::vector<int> label_;
    std::vector<int> stack_, touched_;
};

/// Coarse vertices: the corners' vertices, copied to c in f's order; per vertex of f its index
/// in c, or -1. Nothing if a triangle holds another number of them than its label says.
std::optional<std::vector<int>> coarse_vertices(const Mesh& f, const std::vector<int>& label,
                                                Mesh& c) {
    const int nt = f.n_cells(), nv = f.n_vertices();
    std::vector<int> coarse_of(static_cast<size_t>(nv), -1);
    for (int t = 0; t < nt; ++t)
        if (const int l = label[static_cast<size_t>(t)]; l >= 0)
            coarse_of[static_cast<size_t>(f.cells[static_cast<size_t>(t)][l])] = 0;
    for (int t = 0; t < nt; ++t) {
        int n_coarse = 0;
        for (int v : f.cells[static_cast<size_t>(t)])
            n_coarse += coarse_of[static_cast<size_t>(v)] == 0;
        if (n_coarse != (label[static_cast<size_t>(t)] >= 0 ? 1 : 0)) return std::nullopt;
    }
    for (int v = 0; v < nv; ++v)
        if (coarse_of[static_cast<size_t>(v)] == 0) {
            coarse_of[static_cast<size_t>(v)] = c.n_vertices();
            c.vertices.push_back(f.vertices[static_cast<size_t>(v)]);
        }
    return coarse_of;
}

/// Each middle child (ab, bc, ca) with the corners across its edges: coarse triangle (a, b, c),
/// a = the coarse vertex across the edge opposite bc, and so on; every corner in one group.
/// Fills edge_of (per midpoint of f: its coarse edge's two vertices of f, else {-1, -1}).
bool coarse_triangles(const Mesh& f, const Neighbours& nb, const std::vector<int>& label,
                      const std::vector<int>& coarse_of, Mesh& c,
                      std::vector<std::array<int, 2>>& edge_of) {
    const int nt = f.n_cells(), nv = f.n_vertices();
    std::vector<char> grouped(static_cast<size_t>(nt), 0);
    edge_of.assign(static_cast<size_t>(nv), {-1, -1});
    auto set_mid = [&](int m, int a, int b) {
        std::array<int, 2> pair{std::min(a, b), std::max(a, b)};
        auto& cur = edge_of[static_cast<size_t>(m)];
        if (cur[0] < 0) cur = pair;
        return cur == pair;
    };
    for (int t = 0; t < nt; ++t) {
        if (label[static_cast<size_t>(t)] != -1) continue;
        const auto& mid = f.cells[static_cast<size_t>(t)];
        std::array<int, 3> p{};
        for (int e = 0; e < 3; ++e) {
            const int n = nb[static_cast<size_t>(t)][static_cast<size_t>(e)];
            if (grouped[static_cast<size_t>(n)]) return false;
            grouped[static_cast<size_t>(n)] = 1;
            p[static_cast<size_t>(e)] =
                f.cells[static_cast<size_t>(n)][label[static_cast<size_t>(n)]];
        }
        grouped[static_cast<size_t>(t)] = 1;
        // mid = (ab, bc, ca): across (bc, ca) lies c = p[0], across (ca, ab) a = p[1], b = p[2].
        const int a = p[1], b = p[2], cc = p[0];
        if (!set_mid(mid[0], a, b) || !set_mid(mid[1], b, cc) || !set_mid(mid[2], cc, a))
            return false;
        c.cells.push_back({coarse_of[static_cast<size_t>(a)], coarse_of[static_cast<size_t>(b)],
                           coarse_of[static_cast<size_t>(cc)]});
        if (!f.attribute.empty()) {
            const int at = f.attribute[static_cast<size_t>(t)];
            for (int e = 0; e < 3; ++e)
                if (f.attribute[static_cast<size_t>(nb[static_cast<size_t>(t)][e])] != at)
                    return false;
            c.attribute.push_back(at);
        }
    }
    return 4 * c.n_cells() == nt;
}

/// Boundary edges or lines: the two halves (a, m), (m, b) of each coarse edge, same tag and
/// curve, m the midpoint of (a, b), joined into out (oriented: a half's direction kept).
bool join_halves(const std::vector<BoundaryEdge>& halves, std::vector<BoundaryEdge>& out,
                 bool oriented, const std::vector<int>& coarse_of,
                 const std::vector<std::array<int, 2>>& edge_of) {
    const size_t nv = coarse_of.size();
    std::vector<int> first(nv, -1);
    for (size_t h = 0; h < halves.size(); ++h) {
        const BoundaryEdge& e = halves[h];
        const bool c0 =
            coarse_of[static_cast<size_t>(e.v0)] >= 0 && edge_of[static_cast<size_t>(e.v0)][0] < 0;
        const bool c1 =
            coarse_of[static_cast<size_t>(e.v1)] >= 0 && edge_of[static_cast<size_t>(e.v1)][0] < 0;
        if (c0 == c1) return false; // one end coarse, one a midpoint
        const int m = c0 ? e.v1 : e.v0;
        int& other = first[static_cast<size_t>(m)];
        if (other < 0) {
            other = static_cast<int>(h);
            continue;
        }
        const BoundaryEdge& g = halves[static_cast<size_t>(other)];
        if (g.tag != e.tag || g.shape != e.shape) return false;
        const int ga = g.v0 == m ? g.v1 : g.v0, ea = c0 ? e.v0 : e.v1;
        const auto& pair = edge_of[static_cast<size_t>(m)];
        if (std::array<int, 2>{std::min(ga, ea), std::max(ga, ea)} != pair) return false;
        int a = ga, b = ea; // unoriented: any order
        if (oriented) {
            if (g.v1 == m && e.v0 == m) {
                a = g.v0;
                b = e.v1;
            } else if (e.v1 == m && g.v0 == m) {
                a = e.v0;
                b = g.v1;
            } else {
                return false;
            }
        }
        out.push_back(
            {coarse_of[static_cast<size_t>(a)], coarse_of[static_cast<size_t>(b)], e.tag, e.shape});
        other = -2;
    }
    for (size_t v = 0; v < nv; ++v)
        if (first[v] >= 0) return false; // an unpaired half
    return true;
}

/// The check that settles it: refining the coarse mesh c gives back f, every vertex within tol
/// and every triangle, boundary half and line half present.
bool refines_to(const Mesh& c, const Mesh& f, const VertexTriangles& vtri,
                const std::vector<int>& coarse_of, const std::vector<std::array<int, 2>>& edge_of,
                double tol) {
    const int nt = f.n_cells(), nv = f.n_vertices(), nc = c.n_vertices();
    Mesh r;
    try {
        r = refine(c);
    } catch (const InvalidInput&) {
        return false; // e.g. an arc whose chord's midpoint is its centre
    }
    if (r.n_vertices() != nv || r.n_cells() != nt || r.boundary.size() != f.boundary.size() ||
        r.lines.size() != f.lines.size())
        return false;
    std::vector<int> to_f(static_cast<size_t>(nv), -1); // r's vertex -> f's
    for (int v = 0; v < nv; ++v) {
        const int cv = coarse_of[static_cast<size_t>(v)];
        if (cv >= 0 && edge_of[static_cast<size_t>(v)][0] < 0) to_f[static_cast<size_t>(cv)] = v;
    }
    // f's midpoint of each coarse edge, listed under the edge's first coarse vertex.
    std::vector<int> mo_off(static_cast<size_t>(nc) + 1, 0);
    std::vector<std::array<int, 2>> mo(static_cast<size_t>(nv - nc)); // (second vertex, midpoint)
    for (int v = 0; v < nv; ++v)
        if (const auto& pr = edge_of[static_cast<size_t>(v)]; pr[0] >= 0)
            ++mo_off[static_cast<size_t>(coarse_of[static_cast<size_t>(pr[0])]) + 1];
    for (int v = 0; v < nc; ++v)
        mo_off[static_cast<size_t>(v) + 1] += mo_off[static_cast<size_t>(v)];
    {
        std::vector<int> fill(mo_off.begin(), mo_off.end() - 1);
        for (int v = 0; v < nv; ++v)
            if (const auto& pr = edge_of[static_cast<size_t>(v)]; pr[0] >= 0) {
                const int a = coarse_of[static_cast<size_t>(pr[0])];
                const int b = coarse_of[static_cast<size_t>(pr[1])];
                mo[static_cast<size_t>(fill[static_cast<size_t>(std::min(a, b))]++)] = {
                    std::max(a, b), v};
            }
    }
    for (int v = nc; v < nv; ++v) {
        const auto& pr = r.parents[static_cast<size_t>(v - nc)]; // (min, max)
        for (int k = mo_off[static_cast<size_t>(pr[0])]; k < mo_off[static_cast<size_t>(pr[0]) + 1];
             ++k)
            if (mo[static_cast<size_t>(k)][0] == pr[1])
                to_f[static_cast<size_t>(v)] = mo[static_cast<size_t>(k)][1];
    }
    for (int v = 0; v < nv; ++v) {
        const int w = to_f[static_cast<size_t>(v)];
        if (w < 0 ||
            (r.vertices[static_cast<size_t>(v)] - f.vertices[static_cast<size_t>(w)]).norm() > tol)
            return false;
    }
    for (const auto& t : r.cells) {
        const int x = to_f[static_cast<size_t>(t[0])], y = to_f[static_cast<size_t>(t[1])],
                  z = to_f[static_cast<size_t>(t[2])];
        bool found = false; // a triangle of f on the edge (x, y) holds z (f's edges hold <= 2)
        for (const int u : vtri.on_edge(f, x, y).first) {
            if (u < 0) continue;
            const auto& tu = f.cells[static_cast<size_t>(u)];
            found = found || tu[0] == z || tu[1] == z || tu[2] == z;
        }
        if (!found) return false;
    }
    return true;
}

} // namespace

std::optional<Mesh> unrefine(const Mesh& f, double tol) {
    const int nt = f.n_cells();
    if (nt < 4 || nt % 4 != 0) return std::nullopt;
    const VertexTriangles vtri = vertex_triangles(f);
    const std::optional<Neighbours> nb = neighbours(f, vtri);
    if (!nb) return std::nullopt;
    ChildLabels labels(f, *nb);
    if (!labels.label_all()) return std::nullopt;
    Mesh c;
    c.shapes = f.shapes;
    c.tag_names = f.tag_names;
    const std::optional<std::vector<int>> coarse_of = coarse_vertices(f, labels.labels(), c);
    if (!coarse_of) return std::nullopt;
    std::vector<std::array<int, 2>> edge_of; // per midpoint of f: its coarse edge's vertices
    if (!coarse_triangles(f, *nb, labels.labels(), *coarse_of, c, edge_of)) return std::nullopt;
    if (!join_halves(f.boundary, c.boundary, true, *coarse_of, edge_of) ||
        !join_halves(f.lines, c.lines, false, *coarse_of, edge_of))
        return std::nullopt;
    if (!refines_to(c, f, vtri, *coarse_of, edge_of, tol)) return std::nullopt;
    return c;
}

} // namespace mlc::mesh
