// SPDX-License-Identifier: MIT
// solvers::LatticeTransfer: the multigrid's T and R between two lattice-numbered levels, applied
// through the lattice, equal csr_multiply(T, ...) and csr_multiply(R, ...) bit for bit (with and
// without `add`), on the square (one body, a fixed side, a contact side) and on the patch test
// (two bodies, node on facet); most rows are structured; a row whose entries differ from the
// lattice's interpolation is applied by its entries.
#include "core/csr.hpp"
#include "core/traffic.hpp"
#include "levels/hierarchy.hpp"
#include "mesh/lattice.hpp"
#include "scene/scene.hpp"
#include "solvers/lattice_transfer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>

using namespace mlc;

namespace {

// Values of every sign and size, with exact zeros and negative zeros among them.
Vector sample(Index n, unsigned seed) {
    std::mt19937 g(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Vector x(n);
    for (Index i = 0; i < n; ++i) {
        const int k = static_cast<int>(g() % 16);
        x[i] = k == 0 ? 0.0 : k == 1 ? -0.0 : u(g) * std::ldexp(1.0, k - 8);
    }
    return x;
}

bool same_bits(const Vector& a, const Vector& b) {
    return a.size() == b.size() &&
           std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

// T x, y += T x and R x through `lt` against csr_multiply, bit for bit.
void expect_products(const solvers::LatticeTransfer& lt, const SparseMatrix& T,
                     const SparseMatrix& R, unsigned seed, const std::string& what) {
    const Vector xc = sample(T.cols(), seed), xf = sample(T.rows(), seed + 1);
    Vector ref, got;
    csr_multiply(T, xc, ref);
    lt.prolongate(xc, got, false);
    EXPECT_TRUE(same_bits(ref, got))
        << what << ": T x, largest difference " << (ref - got).cwiseAbs().maxCoeff();
    ref = xf;
    got = xf;
    csr_multiply(T, xc, ref, true);
    lt.prolongate(xc, got, true);
    EXPECT_TRUE(same_bits(ref, got)) << what << ": y += T x";
    csr_multiply(R, xf, ref);
    lt.restrict_residual(xf, got);
    EXPECT_TRUE(same_bits(ref, got))
        << what << ": R x, largest difference " << (ref - got).cwiseAbs().maxCoeff();
}

// The patch test's levels 0-5 numbered by lattices (levels 4 and 5 have lattices): two bodies,
// 86 000 unknowns on level 5, six times fewer than the square's.
levels::Hierarchy patch_level5() {
    auto p = scene::load_scene("patch");
    p.levels = 5;
    p.numbering = levels::Problem::Numbering::lattice;
    return levels::build_hierarchy(p);
}

void expect_like_csr(const SparseMatrix& T, const SparseMatrix& R,
                     const smoothers::LatticeRows& fine, const smoothers::LatticeRows& coarse,
                     const std::string& what, double min_structured) {
    const solvers::LatticeTransfer lt(T, R, fine, coarse);
    EXPECT_GE(static_cast<double>(lt.structured_rows_T()), min_structured * T.rows()) << what;
    EXPECT_GE(static_cast<double>(lt.structured_rows_R()), min_structured * R.rows()) << what;
    expect_products(lt, T, R, 1, what);
    const Vector xf = sample(T.rows(), 2);
    Vector got;
    const traffic::Account before = traffic::snapshot();
    lt.restrict_residual(xf, got);
    const traffic::Account d = traffic::snapshot() - before;
    // One structured pass; fewer bytes than the CSR product's.
    EXPECT_EQ(d.p(traffic::Kind::structured), 1.0) << what;
    EXPECT_LT(d.b(traffic::Kind::structured),
              traffic::csr_bytes(R.rows(), R.cols(), R.nonZeros(), false))
        << what;
}

void expect_scene(const std::string& scene, int levels, double min_structured) {
    auto p = scene::load_scene(scene);
    p.levels = levels;
    p.numbering = levels::Problem::Numbering::lattice;
    const levels::Hierarchy h = levels::build_hierarchy(p);
    int checked = 0;
    for (int l = 0; l + 1 < h.n_levels(); ++l) {
        const auto& coarse = h.levels[static_cast<size_t>(l)].lattice;
        const auto& fine = h.levels[static_cast<size_t>(l + 1)].lattice;
        if (!coarse || !fine) continue;
        const auto& tr = h.transfers[static_cast<size_t>(l)];
        expect_like_csr(tr.T, tr.R, *fine, *coarse, scene + " level " + std::to_string(l + 1),
                        min_structured);
        ++checked;
    }
    EXPECT_EQ(checked, levels - 4) << scene;
}

} // namespace

TEST(LatticeTransfer, TAndRThroughTheLatticeAreTheirCsrProductsBitForBit) {
    // Levels 4 -> 5: 16 and 32 subdivisions per macro edge. The structured fine points are those
    // of lattice rows 2 .. 29 from column 2 on (378 of a macro's 512 vertices: 74 %; 86 % at 64
    // subdivisions). The square has one body, patch two (node on facet).
    for (const char* scene : {"square", "patch"})
        expect_scene(scene, 5, 0.7);
}

// A row of T or R that is not the lattice's interpolation (here: one value changed in a
// structured row of each) is applied by its entries: the products stay csr_multiply's.
TEST(LatticeTransfer, ARowThatIsNotTheInterpolationIsAppliedByItsEntries) {
    const levels::Hierarchy h = patch_level5();
    SparseMatrix T = h.transfers[4].T, R = h.transfers[4].R;
    const auto& fine = *h.levels[5].lattice;
    const auto& coarse = *h.levels[4].lattice;
    const solvers::LatticeTransfer all(h.transfers[4].T, h.transfers[4].R, fine, coarse);
    // Point (8, 8) of macro 0's fine lattice (32 subdivisions), point (4, 4) of its coarse one.
    const Index rt = fine.first_row[static_cast<size_t>(mesh::MacroLattice::point_index(32, 8, 8))];
    const Index rr =
        coarse.first_row[static_cast<size_t>(mesh::MacroLattice::point_index(16, 4, 4))];
    ASSERT_EQ(fine.n, 32);
    ASSERT_EQ(coarse.n, 16);
    ASSERT_GE(rt, 0);
    ASSERT_GE(rr, 0);
    T.valuePtr()[T.outerIndexPtr()[rt]] *= 1.25;
    R.valuePtr()[R.outerIndexPtr()[rr]] *= 1.25;
    const solvers::LatticeTransfer changed(T, R, fine, coarse);
    // The macro holding them is applied by its entries (a whole macro falls back).
    EXPECT_LT(changed.structured_rows_T(), all.structured_rows_T());
    EXPECT_LT(changed.structured_rows_R(), all.structured_rows_R());
    EXPECT_GT(changed.structured_rows_T(), 0);
    expect_products(changed, T, R, 3, "a changed row");
}

// Two macros that claim the same rows (a malformed lattice): only the first is applied through
// the lattice, so no row is written twice and y += T x stays csr_multiply's.
TEST(LatticeTransfer, MacrosThatShareRowsAreAppliedOnce) {
    const levels::Hierarchy h = patch_level5();
    const auto& T = h.transfers[4].T;
    const auto& R = h.transfers[4].R;
    smoothers::LatticeRows fine = *h.levels[5].lattice, coarse = *h.levels[4].lattice;
    const long npf = smoothers::LatticeRows::interior_points(fine.n);
    const long npc = smoothers::LatticeRows::interior_points(coarse.n);
    ASSERT_GE(fine.first_row.size(), static_cast<size_t>(2 * npf));
    // Macro 1 repeats macro 0's rows on both levels.
    std::copy(fine.first_row.begin(), fine.first_row.begin() + npf, fine.first_row.begin() + npf);
    std::copy(coarse.first_row.begin(), coarse.first_row.begin() + npc,
              coarse.first_row.begin() + npc);
    const solvers::LatticeTransfer all(T, R, *h.levels[5].lattice, *h.levels[4].lattice);
    const solvers::LatticeTransfer shared(T, R, fine, coarse);
    EXPECT_LT(shared.structured_rows_T(), all.structured_rows_T());
    EXPECT_GT(shared.structured_rows_T(), 0);
    expect_products(shared, T, R, 5, "a repeated macro");
}
