// SPDX-License-Identifier: MIT
// Contact element kinematics and residual (Alart, Barboteu & Lebon 1997, eqs. 9-11).
#include "contact/element.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace mlc::contact {

std::string_view to_string(FacetIntegration f) {
    switch (f) {
    case FacetIntegration::nodal:
        return "nodal";
    case FacetIntegration::segment:
        return "segment";
    case FacetIntegration::dual:
        return "dual";
    }
    return "?";
}

template <int dim>
std::vector<BasicContactElement<dim>>
node_on_rigid(const mesh::SimplexMesh<dim>& m, const std::vector<int>& contactors,
              const BasicObstacle<dim>& obstacle, double mu, double r, int pair) {
    std::vector<BasicContactElement<dim>> out;
    out.reserve(contactors.size());
    for (int v : contactors) {
        BasicContactElement<dim> e; // vertex {-1}, weight {1}
        e.vertex[0] = v;
        obstacle.frame(m.vertices[static_cast<size_t>(v)], e.n, e.g0);
        e.t = tangent_basis<dim>(e.n);
        e.mu = mu;
        e.r = r;
        e.pair = pair;
        out.push_back(e);
    }
    return out;
}

namespace {
/// Sets the local frame (n, t = tangent_basis(n): 2D (n_y, -n_x)), initial gap and pair data of
/// a two-body element.
template <int dim>
BasicContactElement<dim> with_frame(BasicContactElement<dim> e,
                                    const Eigen::Matrix<double, dim, 1>& n, double g0, double mu,
                                    double r, int pair) {
    e.n = n;
    e.t = tangent_basis<dim>(n);
    e.g0 = g0;
    e.mu = mu;
    e.r = r;
    e.pair = pair;
    return e;
}
} // namespace

ContactElement node_on_facet(int c, int a, int b, double alpha, const Vec2& n, double g0, double mu,
                             double r, int pair) {
    MLC_CHECK(alpha >= 0.0 && alpha <= 1.0,
              "node_on_facet: barycentric coordinate alpha must lie in [0, 1], found " << alpha);
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_facet: the normal must have unit length, found |n| = " << n.norm());
    MLC_CHECK(c != a && c != b,
              "node_on_facet: contactor vertex " << c << " is an end of its facet");
    ContactElement e;
    e.vertex = {c, a, b};
    e.weight = {1.0, -(1.0 - alpha), -alpha};
    return with_frame<2>(std::move(e), n, g0, mu, r, pair);
}

template <int dim>
BasicContactElement<dim> node_on_facet_weighted(int c, const std::vector<int>& targets,
                                                const std::vector<double>& weights,
                                                const Eigen::Matrix<double, dim, 1>& n, double g0,
                                                double mu, double r, int pair) {
    MLC_CHECK(targets.size() == weights.size(),
              "node_on_facet_weighted: " << targets.size() << " target vertices but "
                                         << weights.size() << " weights");
    MLC_CHECK(!targets.empty(),
              "node_on_facet_weighted: contactor vertex " << c << " has no target vertex");
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_facet_weighted: the normal must have unit length, found |n| = " << n.norm());
    BasicContactElement<dim> e;
    e.vertex.reserve(1 + targets.size());
    e.weight.reserve(1 + targets.size());
    e.vertex[0] = c;
    double sum = 0.0;
    for (size_t k = 0; k < targets.size(); ++k) {
        MLC_CHECK(targets[k] != c,
                  "node_on_facet_weighted: contactor vertex " << c << " is its own target");
        for (size_t j = 0; j < k; ++j)
            MLC_CHECK(targets[j] != targets[k],
                      "node_on_facet_weighted: target vertex " << targets[k] << " repeats");
        MLC_CHECK(std::isfinite(weights[k]), "node_on_facet_weighted: weight of target vertex "
                                                 << targets[k] << " is not finite");
        e.vertex.push_back(targets[k]);
        e.weight.push_back(weights[k]);
        sum += weights[k];
    }
    MLC_CHECK(std::abs(sum + 1.0) < 1e-10,
              "node_on_facet_weighted: the target weights sum to " << sum << ", not -1");
    return with_frame<dim>(std::move(e), n, g0, mu, r, pair);
}

