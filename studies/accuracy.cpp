// SPDX-License-Identifier: MIT
// Accuracy study: closed-form quantities of hertz, mindlin and patch per level, observed orders.
#include "studies/accuracy.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/timer.hpp"
#include "run/closed_form.hpp"
#include "run/plot_script.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <toml++/toml.h>

namespace mlc::apps {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Contact nodes of pair 0 sorted by x, with their tributary lengths along x.
struct SortedNodes {
    std::vector<levels::ContactNodeState> n;
    std::vector<double> trib;
};

SortedNodes sorted_nodes(const levels::Level& L,
                         const std::vector<levels::ContactNodeState>& nodes) {
    SortedNodes s;
    for (size_t e = 0; e < nodes.size(); ++e)
        if (L.contacts[e].pair == 0) s.n.push_back(nodes[e]);
    MLC_CHECK(s.n.size() >= 3,
              "the accuracy study needs at least 3 contact nodes, found " << s.n.size());
    std::sort(s.n.begin(), s.n.end(),
              [](const auto& a, const auto& b) { return a.x.x() < b.x.x(); });
    const size_t m = s.n.size();
    for (size_t i = 0; i < m; ++i) {
        const double left = i > 0 ? 0.5 * (s.n[i].x.x() - s.n[i - 1].x.x()) : 0.0;
        const double right = i + 1 < m ? 0.5 * (s.n[i + 1].x.x() - s.n[i].x.x()) : 0.0;
        s.trib.push_back(left + right);
    }
    return s;
}

/// Half-width of the zone of nodes where `in` holds (first to last such node), each end midway
/// to the neighbour outside. Throws when the zone reaches the first or last candidate.
template <class Pred> double zone_half_width(const SortedNodes& s, Pred in, const char* what) {
    int lo = -1, hi = -1;
    for (size_t i = 0; i < s.n.size(); ++i)
        if (in(s.n[i])) {
            if (lo < 0) lo = static_cast<int>(i);
            hi = static_cast<int>(i);
        }
    MLC_CHECK(lo >= 0, "no contact node is in the " << what << " zone");
    MLC_CHECK(lo > 0 && hi + 1 < static_cast<int>(s.n.size()),
              "the " << what << " zone reaches the last contact candidate: widen the region");
    const auto x = [&](int i) { return s.n[static_cast<size_t>(i)].x.x(); };
    return 0.5 * (0.5 * (x(hi) + x(hi + 1)) - 0.5 * (x(lo) + x(lo - 1)));
}

/// Radius of the circle the contactor boundary of pair 0 lies on.
double contactor_radius(const levels::Problem& p, const levels::Level& L) {
    const int tag = L.mesh.tag(p.contacts.front().contactor);
    for (const auto& e : L.mesh.boundary)
        if (e.tag == tag && e.shape >= 0) return L.mesh.shapes[static_cast<size_t>(e.shape)].radius;
    MLC_CHECK(false, "the contactor boundary '" << p.contacts.front().contactor
                                                << "' lies on no circle: no Hertz radius");
    return 0.0;
}

double plane_modulus(const fem::Material& m) {
    return m.plane == fem::Plane::strain ? m.E / (1.0 - m.nu * m.nu) : m.E;
}

} // namespace

