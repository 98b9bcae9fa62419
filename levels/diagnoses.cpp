// SPDX-License-Identifier: MIT
// Diagnoses of a failed or doubtful solve (see diagnoses.hpp).
#include "levels/diagnoses.hpp"

#include "fem/elasticity.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlc::levels {

namespace {

/// Body index of every vertex (the attribute of a triangle holding it; 0 without attributes).
std::vector<int> vertex_bodies(const Level& L) {
    std::vector<int> body(static_cast<size_t>(L.mesh.n_vertices()), -1);
    for (int t = 0; t < L.mesh.n_cells(); ++t) {
        const int b = L.mesh.attribute.empty() ? 0 : L.mesh.attribute[static_cast<size_t>(t)];
        for (int v : L.mesh.cells[static_cast<size_t>(t)])
            body[static_cast<size_t>(v)] = b;
    }
    return body;
}

std::string point(const Vec2& x) {
    std::ostringstream os;
    os << "(" << x.x() << ", " << x.y() << ")";
    return os.str();
}

std::string body_name(const Problem& p, int b) {
    return b >= 0 && b < static_cast<int>(p.bodies.size()) ? p.bodies[static_cast<size_t>(b)].name
                                                           : std::to_string(b);
}

/// Bodies with a contact node of a two-body pair (as contactor or target): another body may hold
/// them, which the rigid-motion diagnoses below do not model.
std::vector<char> two_body_bodies(const Problem& p, const Level& L, const std::vector<int>& body) {
    std::vector<char> out(p.bodies.size() + 1, 0);
    for (const auto& el : L.contacts) {
        if (p.contacts[static_cast<size_t>(el.pair)].obstacle) continue;
        for (int j = 0; j < el.n_nodes(); ++j) {
            const int b = body[static_cast<size_t>(el.vertex[static_cast<size_t>(j)])];
            if (b >= 0 && static_cast<size_t>(b) < out.size()) out[static_cast<size_t>(b)] = 1;
        }
    }
    return out;
}

} // namespace

std::string r_out_of_scale(double r, double E) {
    if (!(r > 0) || !(E > 0)) return {};
    const double ratio = r / E;
    if (ratio >= kMinROverE && ratio <= kMaxROverE) return {};
    std::ostringstream os;
    os << "augmentation parameter r = " << r << " is " << ratio << " times E = " << E
       << " (the smallest Young's modulus of the scene), "
       << (ratio < kMinROverE ? "below " : "above ")
       << (ratio < kMinROverE ? kMinROverE : kMaxROverE) << " E: "
       << (ratio < kMinROverE
               ? "the contact conditions are then met only loosely (the penetration left grows "
                 "as 1/r) and, further down, the Newton matrices are numerically singular, which "
                 "reads as missing supports"
               : "the contact terms then outweigh the elastic ones in the Newton matrices by "
                 "more than the solver is tested on")
       << "; use r of the order of E (r_over_E = 0.1, the default, or within [" << kMinROverE
       << ", " << kMaxROverE << "])";
    return os.str();
}

Vec2 FreeMotions::at(const Eigen::Vector3d& c, const Vec2& x) const {
    return {c[0] - c[2] * (x.y() - centre.y()) / size, c[1] + c[2] * (x.x() - centre.x()) / size};
}

std::string FreeMotions::describe(const Eigen::Vector3d& c) const {
    const double n = c.norm();
    if (std::abs(c[2]) <= 1e-9 * n) {
        std::ostringstream os;
        os << "translation along (" << c[0] / n << ", " << c[1] / n << ")";
        return os.str();
    }
    // The point the motion leaves in place.
    const Vec2 o(centre.x() - c[1] * size / c[2], centre.y() + c[0] * size / c[2]);
    return "rotation about " + point(o);
}

