// SPDX-License-Identifier: MIT
// Contact element kinematics and residual (Alart, Barboteu & Lebon 1997, eqs. 9-11).
#include "contact/element.hpp"

#include "core/check.hpp"

#include <cmath>

namespace mlc::contact {

std::vector<ContactElement> node_on_rigid(const mesh::Mesh& m, const std::vector<int>& contactors,
                                          const Obstacle& obstacle, double mu, double r, int pair) {
    std::vector<ContactElement> out;
    out.reserve(contactors.size());
    for (int v : contactors) {
        ContactElement e;
        e.n_nodes = 1;
        e.vertex = {v, -1, -1};
        e.weight = {1.0, 0.0, 0.0};
        obstacle.frame(m.vertices[static_cast<size_t>(v)], e.n, e.g0);
        e.t = Vec2(e.n.y(), -e.n.x());
        e.mu = mu;
        e.r = r;
        e.pair = pair;
        out.push_back(e);
    }
    return out;
}

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
    e.vertex = {c, a, b};
    e.weight = {1.0, -(1.0 - alpha), -alpha};
    e.n = n;
    e.t = Vec2(n.y(), -n.x());
    e.g0 = g0;
    e.mu = mu;
    e.r = r;
    e.pair = pair;
    return e;
}

ContactElement node_on_node(int c, int a, const Vec2& n, double g0, double mu, double r, int pair) {
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_node: the normal must have unit length, found |n| = " << n.norm());
    MLC_CHECK(c != a, "node_on_node: contactor vertex " << c << " is its own target");
    ContactElement e;
    e.n_nodes = 2;
    e.vertex = {c, a, -1};
    e.weight = {1.0, -1.0, 0.0};
    e.n = n;
    e.t = Vec2(n.y(), -n.x());
    e.g0 = g0;
    e.mu = mu;
    e.r = r;
    e.pair = pair;
    return e;
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
    if (e.frictional()) {
        s.lambda = {x[lambda_dof], x[lambda_dof + 1]};
        s.proj = project(s.lambda[0] + e.r * s.d_t, s.lambda[1] + e.r * s.d_n, e.mu);
    } else {
        s.lambda = {0.0, x[lambda_dof]};
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