MindlinMeasures measure_mindlin(const levels::Problem& p, const levels::RunResult& r) {
    MLC_CHECK(!p.contacts.empty() && !p.bodies.empty(), "mindlin: no contact pair or body");
    MLC_CHECK(r.converged, "mindlin: the run did not converge: " << r.failure);
    MLC_CHECK(r.step_nodes.size() >= 2,
              "mindlin: the run needs keep_step_states and two load steps, found "
                  << r.step_nodes.size() << " kept states");
    const auto& L = r.finest();
    const double mu = p.contacts.front().mu;
    MLC_CHECK(mu > 0, "mindlin: the contact pair is frictionless");
    const double R = contactor_radius(p, L);
    // Two equal bodies: E* = E' / 2 with E' the plane modulus.
    const double E_star = 0.5 * plane_modulus(p.bodies.front().material);
    MindlinMeasures m;
    {
        const SortedNodes s1 = sorted_nodes(L, r.step_nodes.front());
        double lt = 0, ln = 0;
        for (const auto& n : s1.n) {
            lt = std::max(lt, std::abs(n.lambda_t));
            ln = std::max(ln, std::abs(n.lambda_n));
        }
        m.step1_tangential = ln > 0 ? lt / (mu * ln) : 0.0;
        double P1 = 0;
        for (const auto& n : s1.n)
            P1 -= n.lambda_n;
        if (P1 > 0) {
            const double a1 = std::sqrt(4.0 * P1 * R / (std::numbers::pi * E_star));
            const double mu_p0 = mu * 2.0 * P1 / (std::numbers::pi * a1);
            double s2 = 0;
            int k = 0;
            for (size_t i = 0; i < s1.n.size(); ++i) {
                const double q = std::abs(s1.n[i].lambda_t) / s1.trib[i] / mu_p0;
                m.step1_traction_max = std::max(m.step1_traction_max, q);
                if (s1.n[i].status != contact::Status::gap) {
                    s2 += q * q;
                    ++k;
                }
            }
            m.step1_traction_rms = k > 0 ? std::sqrt(s2 / k) : 0.0;
        }
    }
    const SortedNodes s = sorted_nodes(L, r.nodes);
    double sum_t = 0;
    for (const auto& n : s.n) {
        m.P -= n.lambda_n;
        sum_t += n.lambda_t;
        m.n_closed += n.status != contact::Status::gap;
        m.n_stick += n.status == contact::Status::stick;
        m.n_slip +=
            n.status == contact::Status::slip_forward || n.status == contact::Status::slip_backward;
    }
    m.Q = std::abs(sum_t);
    MLC_CHECK(m.P > 0 && m.Q < mu * m.P, "mindlin: expected 0 < Q < mu P (partial slip), found P = "
                                             << m.P << ", Q = " << m.Q);
    m.a_closed = std::sqrt(4.0 * m.P * R / (std::numbers::pi * E_star));
    m.a = zone_half_width(
        s, [](const auto& n) { return n.status != contact::Status::gap; }, "contact");
    m.c = zone_half_width(
        s, [](const auto& n) { return n.status == contact::Status::stick; }, "stick");
    m.c_over_a = m.c / m.a;
    m.c_over_a_closed = std::sqrt(1.0 - m.Q / (mu * m.P));
    const double a = m.a_closed, c = a * m.c_over_a_closed;
    const double p0 = 2.0 * m.P / (std::numbers::pi * a);
    auto p_closed = [&](double x) {
        return std::abs(x) < a ? p0 * std::sqrt(1 - x * x / (a * a)) : 0.0;
    };
    auto q_closed = [&](double x) {
        double q = std::abs(x) < a ? std::sqrt(a * a - x * x) : 0.0;
        if (std::abs(x) < c) q -= std::sqrt(c * c - x * x);
        return mu * p0 / a * q;
    };
    double s_slip = 0, s_q = 0, s_p = 0;
    int k_slip = 0, k_in = 0;
    for (size_t i = 0; i < s.n.size(); ++i) {
        const auto& n = s.n[i];
        const double x = n.x.x();
        const double pi_ = -n.lambda_n / s.trib[i], qi = std::abs(n.lambda_t) / s.trib[i];
        if (n.status == contact::Status::slip_forward ||
            n.status == contact::Status::slip_backward) {
            s_slip += std::pow((qi - mu * p_closed(x)) / (mu * p0), 2);
            ++k_slip;
        }
        if (std::abs(x) < 0.9 * a) {
            s_q += std::pow((qi - q_closed(x)) / (mu * p0), 2);
            s_p += std::pow((pi_ - p_closed(x)) / p0, 2);
            ++k_in;
        }
    }
    m.slip_traction_rms = k_slip > 0 ? std::sqrt(s_slip / k_slip) : 0.0;
    m.q_profile_rms = k_in > 0 ? std::sqrt(s_q / k_in) : 0.0;
    m.pressure_rms = k_in > 0 ? std::sqrt(s_p / k_in) : 0.0;
    return m;
}