std::vector<FreeMotions> free_rigid_motions(const Level& L) {
    const std::vector<int> body = vertex_bodies(L);
    int n_bodies = 0;
    for (int b : body)
        n_bodies = std::max(n_bodies, b + 1);
    std::vector<FreeMotions> out(static_cast<size_t>(n_bodies));
    std::vector<Vec2> lo(out.size(), Vec2::Constant(1e300)), hi(out.size(), Vec2::Constant(-1e300));
    std::vector<int> count(out.size(), 0);
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        const int b = body[static_cast<size_t>(v)];
        if (b < 0) continue;
        const Vec2& x = L.mesh.vertices[static_cast<size_t>(v)];
        auto& f = out[static_cast<size_t>(b)];
        f.centre += x;
        lo[static_cast<size_t>(b)] = lo[static_cast<size_t>(b)].cwiseMin(x);
        hi[static_cast<size_t>(b)] = hi[static_cast<size_t>(b)].cwiseMax(x);
        ++count[static_cast<size_t>(b)];
    }
    std::vector<Eigen::Matrix3d> CtC(out.size(), Eigen::Matrix3d::Zero());
    for (size_t b = 0; b < out.size(); ++b) {
        out[b].body = static_cast<int>(b);
        if (count[b] == 0) continue;
        out[b].centre /= count[b];
        out[b].size = std::max((hi[b] - lo[b]).norm(), 1e-300);
    }
    // Each held component is a row of the constraints on the coefficients.
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        const int b = body[static_cast<size_t>(v)];
        if (b < 0) continue;
        const auto& f = out[static_cast<size_t>(b)];
        const Vec2 d = (L.mesh.vertices[static_cast<size_t>(v)] - f.centre) / f.size;
        for (int a = 0; a < 2; ++a)
            if (L.fixed[static_cast<size_t>(v)][static_cast<size_t>(a)]) {
                const Eigen::Vector3d row =
                    a == 0 ? Eigen::Vector3d(1.0, 0.0, -d.y()) : Eigen::Vector3d(0.0, 1.0, d.x());
                CtC[static_cast<size_t>(b)] += row * row.transpose();
            }
    }
    for (size_t b = 0; b < out.size(); ++b) {
        if (count[b] == 0) continue;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(CtC[b]);
        const double top = std::max(es.eigenvalues().maxCoeff(), 1.0);
        for (int k = 0; k < 3; ++k)
            if (es.eigenvalues()[k] <= 1e-10 * top)
                out[b].basis.push_back(es.eigenvectors().col(k));
    }
    return out;
}

std::string no_equilibrium(const Problem& p, const Level& L, double s) {
    const std::vector<int> body = vertex_bodies(L);
    const std::vector<char> two_body = two_body_bodies(p, L, body);
    const Vector F = L.f_nodal_at(s);
    for (const FreeMotions& fm : free_rigid_motions(L)) {
        if (fm.basis.empty() || two_body[static_cast<size_t>(fm.body)]) continue;
        // The loads' work on each basis motion, and their scale.
        Eigen::VectorXd work = Eigen::VectorXd::Zero(static_cast<Index>(fm.basis.size()));
        double load_scale = 0.0;
        Vec2 resultant = Vec2::Zero();
        for (int v = 0; v < L.mesh.n_vertices(); ++v) {
            if (body[static_cast<size_t>(v)] != fm.body) continue;
            const Vec2 f = F.segment<2>(2 * v);
            const Vec2& x = L.mesh.vertices[static_cast<size_t>(v)];
            resultant += f;
            load_scale += f.norm();
            for (size_t k = 0; k < fm.basis.size(); ++k)
                work[static_cast<Index>(k)] += f.dot(fm.at(fm.basis[k], x));
        }
        if (!(load_scale > 0) || work.norm() <= 1e-9 * load_scale) continue;
        std::vector<const contact::ContactElement*> nodes;
        for (const auto& el : L.contacts)
            if (body[static_cast<size_t>(el.vertex[0])] == fm.body) nodes.push_back(&el);
        if (nodes.empty()) continue; // no contact at all: the missing supports diagnosis
        // Candidates: the motion the loads work on most, and each basis motion they work on.
        std::vector<Eigen::Vector3d> cand;
        Eigen::Vector3d steepest = Eigen::Vector3d::Zero();
        for (size_t k = 0; k < fm.basis.size(); ++k)
            steepest += work[static_cast<Index>(k)] * fm.basis[k];
        cand.push_back(steepest);
        for (size_t k = 0; k < fm.basis.size(); ++k)
            if (std::abs(work[static_cast<Index>(k)]) > 1e-9 * load_scale)
                cand.push_back((work[static_cast<Index>(k)] > 0 ? 1.0 : -1.0) * fm.basis[k]);
        for (const Eigen::Vector3d& c : cand) {
            double w = 0.0, mmax = 0.0;
            for (int v = 0; v < L.mesh.n_vertices(); ++v)
                if (body[static_cast<size_t>(v)] == fm.body) {
                    const Vec2 m = fm.at(c, L.mesh.vertices[static_cast<size_t>(v)]);
                    w += F.segment<2>(2 * v).dot(m);
                    mmax = std::max(mmax, m.norm());
                }
            if (!(w > 1e-9 * load_scale * mmax)) continue;
            bool opens = true;
            for (const auto* el : nodes) {
                const Vec2 m = fm.at(c, L.mesh.vertices[static_cast<size_t>(el->vertex[0])]);
                if (el->n.dot(m) < el->mu * std::abs(el->t.dot(m)) - 1e-9 * mmax) {
                    opens = false;
                    break;
                }
            }
            if (!opens) continue;
            std::ostringstream os;
            os << "no equilibrium: the loads pull body '" << body_name(p, fm.body)
               << "' off its contacts: no support holds its rigid " << fm.describe(c)
               << ", the loads (resultant " << point(resultant)
               << ") do positive work on it, and it opens or slides every contact node of the "
                  "body within its friction cone, where a contact force can only push (and "
                  "resist sliding up to mu times the pressure); hold the body with a support, "
                  "or change the loads";
            return os.str();
        }
    }
    return {};
}

