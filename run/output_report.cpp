// SPDX-License-Identifier: MIT
// The printed report of a run: header, checks, summary.
#include "run/output.hpp"
#include "run/summary_json.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/checks.hpp"
#include "mesh/io/vtu.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <sys/file.h>
#include <sys/stat.h>
#include <toml++/toml.h>
#include <unistd.h>

namespace mlc::apps {

namespace {

const char* plane_name(const levels::Problem& p) {
    return p.bodies.front().material.plane == fem::Plane::strain ? "plane strain" : "plane stress";
}

} // namespace

void print_not_found(std::ostream& os, const levels::Problem& p, const levels::Level& L,
                     int max_listed) {
    for (size_t k = 0; k < L.not_found.size() && k < p.contacts.size(); ++k) {
        const auto& nf = L.not_found[k];
        if (nf.empty()) continue;
        os << "contact '" << p.contacts[k].name << "': " << nf.size()
           << " contactor nodes found no "
           << (p.contacts[k].element == levels::ContactElementKind::node_on_node ? "target node"
                                                                                 : "facet")
           << ":";
        for (size_t i = 0; i < nf.size(); ++i) {
            if (max_listed >= 0 && static_cast<int>(i) == max_listed) {
                os << " ... (" << nf.size() - i << " more)";
                break;
            }
            const Vec2& x = L.mesh.vertices[static_cast<size_t>(nf[i])];
            os << " (" << x.x() << "," << x.y() << ")";
        }
        os << "\n";
    }
}

void print_header(std::ostream& os, const levels::Problem& p, const levels::RunResult& r) {
    const auto& L = r.finest();
    os << "scene      " << p.name << (p.units.empty() ? "" : "  [units: " + p.units + "]") << "\n";
    if (!p.description.empty()) os << "           " << p.description << "\n";
    for (const auto& b : p.bodies)
        os << "body       " << b.name << ": " << b.material << "\n";
    os << "mesh       level " << r.levels().size() - 1 << ": " << L.mesh.n_vertices()
       << " vertices, " << L.mesh.n_cells() << " triangles (" << plane_name(p) << ")\n";
    if (p.recovered_levels > 0)
        os << "           the Gmsh file's mesh is level " << p.recovered_levels
           << ", a uniform refinement of a " << p.mesh0.n_cells() << "-triangle mesh: levels 0.."
           << p.recovered_levels << " recovered ([scene].recover_levels)"
           << (p.levels < p.recovered_levels ? "; this run stops at a coarser level" : "") << "\n";
    os << "unknowns   " << L.n_unknowns() << " (" << L.dofs.n_displacement_dofs()
       << " displacement, " << L.n_unknowns() - L.dofs.n_displacement_dofs() << " multipliers), "
       << L.n_contact_nodes() << " contact nodes\n";
    for (size_t k = 0; k < p.contacts.size(); ++k) {
        const auto& c = p.contacts[k];
        int n_nodes = 0;
        for (const auto& e : L.contacts)
            n_nodes += e.pair == static_cast<int>(k);
        os << "contact    " << c.name << ": " << n_nodes << " nodes on '" << c.contactor
           << "' against ";
        if (c.obstacle)
            os << *c.obstacle;
        else
            os << two_body_target_text(c);
        os << ", mu = " << c.mu << ", r = " << c.r << "\n";
    }
    print_not_found(os, p, L);
    os << loading_text(p);
    os << "; Newton " << p.newton << "\n";
}

void print_checks(std::ostream& os, const levels::Problem& p, const levels::StateChecks& c,
                  const std::vector<PairResultant>& resultants) {
    os << "\nchecks (relative)  force balance " << std::scientific << std::setprecision(1);
    if (c.force_balance_applicable)
        os << c.force_balance;
    else
        os << "n/a (no force to balance)";
    os << "  Coulomb excess " << c.coulomb_excess << "  slip |lt|-mu|ln| " << c.slip_equality
       << "  complementarity " << c.complementarity << "  penetration " << c.penetration
       << std::defaultfloat << "\n";
    // Per pair: the resultant force the target exerts on the contactor nodes (global axes),
    // -sum (lambda_t t + lambda_n n), and the number of nodes in contact.
    for (size_t k = 0; k < p.contacts.size() && k < resultants.size(); ++k)
        os << "contact '" << p.contacts[k].name << "': resultant on the contactor ("
           << std::setprecision(6) << resultants[k].force.x() << ", " << resultants[k].force.y()
           << "), " << resultants[k].in_contact << " nodes in contact\n";
}

void print_summary(std::ostream& os, const levels::Problem& p, const levels::RunResult& r) {
    os << "\n step   load  newton  lin.it  residual    gap  stick  slip+  slip-   time[s]\n";
    for (const auto& s : r.steps)
        os << std::setw(5) << s.step << std::setw(7) << std::fixed << std::setprecision(3)
           << s.load_factor << std::setw(8) << s.iterations << std::setw(8) << s.linear_iterations
           << "  " << std::scientific << std::setprecision(2) << s.residuals.back() << std::setw(7)
           << s.counts.gap << std::setw(7) << s.counts.stick << std::setw(7)
           << s.counts.slip_forward << std::setw(7) << s.counts.slip_backward << std::setw(10)
           << std::fixed << std::setprecision(3) << s.seconds
           << (s.converged ? ""
               : s.stopped ? "  stopped"
                           : "  no conv")
           << "\n";
    os << std::defaultfloat;
    if (r.converged) {
        std::vector<PairResultant> res;
        for (size_t k = 0; k < p.contacts.size(); ++k) {
            PairResultant q;
            q.force = levels::contact_resultant(r, static_cast<int>(k), &q.in_contact);
            res.push_back(q);
        }
        print_checks(os, p, levels::check_state(p, r), res);
    }
    for (const auto& w : r.warnings)
        os << "warning: " << w << "\n";
    os << "\ntimings\n";
    r.timings.print(os);
}

} // namespace mlc::apps