template <int dim>
BasicContactElement<dim> node_on_node(int c, int a, const Eigen::Matrix<double, dim, 1>& n,
                                      double g0, double mu, double r, int pair) {
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_node: the normal must have unit length, found |n| = " << n.norm());
    MLC_CHECK(c != a, "node_on_node: contactor vertex " << c << " is its own target");
    BasicContactElement<dim> e;
    e.vertex = {c, a};
    e.weight = {1.0, -1.0};
    return with_frame<dim>(std::move(e), n, g0, mu, r, pair);
}

template <int dim>
HeldComponents
held_components(const BasicContactElement<dim>& e,
                const std::type_identity_t<std::vector<std::array<bool, dim>>>& fixed) {
    using Element = BasicContactElement<dim>;
    std::array<bool, dim> held; // components prescribed at every vertex
    held.fill(true);
    for (int j = 0; j < e.n_nodes(); ++j) {
        if (e.weight[static_cast<size_t>(j)] == 0.0) continue;
        const auto& f = fixed[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])];
        for (size_t c = 0; c < dim; ++c)
            held[c] = held[c] && f[c];
    }
    HeldComponents out;
    if (std::none_of(held.begin(), held.end(), [](bool h) { return h; })) return out;
    // The part of a unit direction along the components left free somewhere.
    auto is_held = [&](const typename Element::Point& g) {
        double free2 = 0.0;
        for (int c = 0; c < dim; ++c)
            if (!held[static_cast<size_t>(c)]) free2 += g[c] * g[c];
        return std::sqrt(free2) <= kHeldDirectionTolerance;
    };
    if (is_held(e.n)) {
        out.pinned = Element::kPinnedN;
        if (e.frictional()) out.pinned |= Element::kPinnedT;
        return out;
    }
    if (!e.frictional()) return out; // n alone, not held, never along the held span then
    int tangents_held = 0;
    for (int c = 0; c < dim - 1; ++c)
        tangents_held += is_held(e.t.col(c)) ? 1 : 0;
    if (tangents_held == dim - 1) {
        out.pinned = Element::kPinnedT;
        return out;
    }
    if constexpr (dim == 3) {
        // One component c held, and n across it: the tangent along e_c carries no force (the
        // support takes it), the other tangent n x e_c is free. The frame is turned so that t1
        // is (the part across n of) e_c: its multiplier is pinned alone.
        const auto n_held = std::count(held.begin(), held.end(), true);
        for (int c = 0; c < dim; ++c)
            if (n_held == 1 && held[static_cast<size_t>(c)] &&
                std::abs(e.n[c]) <= kHeldDirectionTolerance) {
                out.pinned = Element::kPinnedT1;
                out.pinned_axis = c;
                return out;
            }
    }
    // The frame spans the space: it meets the held components without lying in them.
    out.ambiguous = true;
    return out;
}

template <int dim>
BasicElementState<dim> evaluate(const BasicContactElement<dim>& e, const Vector& u_full,
                                const Vector& u_prev_full, const Vector& x, int lambda_dof) {
    using Element = BasicContactElement<dim>;
    using Point = typename Element::Point;
    Point du = Point::Zero(), du_prev = Point::Zero();
    for (int j = 0; j < e.n_nodes(); ++j) {
        const int v = e.vertex[static_cast<size_t>(j)];
        du += e.weight[static_cast<size_t>(j)] * u_full.segment<dim>(dim * v);
        du_prev += e.weight[static_cast<size_t>(j)] * u_prev_full.segment<dim>(dim * v);
    }
    BasicElementState<dim> s;
    s.d_n = e.g0 + e.n.dot(du);
    for (int c = 0; c < dim - 1; ++c)
        s.d_t[c] = e.t.col(c).dot(du - du_prev);
    if (e.frictional())
        for (int q = 0; q < dim; ++q)
            s.lambda[q] = x[lambda_dof + q];
    else
        s.lambda[dim - 1] = x[lambda_dof];
    if (e.pinned & Element::kPinnedN) return s; // Phi = 0, M = 0, status gap
    using Tangential = Eigen::Matrix<double, dim - 1, 1>;
    if (e.frictional()) {
        // Pinned tangents project as sigma_t = 0: the status follows the normal alone.
        // A pinned first tangent (3D) projects with sigma_t1 = 0: the law acts on t2 alone.
        const bool pin_t = (e.pinned & Element::kPinnedT) != 0;
        const bool pin_t1 = (e.pinned & Element::kPinnedT1) != 0;
        Tangential sigma_t = Tangential::Zero();
        if (!pin_t) sigma_t = s.lambda.template head<dim - 1>() + e.r * s.d_t;
        if (pin_t1) sigma_t[0] = 0.0;
        s.proj = project<dim>(sigma_t, s.lambda[dim - 1] + e.r * s.d_n, e.mu);
        if (pin_t) {
            s.proj.phi.template head<dim - 1>().setZero();
            s.proj.M.template topRows<dim - 1>().setZero();
            s.proj.M.template leftCols<dim - 1>().setZero();
        } else if (pin_t1) {
            s.proj.phi[0] = 0.0;
            s.proj.M.row(0).setZero();
            s.proj.M.col(0).setZero();
        }
    } else {
        s.proj = project<dim>(Tangential::Zero(), s.lambda[dim - 1] + e.r * s.d_n, 0.0);
        // no tangential unknown: keep M_tt out of the tangent
        s.proj.M.template topLeftCorner<dim - 1, dim - 1>().setZero();
    }
    return s;
}