PatchMeasures measure_patch(const levels::Problem& p, const levels::RunResult& r) {
    MLC_CHECK(r.converged, "patch: the run did not converge: " << r.failure);
    const auto& mat = p.bodies.front().material;
    MLC_CHECK(mat.nu == 0.0, "patch: the closed form needs nu = 0, found " << mat.nu);
    // The prescribed platen displacement: the support with the largest |u_y|.
    double u_top = 0;
    for (const auto& s : p.supports)
        if (s.uy && std::abs(*s.uy) > std::abs(u_top)) u_top = *s.uy;
    MLC_CHECK(u_top != 0.0, "patch: no support prescribes a non-zero u_y");
    const auto& L = r.finest();
    const double diam_y = [&] {
        double lo = 1e300, hi = -1e300;
        for (const auto& v : L.mesh.vertices) {
            lo = std::min(lo, v.y());
            hi = std::max(hi, v.y());
        }
        return hi - lo;
    }();
    PatchMeasures m;
    m.p_exact = mat.E * std::abs(u_top) / diam_y;
    m.uy_exact = 0.5 * u_top;
    const SortedNodes s = sorted_nodes(L, r.nodes);
    const double width = s.n.back().x.x() - s.n.front().x.x();
    double total = 0;
    for (size_t i = 0; i < s.n.size(); ++i) {
        const double pi_ = -s.n[i].lambda_n / s.trib[i];
        const double e = std::abs(pi_ - m.p_exact) / m.p_exact;
        total -= s.n[i].lambda_n;
        m.pressure_max_error = std::max(m.pressure_max_error, e);
        if (i > 0 && i + 1 < s.n.size())
            m.pressure_interior_max_error = std::max(m.pressure_interior_max_error, e);
        m.uy_max_error =
            std::max(m.uy_max_error, std::abs(s.n[i].u.y() - m.uy_exact) / std::abs(m.uy_exact));
    }
    m.resultant_error = std::abs(total - m.p_exact * width) / (m.p_exact * width);
    return m;
}

std::vector<AccuracyValue> accuracy_values(const levels::Problem& p, const levels::RunResult& r) {
    std::vector<AccuracyValue> out;
    auto rel = [](double v, double ref) { return (v - ref) / ref; };
    if (p.name == "hertz" || p.name == "hertz_gmsh") {
        MLC_CHECK(r.converged, "hertz: the run did not converge: " << r.failure);
        const auto& L = r.finest();
        double P = 0;
        for (const auto& n : r.nodes)
            P -= 2.0 * n.lambda_n; // right half modelled: the full load is twice the contact force
        const Hertz h{.P = P,
                      .R = contactor_radius(p, L),
                      .E_star = plane_modulus(p.bodies.front().material)};
        const auto prof = pressure_profile(r.nodes);
        const auto e = compare(prof, h);
        out.push_back({"P", P, P, kNaN, "contact resultant x 2 (half model)"});
        out.push_back({"half_width", prof.half_width, h.half_width(), e.half_width, "relative"});
        out.push_back({"peak_pressure", prof.p.front(), h.peak_pressure(), e.peak, "relative"});
        out.push_back({"profile_rms", e.profile_rms, 0.0, e.profile_rms,
                       "rms of p - p_closed over |x| < 0.9 a, / p0"});
        return out;
    }
    if (p.name == "mindlin") {
        const auto m = measure_mindlin(p, r);
        const double mu = p.contacts.front().mu;
        out.push_back({"P", m.P, m.P, kNaN, "measured normal force"});
        out.push_back({"Q", m.Q, m.Q, kNaN, "measured tangential force"});
        out.push_back({"Q_over_muP", m.Q / (mu * m.P), m.Q / (mu * m.P), kNaN, "load ratio"});
        out.push_back({"half_width", m.a, m.a_closed, rel(m.a, m.a_closed), "relative"});
        out.push_back({"c_over_a", m.c_over_a, m.c_over_a_closed,
                       rel(m.c_over_a, m.c_over_a_closed), "relative, vs sqrt(1 - Q/(mu P))"});
        out.push_back({"pressure_rms", m.pressure_rms, 0.0, m.pressure_rms,
                       "rms of p - p_closed over |x| < 0.9 a, / p0"});
        out.push_back({"slip_traction_rms", m.slip_traction_rms, 0.0, m.slip_traction_rms,
                       "rms of q - mu p_closed at slip nodes, / (mu p0)"});
        out.push_back({"q_profile_rms", m.q_profile_rms, 0.0, m.q_profile_rms,
                       "rms of q - q_closed over |x| < 0.9 a, / (mu p0)"});
        out.push_back({"step1_tangential", m.step1_tangential, 0.0, m.step1_tangential,
                       "max |lambda_t| / (mu max |lambda_n|) after step 1"});
        out.push_back({"step1_traction_rms", m.step1_traction_rms, 0.0, m.step1_traction_rms,
                       "rms of q / (mu p0) over the closed nodes after step 1"});
        out.push_back({"step1_traction_max", m.step1_traction_max, 0.0, m.step1_traction_max,
                       "max q / (mu p0) after step 1"});
        return out;
    }
    if (p.name == "patch" || p.name == "patch_matching") {
        const auto m = measure_patch(p, r);
        out.push_back({"pressure_max", m.pressure_max_error, 0.0, m.pressure_max_error,
                       "max |p - p_exact| / p_exact"});
        out.push_back({"pressure_interior_max", m.pressure_interior_max_error, 0.0,
                       m.pressure_interior_max_error, "the same without the end nodes"});
        out.push_back({"uy_max", m.uy_max_error, 0.0, m.uy_max_error,
                       "max |u_y - u_exact| / |u_exact| at the contactor nodes"});
        out.push_back({"resultant", m.resultant_error, 0.0, m.resultant_error, "relative"});
        return out;
    }
    MLC_CHECK(false, "the accuracy study knows closed forms for the scenes hertz, mindlin, patch, "
                     "patch_matching and hertz_gmsh only, not '"
                         << p.name << "'");
    return out;
}