Deformation max_deformation(const Level& L, const Vector& u_full) {
    Deformation d;
    for (int t = 0; t < L.mesh.n_cells(); ++t) {
        const auto& tri = L.mesh.cells[static_cast<size_t>(t)];
        double area = 0.0;
        const auto B = fem::strain_matrix(L.mesh.vertices[static_cast<size_t>(tri[0])],
                                          L.mesh.vertices[static_cast<size_t>(tri[1])],
                                          L.mesh.vertices[static_cast<size_t>(tri[2])], area);
        Eigen::Matrix<double, 6, 1> ue;
        for (int i = 0; i < 3; ++i)
            ue.segment<2>(2 * i) = u_full.segment<2>(2 * tri[static_cast<size_t>(i)]);
        const Eigen::Vector3d e = B * ue; // exx, eyy, gamma_xy
        // d uy / dx - d ux / dy: row 2 of B holds d/dy at the ux columns, d/dx at the uy ones.
        double curl = 0.0;
        for (int i = 0; i < 3; ++i)
            curl += B(2, 2 * i + 1) * ue[2 * i + 1] - B(2, 2 * i) * ue[2 * i];
        const double rot = 0.5 * std::abs(curl);
        const double mean = 0.5 * (e[0] + e[1]);
        const double rad = std::hypot(0.5 * (e[0] - e[1]), 0.5 * e[2]);
        const double strain = std::max(std::abs(mean + rad), std::abs(mean - rad));
        if (rot > d.rotation) {
            d.rotation = rot;
            d.rotation_triangle = t;
        }
        if (strain > d.strain) {
            d.strain = strain;
            d.strain_triangle = t;
        }
    }
    return d;
}

std::string unheld_tangential_motion(const Problem& p, const Level& L,
                                     const std::vector<ContactNodeState>& nodes) {
    const std::vector<int> body = vertex_bodies(L);
    const std::vector<char> two_body = two_body_bodies(p, L, body);
    for (const FreeMotions& fm : free_rigid_motions(L)) {
        if (fm.basis.empty() || two_body[static_cast<size_t>(fm.body)]) continue;
        // The free motions tangential at every contact node of the body: the null space of
        // the normal components, within the free ones.
        const Index d = static_cast<Index>(fm.basis.size());
        Eigen::MatrixXd A = Eigen::MatrixXd::Zero(d, d);
        int in_contact = 0, contact_nodes = 0;
        bool all_slip = true;
        for (size_t e = 0; e < L.contacts.size() && e < nodes.size(); ++e) {
            const auto& el = L.contacts[e];
            if (body[static_cast<size_t>(el.vertex[0])] != fm.body) continue;
            ++contact_nodes;
            const Vec2& x = L.mesh.vertices[static_cast<size_t>(el.vertex[0])];
            Eigen::VectorXd row(d);
            for (Index k = 0; k < d; ++k)
                row[k] = el.n.dot(fm.at(fm.basis[static_cast<size_t>(k)], x));
            A += row * row.transpose();
            const auto st = nodes[e].status;
            if (st == contact::Status::gap) continue;
            ++in_contact;
            if (el.frictional() && st == contact::Status::stick) all_slip = false;
        }
        if (contact_nodes == 0 || in_contact == 0 || !all_slip) continue;
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
        const double top = std::max(es.eigenvalues().maxCoeff(), 1.0);
        for (Index k = 0; k < d; ++k) {
            if (es.eigenvalues()[k] > 1e-10 * top) continue;
            Eigen::Vector3d c = Eigen::Vector3d::Zero();
            for (Index j = 0; j < d; ++j)
                c += es.eigenvectors()(j, k) * fm.basis[static_cast<size_t>(j)];
            std::ostringstream os;
            os << "the solution is not unique: every contact node of body '"
               << body_name(p, fm.body) << "' in contact (" << in_contact
               << ") slips, and nothing else holds its rigid " << fm.describe(c)
               << ", which is tangential at every contact node; the same motion added to this "
                  "state gives another solution (add a support that holds it)";
            return os.str();
        }
    }
    return {};
}

} // namespace mlc::levels