template <int dim>
void add_residual(const BasicContactElement<dim>& e, const BasicElementState<dim>& s,
                  const fem::BasicDofMap<dim>& dofs, int lambda_dof, Vector& R) {
    using Point = typename BasicContactElement<dim>::Point;
    Point force = s.proj.phi[dim - 1] * e.n;
    for (int c = 0; c < dim - 1; ++c)
        force += s.proj.phi[c] * e.t.col(c);
    for (int j = 0; j < e.n_nodes(); ++j) {
        const int v = e.vertex[static_cast<size_t>(j)];
        for (int a = 0; a < dim; ++a)
            if (int d = dofs.u_dof(v, a); d >= 0)
                R[d] += e.weight[static_cast<size_t>(j)] * force[a];
    }
    if (e.frictional()) {
        for (int q = 0; q < dim; ++q)
            R[lambda_dof + q] = -(s.lambda[q] - s.proj.phi[q]) / e.r;
    } else {
        R[lambda_dof] = -(s.lambda[dim - 1] - s.proj.phi[dim - 1]) / e.r;
    }
}

void turn_first_tangent_onto_axis(BasicContactElement<3>& e, int axis) {
    MLC_CHECK(axis >= 0 && axis < 3, "turn_first_tangent_onto_axis: axis " << axis);
    Eigen::Vector3d t1 = Eigen::Vector3d::Unit(axis);
    t1 -= t1.dot(e.n) * e.n;
    MLC_CHECK(t1.norm() > 0.5, "turn_first_tangent_onto_axis: the normal lies along axis " << axis);
    t1.normalize();
    e.t.col(0) = t1;
    e.t.col(1) = e.n.cross(t1);
}

#define MLC_CONTACT_ELEMENT(dim)                                                                   \
    template std::vector<BasicContactElement<dim>> node_on_rigid<dim>(                             \
        const mesh::SimplexMesh<dim>&, const std::vector<int>&, const BasicObstacle<dim>&, double, \
        double, int);                                                                              \
    template HeldComponents held_components<dim>(                                                  \
        const BasicContactElement<dim>&,                                                           \
        const std::type_identity_t<std::vector<std::array<bool, dim>>>&);                          \
    template BasicElementState<dim> evaluate<dim>(const BasicContactElement<dim>&, const Vector&,  \
                                                  const Vector&, const Vector&, int);              \
    template void add_residual<dim>(const BasicContactElement<dim>&,                               \
                                    const BasicElementState<dim>&, const fem::BasicDofMap<dim>&,   \
                                    int, Vector&);                                                 \
    template BasicContactElement<dim> node_on_facet_weighted<dim>(                                 \
        int, const std::vector<int>&, const std::vector<double>&,                                  \
        const Eigen::Matrix<double, dim, 1>&, double, double, double, int);                        \
    template BasicContactElement<dim> node_on_node<dim>(                                           \
        int, int, const Eigen::Matrix<double, dim, 1>&, double, double, double, int);
MLC_CONTACT_ELEMENT(2)
MLC_CONTACT_ELEMENT(3)
#undef MLC_CONTACT_ELEMENT

} // namespace mlc::contact
