// SPDX-License-Identifier: MIT
// Contact element kinematics and residual (Alart, Barboteu & Lebon 1997, eqs. 9-11).
#include "contact/element.hpp"

#include "core/check.hpp"

#include <cmath>

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

std::vector<ContactElement> node_on_rigid(const mesh::Mesh& m, const std::vector<int>& contactors,
                                          const Obstacle& obstacle, double mu, double r, int pair) {
    std::vector<ContactElement> out;
    out.reserve(contactors.size());
    for (int v : contactors) {
        ContactElement e;
        e.n_nodes = 1;
        e.vertex[0] = v;
        e.weight[0] = 1.0;
        obstacle.frame(m.vertices[static_cast<size_t>(v)], e.n, e.g0);
        e.t = Vec2(e.n.y(), -e.n.x());
        e.mu = mu;
        e.r = r;
        e.pair = pair;
        out.push_back(e);
    }
    return out;
}

namespace {
/// Sets the local frame (n, t = (n_y, -n_x)), initial gap and pair data of a two-body element.
ContactElement with_frame(ContactElement e, const Vec2& n, double g0, double mu, double r,
                          int pair) {
    e.n = n;
    e.t = Vec2(n.y(), -n.x());
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
    e.n_nodes = 3;
    e.vertex[0] = c;
    e.vertex[1] = a;
    e.vertex[2] = b;
    e.weight[0] = 1.0;
    e.weight[1] = -(1.0 - alpha);
    e.weight[2] = -alpha;
    return with_frame(e, n, g0, mu, r, pair);
}

ContactElement node_on_facet_weighted(int c, const std::vector<int>& targets,
                                      const std::vector<double>& weights, const Vec2& n, double g0,
                                      double mu, double r, int pair) {
    constexpr int max_targets = ContactElement::kMaxNodes - 1;
    MLC_CHECK(targets.size() == weights.size(),
              "node_on_facet_weighted: " << targets.size() << " target vertices but "
                                         << weights.size() << " weights");
    MLC_CHECK(!targets.empty() && static_cast<int>(targets.size()) <= max_targets,
              "node on facet (segment integration): contactor vertex "
                  << c << " touches " << targets.size() << " target vertices, at most "
                  << max_targets
                  << " are supported (the target mesh is much finer than the contactor's there: "
                     "refine the contactor, swap contactor and target, or use integration = "
                     "\"nodal\")");
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_facet_weighted: the normal must have unit length, found |n| = " << n.norm());
    ContactElement e;
    e.n_nodes = 1 + static_cast<int>(targets.size());
    e.vertex[0] = c;
    e.weight[0] = 1.0;
    double sum = 0.0;
    for (size_t k = 0; k < targets.size(); ++k) {
        MLC_CHECK(targets[k] != c,
                  "node_on_facet_weighted: contactor vertex " << c << " is its own target");
        for (size_t j = 0; j < k; ++j)
            MLC_CHECK(targets[j] != targets[k],
                      "node_on_facet_weighted: target vertex " << targets[k] << " repeats");
        MLC_CHECK(std::isfinite(weights[k]), "node_on_facet_weighted: weight of target vertex "
                                                 << targets[k] << " is not finite");
        e.vertex[k + 1] = targets[k];
        e.weight[k + 1] = weights[k];
        sum += weights[k];
    }
    MLC_CHECK(std::abs(sum + 1.0) < 1e-10,
              "node_on_facet_weighted: the target weights sum to " << sum << ", not -1");
    return with_frame(e, n, g0, mu, r, pair);
}

ContactElement node_on_node(int c, int a, const Vec2& n, double g0, double mu, double r, int pair) {
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_node: the normal must have unit length, found |n| = " << n.norm());
    MLC_CHECK(c != a, "node_on_node: contactor vertex " << c << " is its own target");
    ContactElement e;
    e.n_nodes = 2;
    e.vertex[0] = c;
    e.vertex[1] = a;
    e.weight[0] = 1.0;
    e.weight[1] = -1.0;
    return with_frame(e, n, g0, mu, r, pair);
}

HeldComponents held_components(const ContactElement& e,
                               const std::vector<std::array<bool, 2>>& fixed) {
    std::array<bool, 2> held = {true, true}; // components prescribed at every vertex
    for (int j = 0; j < e.n_nodes; ++j) {
        if (e.weight[static_cast<size_t>(j)] == 0.0) continue;
        const auto& f = fixed[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])];
        for (size_t c = 0; c < 2; ++c)
            held[c] = held[c] && f[c];
    }
    HeldComponents out;
    if (!held[0] && !held[1]) return out;
    // The part of a unit direction along the components left free somewhere.
    auto is_held = [&](const Vec2& g) {
        double free2 = 0.0;
        for (int c = 0; c < 2; ++c)
            if (!held[static_cast<size_t>(c)]) free2 += g[c] * g[c];
        return std::sqrt(free2) <= kHeldDirectionTolerance;
    };
    if (is_held(e.n)) {
        out.pinned = ContactElement::kPinnedN;
        if (e.frictional()) out.pinned |= ContactElement::kPinnedT;
        return out;
    }
    if (!e.frictional()) return out; // n alone, not held, never along the held span then
    if (is_held(e.t)) {
        out.pinned = ContactElement::kPinnedT;
        return out;
    }
    // (t, n) spans the plane: it meets the held components without lying in them.
    out.ambiguous = true;
    return out;
}

