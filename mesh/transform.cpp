// SPDX-License-Identifier: MIT
// Mirroring a half-domain mesh and merging the meshes of several bodies.
#include "mesh/transform.hpp"

#include "core/check.hpp"

#include <cmath>

namespace mlc::mesh {

Mesh mirror_about_x(const Mesh& h, double x0) {
    const double tol = 1e-10 * h.diameter();
    const int nv = h.n_vertices();
    Mesh m = h;
    m.boundary.clear();
    m.lines.clear();
    std::vector<int> image(static_cast<size_t>(nv));
    int side = 0;
    bool on_line = false;
    for (int v = 0; v < nv; ++v) {
        const Vec2 p = h.vertices[static_cast<size_t>(v)];
        if (std::abs(p.x() - x0) <= tol) {
            image[static_cast<size_t>(v)] = v;
            on_line = true;
            continue;
        }
        const int sv = p.x() > x0 ? 1 : -1;
        MLC_CHECK(side == 0 || sv == side, "mirror_x = " << x0 << ": the domain has vertices on "
                                                         << "both sides of the mirror line; "
                                                         << "describe one half only");
        side = sv;
        image[static_cast<size_t>(v)] = m.n_vertices();
        m.vertices.emplace_back(2.0 * x0 - p.x(), p.y());
    }
    MLC_CHECK(on_line, "mirror_x = " << x0 << ": no boundary vertex lies on the mirror line; the "
                                     << "half domain must have an edge on it");
    for (const auto& t : h.cells)
        m.cells.push_back({image[static_cast<size_t>(t[0])], image[static_cast<size_t>(t[2])],
                           image[static_cast<size_t>(t[1])]});
    if (!h.attribute.empty())
        m.attribute.insert(m.attribute.end(), h.attribute.begin(), h.attribute.end());
    const int coff = static_cast<int>(h.shapes.size());
    for (const auto& c : h.shapes)
        m.shapes.push_back({Vec2(2.0 * x0 - c.center.x(), c.center.y()), c.radius});
    auto on = [&](int v) { return image[static_cast<size_t>(v)] == v; };
    for (const auto& e : h.boundary) {
        if (e.shape < 0 && on(e.v0) && on(e.v1)) { // on the mirror line: now an interior line
            m.lines.push_back({e.v0, e.v1, e.tag, -1});
            continue;
        }
        m.boundary.push_back(e);
        m.boundary.push_back({image[static_cast<size_t>(e.v1)], image[static_cast<size_t>(e.v0)],
                              e.tag, e.shape >= 0 ? e.shape + coff : -1});
    }
    for (const auto& e : h.lines) {
        m.lines.push_back(e);
        if (!(on(e.v0) && on(e.v1)))
            m.lines.push_back(
                {image[static_cast<size_t>(e.v1)], image[static_cast<size_t>(e.v0)], e.tag, -1});
    }
    check_quality(m);
    return m;
}

namespace {
/// cos and sin of an angle in degrees, exact at multiples of 90.
std::pair<double, double> cos_sin_deg(double deg) {
    const double q = deg / 90.0;
    if (q == std::round(q)) {
        const long k = ((static_cast<long>(std::round(q)) % 4) + 4) % 4;
        static constexpr double c[4] = {1.0, 0.0, -1.0, 0.0}, s[4] = {0.0, 1.0, 0.0, -1.0};
        return {c[k], s[k]};
    }
    const double a = deg * std::acos(-1.0) / 180.0;
    return {std::cos(a), std::sin(a)};
}
} // namespace

Vec2 RigidMotion::apply(const Vec2& p) const {
    const auto [c, s] = cos_sin_deg(rotate_deg);
    const Vec2 d = p - about;
    return about + Vec2(c * d.x() - s * d.y(), s * d.x() + c * d.y()) + translate;
}

Vec2 RigidMotion::inverse(const Vec2& p) const {
    const auto [c, s] = cos_sin_deg(rotate_deg);
    const Vec2 d = p - translate - about;
    return about + Vec2(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
}

bool RigidMotion::keeps_axes() const {
    const double q = rotate_deg / 90.0;
    return q == std::round(q);
}

void transform_mesh(Mesh& m, const RigidMotion& motion) {
    for (auto& v : m.vertices)
        v = motion.apply(v);
    for (auto& c : m.shapes)
        c.center = motion.apply(c.center);
}

template <int dim> void merge_into(SimplexMesh<dim>& all, const SimplexMesh<dim>& b, int body) {
    const int voff = all.n_vertices();
    const int soff = static_cast<int>(all.shapes.size());
    all.vertices.insert(all.vertices.end(), b.vertices.begin(), b.vertices.end());
    all.shapes.insert(all.shapes.end(), b.shapes.begin(), b.shapes.end());
    for (auto c : b.cells) {
        for (int& v : c)
            v += voff;
        all.cells.push_back(c);
    }
    all.attribute.resize(all.cells.size(), body);
    for (auto f : b.boundary) {
        if constexpr (dim == 2) {
            f.v0 += voff;
            f.v1 += voff;
        } else {
            for (int& v : f.v)
                v += voff;
        }
        f.tag = all.add_tag(b.tag_name(f.tag));
        f.shape = f.shape >= 0 ? f.shape + soff : -1;
        all.boundary.push_back(f);
    }
    for (const auto& e : b.lines)
        all.lines.push_back({e.v0 + voff, e.v1 + voff, all.add_tag(b.tag_name(e.tag)), -1});
}

template void merge_into(SimplexMesh<2>&, const SimplexMesh<2>&, int);
template void merge_into(SimplexMesh<3>&, const SimplexMesh<3>&, int);

} // namespace mlc::mesh
