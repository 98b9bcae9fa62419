// SPDX-License-Identifier: MIT
// Q on a contact surface in mass form: lumped surface masses, P restricted to the surface, and
// the transfer of nodal forces in global and in per-node components (docs/theory.md#theory-q).
#include "transfer/surface_q.hpp"

#include "core/check.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace mlc::transfer {

template <int F> SurfaceVertices surface_vertices(const SurfaceFacets<F>& facets, int n_vertices) {
    SurfaceVertices s;
    s.index.assign(static_cast<size_t>(std::max(n_vertices, 0)), -1);
    for (size_t f = 0; f < facets.size(); ++f)
        for (int a = 0; a < F; ++a) {
            const int v = facets[f][static_cast<size_t>(a)];
            MLC_CHECK(v >= 0 && v < n_vertices, "surface_vertices: facet " << f << " has vertex "
                                                                           << v << ", outside 0.."
                                                                           << n_vertices - 1);
            for (int b = 0; b < a; ++b)
                MLC_CHECK(facets[f][static_cast<size_t>(b)] != v,
                          "surface_vertices: facet " << f << " has vertex " << v << " twice");
            s.index[static_cast<size_t>(v)] = 0;
        }
    for (int v = 0; v < n_vertices; ++v)
        if (s.index[static_cast<size_t>(v)] == 0) {
            s.index[static_cast<size_t>(v)] = s.size();
            s.vertex.push_back(v);
        }
    return s;
}

template <int F> double facet_measure(const SurfacePoints& x, const std::array<int, F>& facet) {
    static_assert(F == 2 || F == 3, "facets are segments (F = 2) or triangles (F = 3)");
    const Eigen::Vector3d& a = x[static_cast<size_t>(facet[0])];
    const Eigen::Vector3d& b = x[static_cast<size_t>(facet[1])];
    if constexpr (F == 2)
        return (b - a).norm();
    else
        return 0.5 * (b - a).cross(x[static_cast<size_t>(facet[2])] - a).norm();
}

template <int F>
Vector lumped_surface_masses(const SurfacePoints& x, const SurfaceFacets<F>& facets,
                             const SurfaceVertices& s) {
    Vector m = Vector::Zero(s.size());
    for (size_t f = 0; f < facets.size(); ++f) {
        for (int v : facets[f])
            MLC_CHECK(v >= 0 && static_cast<size_t>(v) < x.size() &&
                          static_cast<size_t>(v) < s.index.size() &&
                          s.index[static_cast<size_t>(v)] >= 0,
                      "lumped_surface_masses: facet " << f << " has vertex " << v
                                                      << ", which is not a surface vertex of "
                                                      << x.size() << " points");
        const double measure = facet_measure<F>(x, facets[f]);
        MLC_CHECK(measure > 0, "lumped_surface_masses: facet " << f << " has zero measure");
        for (int v : facets[f])
            m[s.index[static_cast<size_t>(v)]] += measure / F;
    }
    return m;
}

namespace {

/// P restricted to the surface: the row of fine surface vertex v is the unit row of its coarse
/// surface index (v < n_coarse) or 1/2 at both parents' coarse surface indices.
MovableSparseMatrix surface_prolongation(const SurfaceVertices& coarse, const SurfaceVertices& fine,
                                         const VertexParents& parents, int n_coarse) {
    const int nf = fine.size();
    MovableSparseMatrix P;
    P.resize(nf, coarse.size());
    P.resizeNonZeros(2 * nf);
    int* outer = P.outerIndexPtr();
    int* inner = P.innerIndexPtr();
    double* value = P.valuePtr();
    int k = 0;
    outer[0] = 0;
    for (int i = 0; i < nf; ++i) {
        const int v = fine.vertex[static_cast<size_t>(i)];
        if (v < n_coarse) {
            const int c = coarse.index[static_cast<size_t>(v)];
            MLC_CHECK(c >= 0, "build_surface_q: fine surface vertex "
                                  << v << " is a coarse vertex but not on the coarse surface");
            inner[k] = c;
            value[k++] = 1.0;
        } else {
            const auto& pr = parents[static_cast<size_t>(v - n_coarse)];
            std::array<int, 2> c{-1, -1};
            for (size_t p = 0; p < 2; ++p) {
                MLC_CHECK(pr[p] >= 0 && pr[p] < n_coarse, "build_surface_q: new vertex "
                                                              << v << " has parent " << pr[p]
                                                              << ", outside 0.." << n_coarse - 1);
                c[p] = coarse.index[static_cast<size_t>(pr[p])];
                MLC_CHECK(c[p] >= 0, "build_surface_q: fine surface vertex "
                                         << v << " has parent " << pr[p]
                                         << ", which is not on the coarse surface");
            }
            MLC_CHECK(c[0] != c[1],
                      "build_surface_q: new vertex " << v << " has the same parent twice");
            if (c[1] < c[0]) std::swap(c[0], c[1]);
            for (int p : c) {
                inner[k] = p;
                value[k++] = 0.5;
            }
        }
        outer[i + 1] = k;
    }
    P.resizeNonZeros(k);
    return P;
}

} // namespace