ElementState evaluate(const ContactElement& e, const Vector& u_full, const Vector& u_prev_full,
                      const Vector& x, int lambda_dof) {
    Vec2 du = Vec2::Zero(), du_prev = Vec2::Zero();
    for (int j = 0; j < e.n_nodes; ++j) {
        const int v = e.vertex[static_cast<size_t>(j)];
        du += e.weight[static_cast<size_t>(j)] * u_full.segment<2>(2 * v);
        du_prev += e.weight[static_cast<size_t>(j)] * u_prev_full.segment<2>(2 * v);
    }
    ElementState s;
    s.d_n = e.g0 + e.n.dot(du);
    s.d_t = e.t.dot(du - du_prev);
    if (e.frictional())
        s.lambda = {x[lambda_dof], x[lambda_dof + 1]};
    else
        s.lambda = {0.0, x[lambda_dof]};
    if (e.pinned & ContactElement::kPinnedN) return s; // Phi = 0, M = 0, status gap
    if (e.frictional()) {
        // A pinned tangent projects as sigma_t = 0: the status follows the normal alone.
        const bool pin_t = (e.pinned & ContactElement::kPinnedT) != 0;
        s.proj = project(pin_t ? 0.0 : s.lambda[0] + e.r * s.d_t, s.lambda[1] + e.r * s.d_n, e.mu);
        if (pin_t) {
            s.proj.phi[0] = 0.0;
            s.proj.M.row(0).setZero();
            s.proj.M.col(0).setZero();
        }
    } else {
        s.proj = project(0.0, s.lambda[1] + e.r * s.d_n, 0.0);
        s.proj.M(0, 0) = 0.0; // no tangential unknown: keep M_tt out of the tangent
    }
    return s;
}

void add_residual(const ContactElement& e, const ElementState& s, const fem::DofMap& dofs,
                  int lambda_dof, Vector& R) {
    const Vec2 force = s.proj.phi[0] * e.t + s.proj.phi[1] * e.n;
    for (int j = 0; j < e.n_nodes; ++j) {
        const int v = e.vertex[static_cast<size_t>(j)];
        for (int a = 0; a < 2; ++a)
            if (int d = dofs.u_dof(v, a); d >= 0)
                R[d] += e.weight[static_cast<size_t>(j)] * force[a];
    }
    if (e.frictional()) {
        R[lambda_dof] = -(s.lambda[0] - s.proj.phi[0]) / e.r;
        R[lambda_dof + 1] = -(s.lambda[1] - s.proj.phi[1]) / e.r;
    } else {
        R[lambda_dof] = -(s.lambda[1] - s.proj.phi[1]) / e.r;
    }
}

} // namespace mlc::contact
