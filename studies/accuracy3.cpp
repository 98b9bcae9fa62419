// SPDX-License-Identifier: MIT
// Accuracy study of the 3D scenes: Hertz (hertz3d, sphere_punch), Hertz and Cattaneo-Mindlin
// between two elastic bodies (sphere_on_block) and the patch test (punch3d).
#include "core/check.hpp"
#include "core/timer.hpp"
#include "studies/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace mlc::apps {

namespace {

constexpr double kNaN3 = std::numeric_limits<double>::quiet_NaN();

/// The sphere of a Hertz scene: the curved surface the contactor faces lie on (hertz3d,
/// sphere_on_block) or the obstacle's (sphere_punch).
mesh::CurvedSurface hertz_sphere(const levels::ElasticProblem3& p) {
    MLC_CHECK(p.contacts.size() == 1,
              "hertz (3D): one contact pair expected, found " << p.contacts.size());
    const auto& c = p.contacts.front();
    const int tag = p.mesh0.tag(c.contactor);
    for (const auto& f : p.mesh0.boundary)
        if (f.tag == tag && f.shape >= 0 &&
            p.mesh0.shapes[static_cast<size_t>(f.shape)].kind == mesh::CurvedSurface::Kind::sphere)
            return p.mesh0.shapes[static_cast<size_t>(f.shape)];
    mesh::CurvedSurface s;
    if (c.obstacle.kind == contact::BasicObstacle<3>::Kind::sphere) {
        s.center = c.obstacle.center;
        s.radius = c.obstacle.radius;
        return s;
    }
    MLC_CHECK(false, "hertz (3D): neither the contactor '" << c.contactor
                                                           << "' nor the obstacle is a sphere");
    return s;
}

/// The contact nodes of a 3D level along a line parallel to x (those within `tol` of y = y0),
/// sorted by x: their reference x and statuses.
struct AxisNodes3 {
    std::vector<double> x;
    std::vector<contact::Status> status;
};

AxisNodes3 axis_nodes3(const std::vector<levels::ContactNodeState3>& nodes, double y0, double tol) {
    std::vector<std::pair<double, contact::Status>> v;
    for (const auto& n : nodes)
        if (std::abs(n.x.y() - y0) <= tol) v.emplace_back(n.x.x(), n.status);
    std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    AxisNodes3 s;
    for (const auto& [x, st] : v) {
        s.x.push_back(x);
        s.status.push_back(st);
    }
    return s;
}

/// Half-width along x of the zone of axis nodes whose status satisfies `in` (first to last
/// such node), each end midway to the neighbour outside; as the 2D mindlin study's zone
/// half-width. Throws when the zone is empty or reaches the first or last node on the axis.
template <class Pred>
double axis_zone_half_width(const AxisNodes3& s, Pred in, const std::string& scene,
                            const char* what) {
    int lo = -1, hi = -1;
    for (size_t i = 0; i < s.x.size(); ++i)
        if (in(s.status[i])) {
            if (lo < 0) lo = static_cast<int>(i);
            hi = static_cast<int>(i);
        }
    MLC_CHECK(lo >= 0, scene << ": no contact node on the x axis is in the " << what << " zone");
    MLC_CHECK(lo > 0 && hi + 1 < static_cast<int>(s.x.size()),
              scene << ": the " << what
                    << " zone reaches the last contact candidate on the x axis: widen the region");
    const auto x = [&](int i) { return s.x[static_cast<size_t>(i)]; };
    return 0.5 * (0.5 * (x(hi) + x(hi + 1)) - 0.5 * (x(lo) + x(lo - 1)));
}

/// sphere_on_block (scenes/sphere_on_block.toml): Hertz between two equal elastic bodies, then
/// Cattaneo-Mindlin partial slip along x, on the half y >= 0.
std::vector<AccuracyValue> sphere_on_block_values(const levels::ElasticProblem3& p,
                                                  const levels::RunResult3& r) {
    MLC_CHECK(p.bodies.size() == 2, p.name << ": two bodies expected, found " << p.bodies.size());
    const auto& m1 = p.bodies[0].material;
    const auto& m2 = p.bodies[1].material;
    // Cattaneo-Mindlin's uncoupling needs elastically similar bodies; the scene's are equal.
    MLC_CHECK(m1.E == m2.E && m1.nu == m2.nu,
              p.name << ": the closed form needs two bodies of one material, found E = " << m1.E
                     << ", nu = " << m1.nu << " and E = " << m2.E << ", nu = " << m2.nu);
    MLC_CHECK(r.step_nodes.size() >= 2,
              p.name << ": two load steps expected (press, then shift), found "
                     << r.step_nodes.size() << " completed");
    const double mu = p.contacts.front().mu;
    MLC_CHECK(mu > 0, p.name << ": the contact pair is frictionless");
    const auto sphere = hertz_sphere(p);
    const double R = sphere.radius;
    const double E_star = 1.0 / ((1.0 - m1.nu * m1.nu) / m1.E + (1.0 - m2.nu * m2.nu) / m2.E);
    const auto& L = r.finest();
    const auto areas = levels::contact_areas(p, L);
    const auto& nodes = r.nodes;
    // The contact forces on the contactor in global components; the half model carries half of
    // P and of Q (its y resultant is the symmetry plane's).
    mesh::Vec3 F = mesh::Vec3::Zero();
    double P = 0.0;
    for (const auto& n : nodes) {
        F += n.n * n.lambda_n + n.t * n.lambda_t;
        P -= 2.0 * n.lambda_n;
    }
    const double Q = 2.0 * std::abs(F.x());
    MLC_CHECK(P > 0 && Q < mu * P,
              p.name << ": expected 0 < Q < mu P (partial slip), found P = " << P << ", Q = " << Q);
    const double a = std::cbrt(3.0 * P * R / (4.0 * E_star));
    const double p0 = 3.0 * P / (2.0 * std::numbers::pi * a * a);
    const double c_over_a = std::cbrt(1.0 - Q / (mu * P));
    const double c = c_over_a * a;
    auto radius = [&](const mesh::Vec3& x) {
        return std::hypot(x.x() - sphere.center.x(), x.y() - sphere.center.y());
    };
    // The contact radius and the peak pressure as for hertz3d (every node, radially).
    double r_in = 0.0, p_axis = 0.0, r_axis = std::numeric_limits<double>::infinity();
    for (size_t e = 0; e < nodes.size(); ++e) {
        const double ri = radius(nodes[e].x);
        if (nodes[e].status != contact::Status::gap) r_in = std::max(r_in, ri);
        if (ri < r_axis) {
            r_axis = ri;
            p_axis = areas[e] > 0 ? -nodes[e].lambda_n / areas[e] : 0.0;
        }
    }
    double r_out = std::numeric_limits<double>::infinity();
    for (const auto& n : nodes)
        if (n.status == contact::Status::gap && radius(n.x) > r_in)
            r_out = std::min(r_out, radius(n.x));
    const double a_meas = std::isfinite(r_out) ? 0.5 * (r_in + r_out) : r_in;
    const double spacing = std::isfinite(r_out) ? r_out - r_in : 0.0;
    // The pressure and the traction along x against their closed forms over r < 0.9 a.
    auto q_closed = [&](double ri) {
        double q = ri < a ? std::sqrt(a * a - ri * ri) : 0.0;
        if (ri < c) q -= std::sqrt(c * c - ri * ri);
        return mu * p0 / a * q;
    };
    double s_p = 0.0, s_q = 0.0;
    int k = 0;
    for (size_t e = 0; e < nodes.size(); ++e) {
        const double ri = radius(nodes[e].x);
        if (ri >= 0.9 * a || areas[e] <= 0) continue;
        const double pe = -nodes[e].lambda_n / areas[e];
        const double qe = std::abs((nodes[e].t * nodes[e].lambda_t).x()) / areas[e];
        s_p += std::pow(pe - p0 * std::sqrt(1.0 - ri * ri / (a * a)), 2);
        s_q += std::pow(qe - q_closed(ri), 2);
        ++k;
    }
    const double rms = k > 0 ? std::sqrt(s_p / k) / p0 : kNaN3;
    const double q_rms = k > 0 ? std::sqrt(s_q / k) / (mu * p0) : kNaN3;
    // c and a along the x axis: the contact nodes on y = 0 (the symmetry plane; refinement
    // keeps them on it), as the 2D mindlin study measures its half-widths.
    const double tol = 1e-9 * R;
    const AxisNodes3 ax = axis_nodes3(nodes, sphere.center.y(), tol);
    const double a_axis = axis_zone_half_width(
        ax, [](contact::Status s) { return s != contact::Status::gap; }, p.name, "contact");
    const double c_axis = axis_zone_half_width(
        ax, [](contact::Status s) { return s == contact::Status::stick; }, p.name, "stick");
    // After step 1 (no shift yet): the tangential multipliers against mu times the normal ones
    // (0 in the half-space theory of equal bodies).
    double lt1 = 0.0, ln1 = 0.0;
    for (const auto& n : r.step_nodes.front()) {
        lt1 = std::max(lt1, n.lambda_t.norm());
        ln1 = std::max(ln1, std::abs(n.lambda_n));
    }
    const double step1 = ln1 > 0 ? lt1 / (mu * ln1) : 0.0;
    int n_stick = 0, n_slip = 0;
    for (const auto& n : nodes) {
        n_stick += n.status == contact::Status::stick;
        n_slip += n.status == contact::Status::slip;
    }
    std::vector<AccuracyValue> out;
    out.push_back({"P", P, P, kNaN3, "normal contact force x 2 (half model)"});
    out.push_back({"Q", Q, Q, kNaN3, "x component of the contact force x 2 (half model)"});
    out.push_back({"Q_over_muP", Q / (mu * P), Q / (mu * P), kNaN3, "load ratio"});
    out.push_back({"radius", a_meas, a, (a_meas - a) / a,
                   "relative; midway between the last node in contact and the next"});
    out.push_back({"node_spacing_over_a", spacing / a, spacing / a, kNaN3,
                   "radial gap between those two nodes, / a"});
    out.push_back({"peak_pressure", p_axis, p0, (p_axis - p0) / p0,
                   "relative; pressure of the node nearest the axis"});
    out.push_back({"profile_rms", rms, 0.0, rms, "rms of p - p_closed over r < 0.9 a, / p0"});
    out.push_back({"c_over_a", c_axis / a_axis, c_over_a, (c_axis / a_axis - c_over_a) / c_over_a,
                   "relative, vs (1 - Q/(mu P))^(1/3); c and a along the x axis"});
    out.push_back(
        {"q_profile_rms", q_rms, 0.0, q_rms, "rms of q_x - q_closed over r < 0.9 a, / (mu p0)"});
    out.push_back({"step1_tangential", step1, 0.0, step1,
                   "max |lambda_t| / (mu max |lambda_n|) after step 1"});
    out.push_back({"stick_nodes", static_cast<double>(n_stick), static_cast<double>(n_stick), kNaN3,
                   "contact nodes that stick"});
    out.push_back({"slip_nodes", static_cast<double>(n_slip), static_cast<double>(n_slip), kNaN3,
                   "contact nodes that slip"});
    return out;
}

} // namespace

std::vector<AccuracyValue> accuracy_values3(const levels::ElasticProblem3& p,
                                            const levels::RunResult3& r) {
    MLC_CHECK(r.converged, p.name << ": the run did not converge: " << r.failure);
    const auto& L = r.finest();
    const auto areas = levels::contact_areas(p, L);
    if (p.name == "sphere_on_block") return sphere_on_block_values(p, r);
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
                     "sphere_punch, sphere_on_block and punch3d only, not '"
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