void print_accuracy_level(const std::vector<AccuracyRow>& rows, std::ostream& os) {
    using Row = AccuracyRow;
    const int l = rows.back().level;
    const double sec = rows.back().seconds;
    const Row& row = rows.back();
        os << "\nlevel " << l << ": " << row.unknowns << " unknowns, " << row.contacts
           << " contact nodes, " << std::fixed << std::setprecision(2) << sec << " s"
           << std::defaultfloat << "\n";
        os << "  quantity                         value          closed form    error       "
              "order\n";
        for (size_t q = 0; q < row.values.size(); ++q) {
            const auto& v = row.values[q];
            os << "  " << std::left << std::setw(30) << v.name << std::right << std::scientific
               << std::setprecision(5) << std::setw(14) << v.value << " " << std::setw(14)
               << v.reference << " ";
            if (std::isnan(v.error))
                os << std::setw(11) << "-";
            else
                os << std::setw(11) << std::setprecision(3) << v.error;
            if (rows.size() > 1 && !std::isnan(v.error)) {
                const double e0 = std::abs(rows[rows.size() - 2].values[q].error);
                const double e1 = std::abs(v.error);
                if (e0 > 0 && e1 > 0)
                    os << std::fixed << std::setprecision(2) << std::setw(10) << std::log2(e0 / e1);
            }
            os << std::defaultfloat << "\n";
        }
}

void write_accuracy_files(const std::string& scene, const std::vector<AccuracyRow>& rows,
                          const std::filesystem::path& dir, bool plot, std::ostream& os) {
    using Row = AccuracyRow;
    // CSV (long format) and JSON.
    AtomicOfstream csv(dir / "accuracy.csv");
    csv << "level,unknowns,contact_nodes,seconds,quantity,value,reference,error,order\n"
        << std::setprecision(12);
    toml::array jl;
    for (size_t i = 0; i < rows.size(); ++i) {
        const Row& row = rows[i];
        toml::table t;
        t.insert("level", static_cast<int64_t>(row.level));
        t.insert("unknowns", static_cast<int64_t>(row.unknowns));
        t.insert("contact_nodes", static_cast<int64_t>(row.contacts));
        t.insert("seconds", row.seconds);
        toml::table qs;
        for (size_t q = 0; q < row.values.size(); ++q) {
            const auto& v = row.values[q];
            double order = kNaN;
            if (i > 0 && !std::isnan(v.error)) {
                const double e0 = std::abs(rows[i - 1].values[q].error), e1 = std::abs(v.error);
                if (e0 > 0 && e1 > 0) order = std::log2(e0 / e1);
            }
            csv << row.level << "," << row.unknowns << "," << row.contacts << "," << row.seconds
                << "," << v.name << "," << v.value << "," << v.reference << ",";
            if (!std::isnan(v.error)) csv << v.error;
            csv << ",";
            if (!std::isnan(order)) csv << order;
            csv << "\n";
            toml::table jq;
            jq.insert("value", v.value);
            jq.insert("reference", v.reference);
            if (!std::isnan(v.error)) jq.insert("error", v.error);
            if (!std::isnan(order)) jq.insert("order", order);
            jq.insert("note", v.note);
            qs.insert(v.name, jq);
        }
        t.insert("quantities", qs);
        jl.push_back(t);
    }
    toml::table root;
    root.insert("scene", scene);
    root.insert("levels", jl);
    AtomicOfstream js(dir / "accuracy.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    MLC_CHECK(csv.good() && js.good(),
              "cannot write the accuracy study's files in " << dir.string());
    os << "\nwrote " << (dir / "accuracy.csv").string() << ", accuracy.json\n";
    if (plot && run_plot_script("plot_accuracy.py", dir, os))
        os << "wrote " << (dir / "accuracy.png").string() << "\n";
}

