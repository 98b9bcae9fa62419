// SPDX-License-Identifier: MIT
// Level hierarchy construction.
#include "levels/hierarchy.hpp"

#include <iomanip>

namespace mlc::levels {

transfer::ContactNodes contact_nodes(const Level& level) {
    transfer::ContactNodes c;
    for (size_t e = 0; e < level.contacts.size(); ++e) {
        c.vertex.push_back(level.contacts[e].vertex[0]);
        c.lambda_dof.push_back(level.lambda_dof[e]);
        c.n_multipliers.push_back(level.contacts[e].n_multipliers());
        c.pinned.push_back(level.contacts[e].pinned);
    }
    return c;
}

Hierarchy build_hierarchy(const Problem& problem, transfer::QRule rule, Timings* timings) {
    problem.validate();
    Hierarchy h;
    // Reserved: growing the vector would copy every level built so far.
    h.levels.reserve(static_cast<size_t>(problem.levels) + 1);
    h.transfers.reserve(static_cast<size_t>(problem.levels));
    mesh::Mesh m = problem.mesh0;
    for (int l = 0;; ++l) {
        {
            ScopedTimer t(timings, "setup/levels");
            h.levels.push_back(build_level(problem, m));
        }
        if (l > 0) {
            ScopedTimer t(timings, "setup/transfer");
            const Level& c = h.levels[static_cast<size_t>(l - 1)];
            const Level& f = h.levels[static_cast<size_t>(l)];
            h.transfers.push_back(transfer::build_transfer(f.mesh, c.dofs, f.dofs, contact_nodes(c),
                                                           contact_nodes(f), rule));
        }
        if (l == problem.levels) break;
        ScopedTimer t(timings, "setup/refine");
        m = mesh::refine(m);
    }
    return h;
}

template <int dim> void BasicHierarchy<dim>::report(std::ostream& os) const {
    long total = 0;
    for (const auto& L : levels)
        total += L.elastic.K.nonZeros();
    os << "  level  vertices  " << (dim == 2 ? "triangles" : "tetrahedra")
       << "  unknowns  contact nodes  nnz(K)\n";
    for (size_t l = 0; l < levels.size(); ++l) {
        const auto& L = levels[l];
        os << std::setw(7) << l << std::setw(10) << L.mesh.n_vertices() << std::setw(dim + 9)
           << L.mesh.n_cells() << std::setw(10) << L.n_unknowns() << std::setw(15)
           << L.n_contact_nodes() << " " << std::setw(8) << L.elastic.K.nonZeros() << "\n";
    }
    os << "  operator complexity " << std::setprecision(3)
       << static_cast<double>(total) / static_cast<double>(finest().elastic.K.nonZeros())
       << std::defaultfloat << "\n";
}

template struct BasicHierarchy<2>;
template struct BasicHierarchy<3>;

} // namespace mlc::levels
