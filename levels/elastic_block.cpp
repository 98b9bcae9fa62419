// SPDX-License-Identifier: MIT
#include "levels/elastic_block.hpp"

#include "core/check.hpp"

namespace mlc::levels {

Vector ElasticBlock::restrict(const Vector& full) const {
    Vector out(K.rows());
    for (Index i = 0; i < full.size(); ++i)
        if (const int c = compact[static_cast<size_t>(i)]; c >= 0) out[c] = full[i];
    return out;
}

ElasticBlock elastic_block(const Level& L) {
    ElasticBlock b;
    const Index n = L.n_unknowns();
    b.compact.assign(static_cast<size_t>(n), -1);
    int m = 0;
    for (Index i = 0; i < n; ++i)
        if (L.dofs.is_displacement(i)) {
            b.compact[static_cast<size_t>(i)] = m++;
            b.vertex.push_back(L.dofs.vertex_of(i));
        }
    b.component.assign(static_cast<size_t>(m), 0);
    for (int v = 0; v < L.mesh.n_vertices(); ++v)
        for (int c = 0; c < 2; ++c)
            if (const int d = L.dofs.u_dof(v, c); d >= 0)
                b.component[static_cast<size_t>(b.compact[static_cast<size_t>(d)])] = c;
    std::vector<Triplet> t;
    t.reserve(static_cast<size_t>(L.elastic.K.nonZeros()));
    for (Index i = 0; i < n; ++i)
        for (SparseMatrix::InnerIterator it(L.elastic.K, i); it; ++it) {
            const int r = b.compact[static_cast<size_t>(i)];
            const int c = b.compact[static_cast<size_t>(it.col())];
            if (r >= 0 && c >= 0) t.emplace_back(r, c, it.value());
        }
    b.K.resize(m, m);
    b.K.setFromTriplets(t.begin(), t.end());
    b.K.makeCompressed();
    return b;
}

SparseMatrix displacement_prolongation(const SparseMatrix& T, const ElasticBlock& fine,
                                       const ElasticBlock& coarse) {
    std::vector<Triplet> t;
    for (Index i = 0; i < T.rows(); ++i)
        for (SparseMatrix::InnerIterator it(T, i); it; ++it) {
            const int r = fine.compact[static_cast<size_t>(i)];
            const int c = coarse.compact[static_cast<size_t>(it.col())];
            if (r >= 0 && c >= 0) t.emplace_back(r, c, it.value());
        }
    SparseMatrix P(fine.K.rows(), coarse.K.rows());
    P.setFromTriplets(t.begin(), t.end());
    P.makeCompressed();
    return P;
}

ElasticMultigrid::ElasticMultigrid(const Hierarchy& h, const std::vector<ElasticBlock>& blocks,
                                   solvers::MultigridParams params) {
    const size_t n = blocks.size();
    MLC_CHECK(n >= 2 && n == static_cast<size_t>(h.n_levels()),
              "ElasticMultigrid: " << n << " elastic blocks for " << h.n_levels()
                                   << " levels (at least two needed)");
    P.resize(n);
    R.resize(n);
    std::vector<solvers::MultigridLevelData> data(n);
    for (size_t l = 0; l < n; ++l) {
        if (l > 0) {
            P[l] = displacement_prolongation(h.transfers[l - 1].T, blocks[l], blocks[l - 1]);
            R[l] = P[l].transpose();
            data[l].T = &P[l];
            data[l].R = &R[l];
        }
        data[l].block_starts = solvers::vertex_block_starts(blocks[l].vertex);
    }
    mg = std::make_unique<solvers::Multigrid>(std::move(data), params);
    for (size_t l = 0; l + 1 < n; ++l)
        mg->set_operator(static_cast<int>(l), blocks[l].K);
    mg->setup(blocks[n - 1].K);
}

} // namespace mlc::levels