template <int F>
SurfaceQ build_surface_q(const SurfacePoints& coarse_points, const SurfaceFacets<F>& coarse_facets,
                         const SurfacePoints& fine_points, const SurfaceFacets<F>& fine_facets,
                         const VertexParents& parents, CoarseMass rule) {
    const int nc = static_cast<int>(coarse_points.size());
    MLC_CHECK(fine_points.size() == coarse_points.size() + parents.size(),
              "build_surface_q: " << fine_points.size() << " fine points, expected "
                                  << coarse_points.size() << " coarse + " << parents.size()
                                  << " new vertices");
    SurfaceQ q;
    q.rule = rule;
    q.coarse = surface_vertices<F>(coarse_facets, nc);
    q.fine = surface_vertices<F>(fine_facets, static_cast<int>(fine_points.size()));
    for (int v : q.coarse.vertex)
        MLC_CHECK(q.fine.index[static_cast<size_t>(v)] >= 0,
                  "build_surface_q: coarse surface vertex " << v << " is not on the fine surface");
    q.coarse_mass = lumped_surface_masses<F>(coarse_points, coarse_facets, q.coarse);
    q.fine_mass = lumped_surface_masses<F>(fine_points, fine_facets, q.fine);
    q.P = surface_prolongation(q.coarse, q.fine, parents, nc);
    q.coarse_mass_on_fine = q.P.transpose() * q.fine_mass;
    const Vector& divisor = rule == CoarseMass::own ? q.coarse_mass : q.coarse_mass_on_fine;
    q.Q = q.P;
    for (Index i = 0; i < q.Q.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(q.Q, i); it; ++it)
            it.valueRef() *= q.fine_mass[i] / divisor[it.index()];
    return q;
}

SurfaceForces transfer_forces(const SurfaceQ& q, const SurfaceForces& coarse) {
    MLC_CHECK(coarse.rows() == q.Q.cols(),
              "transfer_forces: " << coarse.rows() << " coarse forces, expected " << q.Q.cols()
                                  << " surface vertices");
    return SurfaceForces(q.Q * coarse);
}

namespace {

void check_frames(const std::vector<NodeFrame>& frames, Index n, const char* level) {
    MLC_CHECK(static_cast<Index>(frames.size()) == n,
              "transfer_local_forces: " << frames.size() << " " << level << " frames, expected "
                                        << n << " surface vertices");
    constexpr double tol = 1e-10;
    for (size_t i = 0; i < frames.size(); ++i) {
        Eigen::Matrix3d B;
        B << frames[i].t1, frames[i].t2, frames[i].n;
        MLC_CHECK((B.transpose() * B - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tol,
                  "transfer_local_forces: the frame of " << level << " surface vertex " << i
                                                         << " is not orthonormal");
    }
}

} // namespace

SurfaceForces transfer_local_forces(const SurfaceQ& q, const SurfaceForces& coarse_local,
                                    const std::vector<NodeFrame>& coarse_frames,
                                    const std::vector<NodeFrame>& fine_frames) {
    check_frames(coarse_frames, q.Q.cols(), "coarse");
    check_frames(fine_frames, q.Q.rows(), "fine");
    MLC_CHECK(coarse_local.rows() == q.Q.cols(),
              "transfer_local_forces: " << coarse_local.rows() << " coarse nodes, expected "
                                        << q.Q.cols());
    SurfaceForces global(coarse_local.rows(), 3);
    for (Index i = 0; i < global.rows(); ++i)
        global.row(i) =
            to_global(coarse_frames[static_cast<size_t>(i)], coarse_local.row(i).transpose())
                .transpose();
    const SurfaceForces fine_global = q.Q * global;
    SurfaceForces out(fine_global.rows(), 3);
    for (Index j = 0; j < out.rows(); ++j)
        out.row(j) = to_local(fine_frames[static_cast<size_t>(j)], fine_global.row(j).transpose())
                         .transpose();
    return out;
}

template SurfaceVertices surface_vertices<2>(const SurfaceFacets<2>&, int);
template SurfaceVertices surface_vertices<3>(const SurfaceFacets<3>&, int);
template double facet_measure<2>(const SurfacePoints&, const std::array<int, 2>&);
template double facet_measure<3>(const SurfacePoints&, const std::array<int, 3>&);
template Vector lumped_surface_masses<2>(const SurfacePoints&, const SurfaceFacets<2>&,
                                         const SurfaceVertices&);
template Vector lumped_surface_masses<3>(const SurfacePoints&, const SurfaceFacets<3>&,
                                         const SurfaceVertices&);
template SurfaceQ build_surface_q<2>(const SurfacePoints&, const SurfaceFacets<2>&,
                                     const SurfacePoints&, const SurfaceFacets<2>&,
                                     const VertexParents&, CoarseMass);
template SurfaceQ build_surface_q<3>(const SurfacePoints&, const SurfaceFacets<3>&,
                                     const SurfacePoints&, const SurfaceFacets<3>&,
                                     const VertexParents&, CoarseMass);

} // namespace mlc::transfer