int study_accuracy(const levels::Problem& problem_in, const AccuracyOptions& opt,
                   std::ostream& os) {
    MLC_CHECK(opt.levels >= 0 && opt.levels <= 8,
              "the accuracy study needs --levels between 0 and 8, found " << opt.levels);
    levels::Problem problem = problem_in;
    const auto dir =
        opt.out.empty() ? std::filesystem::path("out") / problem.name / "accuracy" : opt.out;
    std::filesystem::create_directories(dir);
    os << "accuracy study: scene '" << problem.name << "', levels 0.." << opt.levels
       << " (each solved coarse-to-fine from level 0)\n";
    using Row = AccuracyRow;
    std::vector<Row> rows;
    // The scene with its node-on-facet pairs in each other integration, to compare.
    std::vector<std::pair<std::string, levels::Problem>> others;
    std::string this_name;
    for (const auto& c : problem.contacts)
        if (opt.compare_integration && c.element == levels::ContactElementKind::node_on_facet) {
            this_name = std::string(contact::to_string(c.integration));
            for (auto f : {contact::FacetIntegration::nodal, contact::FacetIntegration::segment,
                           contact::FacetIntegration::dual}) {
                if (f == c.integration) continue;
                levels::Problem q = problem;
                for (auto& oc : q.contacts)
                    if (oc.element == levels::ContactElementKind::node_on_facet) oc.integration = f;
                others.emplace_back(std::string(contact::to_string(f)), std::move(q));
            }
            break;
        }
    if (!others.empty()) {
        os << "node-on-facet integration: " << this_name << " (the scene's); the quantities with "
           << "the suffix";
        for (const auto& o : others)
            os << " _" << o.first;
        os << " are the other variants'\n";
    }
    for (int l = 0; l <= opt.levels; ++l) {
        problem.levels = l;
        levels::SolveOptions so;
        so.keep_step_states = true;
        const double t0 = wall_seconds();
        const levels::RunResult r = levels::solve(problem, so);
        const double sec = wall_seconds() - t0;
        if (!r.converged) {
            os << "error: level " << l << " did not converge: " << r.failure << "\n";
            return 2;
        }
        rows.push_back({l, r.finest().n_unknowns(), r.finest().n_contact_nodes(), sec,
                        accuracy_values(problem, r)});
        for (auto& [name, other] : others) {
            // The same level with another node-on-facet integration: its errors, suffixed.
            other.levels = l;
            const levels::RunResult ro = levels::solve(other, so);
            if (!ro.converged) {
                os << "error: level " << l << " with " << name
                   << " integration did not converge: " << ro.failure << "\n";
                return 2;
            }
            for (auto v : accuracy_values(other, ro)) {
                if (std::isnan(v.error)) continue;
                v.name += "_" + name;
                v.note += " (" + name + " integration)";
                rows.back().values.push_back(v);
            }
        }
        print_accuracy_level(rows, os);
    }
    write_accuracy_files(problem.name, rows, dir, opt.plot, os);
    return 0;
}

} // namespace mlc::apps
