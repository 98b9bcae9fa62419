// SPDX-License-Identifier: MIT
// Accuracy study of the 3D scenes: Hertz (hertz3d, sphere_punch) and the patch test (punch3d).
#include "core/check.hpp"
#include "core/timer.hpp"
#include "studies/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>

namespace mlc::apps {

namespace {

constexpr double kNaN3 = std::numeric_limits<double>::quiet_NaN();

/// The sphere of a Hertz scene: the obstacle's (sphere_punch) or the curved surface the
/// contactor faces lie on (hertz3d).
mesh::CurvedSurface hertz_sphere(const levels::ElasticProblem3& p) {
    MLC_CHECK(p.contacts.size() == 1, "hertz (3D): one contact pair expected, found "
                                          << p.contacts.size());
    const auto& c = p.contacts.front();
    mesh::CurvedSurface s;
    if (c.obstacle.kind == contact::BasicObstacle<3>::Kind::sphere) {
        s.center = c.obstacle.center;
        s.radius = c.obstacle.radius;
        return s;
    }
    const int tag = p.mesh0.tag(c.contactor);
    for (const auto& f : p.mesh0.boundary)
        if (f.tag == tag && f.shape >= 0 &&
            p.mesh0.shapes[static_cast<size_t>(f.shape)].kind ==
                mesh::CurvedSurface::Kind::sphere)
            return p.mesh0.shapes[static_cast<size_t>(f.shape)];
    MLC_CHECK(false, "hertz (3D): neither the obstacle nor the contactor '"
                         << c.contactor << "' is a sphere");
    return s;
}

} // namespace

std::vector<AccuracyValue> accuracy_values3(const levels::ElasticProblem3& p,
                                            const levels::RunResult3& r) {
    MLC_CHECK(r.converged, p.name << ": the run did not converge: " << r.failure);
    const auto& L = r.finest();
    const auto areas = levels::contact_areas(p, L);
    std::vector<AccuracyValue> out;
    if (p.name == "hertz3d" || p.name == "sphere_punch") {
        // A quarter model: the full load is four times the contact force.
        const auto sphere = hertz_sphere(p);
        const auto& mat = p.bodies.front().material;
        const double E_star = mat.E / (1.0 - mat.nu * mat.nu);
        double P = 0.0;
        for (const auto& n : r.nodes)
            P -= 4.0 * n.lambda_n;
        const double R = sphere.radius;
        const double a = std::cbrt(3.0 * P * R / (4.0 * E_star));
        const double p0 = 3.0 * P / (2.0 * std::numbers::pi * a * a);
        // Radial distance from the axis through the sphere's centre along z.
        auto radius = [&](const mesh::Vec3& x) {
            return std::hypot(x.x() - sphere.center.x(), x.y() - sphere.center.y());
        };
        double r_in = 0.0, p_axis = 0.0, r_axis = std::numeric_limits<double>::infinity();
        for (size_t e = 0; e < r.nodes.size(); ++e) {
            const double ri = radius(r.nodes[e].x);
            if (r.nodes[e].status != contact::Status::gap) r_in = std::max(r_in, ri);
            if (ri < r_axis) {
                r_axis = ri;
                p_axis = areas[e] > 0 ? -r.nodes[e].lambda_n / areas[e] : 0.0;
            }
        }
        // The contact radius: midway between the farthest node in contact and the nearest gap
        // node beyond it.
        double r_out = std::numeric_limits<double>::infinity();
        for (const auto& n : r.nodes)
            if (n.status == contact::Status::gap && radius(n.x) > r_in)
                r_out = std::min(r_out, radius(n.x));
        const double a_meas = std::isfinite(r_out) ? 0.5 * (r_in + r_out) : r_in;
        const double spacing = std::isfinite(r_out) ? r_out - r_in : 0.0;
        double sum2 = 0.0;
        int count = 0;
        for (size_t e = 0; e < r.nodes.size(); ++e) {
            const double ri = radius(r.nodes[e].x);
            if (ri >= 0.9 * a || areas[e] <= 0) continue;
            const double pc = p0 * std::sqrt(1.0 - ri * ri / (a * a));
            sum2 += std::pow(-r.nodes[e].lambda_n / areas[e] - pc, 2);
            ++count;
        }
        const double rms = count > 0 ? std::sqrt(sum2 / count) / p0 : kNaN3;
        out.push_back({"P", P, P, kNaN3, "contact resultant x 4 (quarter model)"});
        out.push_back({"radius", a_meas, a, (a_meas - a) / a,
                       "relative; midway between the last node in contact and the next"});
        out.push_back({"node_spacing_over_a", spacing / a, spacing / a, kNaN3,
                       "radial gap between those two nodes, / a"});
        out.push_back({"peak_pressure", p_axis, p0, (p_axis - p0) / p0,
                       "relative; pressure of the node nearest the axis"});
        out.push_back({"profile_rms", rms, 0.0, rms, "rms of p - p_closed over r < 0.9 a, / p0"});
        return out;
    }
    if (p.name == "punch3d") {
        // The exact solution: the load's pressure at every contact node.
        MLC_CHECK(!p.loads.empty(), "punch3d: no load");
        const double pe = p.loads.front().pressure;
        double err = 0.0, total = 0.0, area = 0.0;
        for (size_t e = 0; e < r.nodes.size(); ++e) {
            err = std::max(err, std::abs(-r.nodes[e].lambda_n / areas[e] - pe) / pe);
            total -= r.nodes[e].lambda_n;
            area += areas[e];
        }
        out.push_back({"pressure_max", err, 0.0, err, "max |p - p_load| / p_load"});
        out.push_back({"resultant", std::abs(total - pe * area) / (pe * area), 0.0,
                       std::abs(total - pe * area) / (pe * area), "relative"});
        return out;
    }
    MLC_CHECK(false, "the accuracy study knows closed forms for the 3D scenes hertz3d, "
                     "sphere_punch and punch3d only, not '"
                         << p.name << "'");
    return out;
}

int study_accuracy3(const levels::ElasticProblem3& problem_in, const AccuracyOptions& opt,
                    std::ostream& os) {
    MLC_CHECK(opt.levels >= 0 && opt.levels <= 4,
              "the 3D accuracy study needs --levels between 0 and 4, found " << opt.levels);
    levels::ElasticProblem3 problem = problem_in;
    const auto dir =
        opt.out.empty() ? std::filesystem::path("out") / problem.name / "accuracy" : opt.out;
    std::filesystem::create_directories(dir);
    os << "accuracy study: scene '" << problem.name << "' (3D), levels 0.." << opt.levels
       << " (each solved coarse-to-fine from level 0)\n";
    std::vector<AccuracyRow> rows;
    for (int l = 0; l <= opt.levels; ++l) {
        problem.levels = l;
        const double t0 = wall_seconds();
        const levels::RunResult3 r = levels::solve(problem);
        const double sec = wall_seconds() - t0;
        if (!r.converged) {
            os << "error: level " << l << " did not converge: " << r.failure << "\n";
            return 2;
        }
        rows.push_back({l, r.finest().n_unknowns(), r.finest().n_contact_nodes(), sec,
                        accuracy_values3(problem, r)});
        print_accuracy_level(rows, os);
    }
    write_accuracy_files(problem.name, rows, dir, opt.plot, os);
    return 0;
}

} // namespace mlc::apps
