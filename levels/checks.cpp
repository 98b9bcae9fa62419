// SPDX-License-Identifier: MIT
// Physics checks of a converged state: force balance and the contact conditions.
#include "levels/checks.hpp"

#include "fem/assembly.hpp"

#include <algorithm>
#include <cmath>

namespace mlc::levels {

double force_balance_error(const Level& level, double s, const Vector& u_full,
                           const std::vector<ContactNodeState>& nodes) {
    // External forces on the body: loads F, contact forces -C (C = sum_j w_j (lambda_t t +
    // lambda_n n), the multiplier being the force the body exerts), and support reactions
    // Rs = K u - F + C on the fixed components (nodal equilibrium K u = F - C + Rs). The
    // resultant F - C + Rs must vanish per axis; K u is recomputed element by element.
    const Vector Ku = fem::internal_forces(level.mesh, level.materials, u_full);
    const Vector F = level.f_nodal_at(s);
    Vector C = Vector::Zero(Ku.size());
    for (size_t e = 0; e < level.contacts.size(); ++e) {
        const auto& el = level.contacts[e];
        const Vec2 f = nodes[e].lambda_t * el.t + nodes[e].lambda_n * el.n;
        for (int j = 0; j < el.n_nodes; ++j)
            C.segment<2>(2 * el.vertex[static_cast<size_t>(j)]) +=
                el.weight[static_cast<size_t>(j)] * f;
    }
    double err = 0.0, total = 0.0;
    for (int a = 0; a < 2; ++a) {
        double resultant = 0.0, magnitude = 0.0;
        for (int v = 0; v < level.mesh.n_vertices(); ++v) {
            const int i = 2 * v + a;
            const double Rs = level.fixed[static_cast<size_t>(v)][static_cast<size_t>(a)]
                                  ? Ku[i] - F[i] + C[i]
                                  : 0.0;
            resultant += F[i] - C[i] + Rs;
            magnitude += std::abs(F[i]) + std::abs(C[i]) + std::abs(Rs);
        }
        err = std::max(err, std::abs(resultant));
        total = std::max(total, magnitude);
    }
    return total > 0 ? err / total : err;
}

StateChecks check_state(const Problem& p, const RunResult& r) {
    StateChecks c;
    const auto& L = r.finest();
    c.force_balance = force_balance_error(L, 1.0, r.u_full, r.nodes);
    double lmax = 0.0;
    for (const auto& n : r.nodes)
        lmax = std::max(lmax, std::abs(n.lambda_n));
    const double umax = r.u_full.size() ? r.u_full.cwiseAbs().maxCoeff() : 0.0;
    for (size_t e = 0; e < r.nodes.size(); ++e) {
        const auto& n = r.nodes[e];
        const double mu = p.contacts[static_cast<size_t>(L.contacts[e].pair)].mu;
        const double excess = std::abs(n.lambda_t) - mu * std::abs(n.lambda_n);
        // At open nodes lambda = 0 up to round-off: the cone test is meaningful in contact only.
        if (n.status != contact::Status::gap)
            c.coulomb_excess = std::max(c.coulomb_excess, std::max(excess, 0.0));
        if (L.contacts[e].frictional() && (n.status == contact::Status::slip_forward ||
                                           n.status == contact::Status::slip_backward))
            c.slip_equality = std::max(c.slip_equality, std::abs(excess));
        c.complementarity = std::max(c.complementarity, std::abs(n.lambda_n * n.d_n));
        c.penetration = std::max(c.penetration, std::max(-n.d_n, 0.0));
        c.tension = std::max(c.tension, std::max(n.lambda_n, 0.0));
    }
    if (lmax > 0) {
        c.coulomb_excess /= lmax;
        c.slip_equality /= lmax;
        c.tension /= lmax;
        if (umax > 0) c.complementarity /= lmax * umax;
    }
    if (umax > 0) c.penetration /= umax;
    return c;
}

Vec2 contact_resultant(const RunResult& r, int pair, int* in_contact) {
    const auto& L = r.finest();
    Vec2 f = Vec2::Zero();
    int closed = 0;
    for (size_t e = 0; e < L.contacts.size() && e < r.nodes.size(); ++e) {
        if (L.contacts[e].pair != pair) continue;
        f -= r.nodes[e].lambda_t * L.contacts[e].t + r.nodes[e].lambda_n * L.contacts[e].n;
        closed += r.nodes[e].status != contact::Status::gap;
    }
    if (in_contact) *in_contact = closed;
    return f;
}

} // namespace mlc::levels
