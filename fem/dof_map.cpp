// SPDX-License-Identifier: MIT
// Unknown numbering.
#include "fem/dof_map.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"

namespace mlc::fem {

template <int dim>
BasicDofMap<dim>::BasicDofMap(const std::vector<std::array<bool, dim>>& fixed,
                              const std::vector<int>& n_extra, const std::vector<int>& order) {
    MLC_CHECK(fixed.size() == n_extra.size(),
              "DofMap: " << fixed.size() << " fixed flags for " << n_extra.size() << " vertices");
    const size_t nv = fixed.size();
    if (!order.empty()) {
        MLC_CHECK(order.size() == nv, "DofMap: the vertex order has "
                                          << order.size() << " entries for " << nv << " vertices");
        std::vector<char> seen(nv, 0);
        for (const int v : order) {
            MLC_CHECK(v >= 0 && static_cast<size_t>(v) < nv && !seen[static_cast<size_t>(v)],
                      "DofMap: the vertex order is not a permutation (entry " << v << ")");
            seen[static_cast<size_t>(v)] = 1;
        }
    }
    u_dof_.resize(nv);
    extra_.assign(nv, -1);
    int next = 0;
    for (size_t pos = 0; pos < nv; ++pos) {
        const size_t v = order.empty() ? pos : static_cast<size_t>(order[pos]);
        for (size_t c = 0; c < dim; ++c) {
            if (fixed[v][c]) {
                u_dof_[v][c] = -1;
            } else {
                u_dof_[v][c] = next++;
                is_u_.push_back(1);
                owner_.push_back(static_cast<int>(v));
                ++n_u_;
            }
        }
        MLC_CHECK(n_extra[v] >= 0 && n_extra[v] <= dim,
                  "DofMap: vertex " << v << " asks for " << n_extra[v] << " extra unknowns");
        if (n_extra[v] > 0) {
            extra_[v] = next;
            for (int k = 0; k < n_extra[v]; ++k) {
                is_u_.push_back(0);
                owner_.push_back(static_cast<int>(v));
            }
            next += n_extra[v];
        }
    }
    n_dofs_ = next;
}

template <int dim>
void BasicDofMap<dim>::expand(const Vector& x, const Vector& u_fixed, Vector& u_full) const {
    const int nv = n_vertices();
    u_full.resize(dim * nv);
    // The vertices over the threads (the Newton residual expands every iterate).
    parallel::for_rows(
        static_cast<size_t>(nv), parallel::kTouchRowsPerChunk / 2, [&](size_t b, size_t e) {
            for (auto v = static_cast<int>(b); v < static_cast<int>(e); ++v)
                for (int c = 0; c < dim; ++c) {
                    const int d = u_dof_[static_cast<size_t>(v)][static_cast<size_t>(c)];
                    u_full[dim * v + c] = d >= 0 ? x[d] : u_fixed[dim * v + c];
                }
        });
}

template class BasicDofMap<2>;
template class BasicDofMap<3>;

} // namespace mlc::fem
