// SPDX-License-Identifier: MIT
#include "smoothers/lattice_gs.hpp"

#include "core/traffic.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "mesh/lattice.hpp"
#include "tests/common/random.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

using namespace mlc;
using namespace mlc::smoothers;

namespace {

// One level: the elastic stiffness of a 2 x 1 rectangle (four macro triangles) refined `depth`
// times, the bottom edge fixed in y (vertex blocks of one row there), numbered along the Hilbert
// curve (`lattice` false) or macro by macro (mesh::lattice_vertex_order).
struct LatticeCase {
    SparseMatrix A;
    std::vector<Index> starts;
    LatticeRows lattice;
    std::vector<int> row_of_hilbert_row; // the lattice-numbered row of each Hilbert-numbered row
};

LatticeCase elastic_case(int depth, bool lattice) {
    mesh::Mesh m =
        mesh::structured_rectangle({0.0, 0.0}, {2.0, 1.0}, 2, 1, mesh::Diagonal::alternate);
    for (int k = 0; k < depth; ++k)
        m = mesh::refine(m);
    const size_t nv = static_cast<size_t>(m.n_vertices());
    std::vector<std::array<bool, 2>> fixed(nv, {false, false});
    for (size_t v = 0; v < nv; ++v)
        if (m.vertices[v].y() == 0.0) fixed[v] = {false, true};
    const auto L = mesh::macro_lattice(m, depth);
    const std::vector<int> hilbert = mesh::hilbert_order(m.vertices);
    const fem::DofMap hdofs(fixed, std::vector<int>(nv, 0), hilbert);
    const fem::DofMap dofs(fixed, std::vector<int>(nv, 0),
                           lattice ? mesh::lattice_vertex_order(m, *L) : hilbert);
    const Vector zero = Vector::Zero(2 * m.n_vertices());
    LatticeCase c;
    c.A = fem::assemble_elastic(m, {fem::Material{}}, dofs, zero, zero).K;
    for (Index i = 0; i < dofs.n_dofs(); ++i)
        if (i == 0 || dofs.vertex_of(i) != dofs.vertex_of(i - 1)) c.starts.push_back(i);
    c.lattice.n = L->n;
    for (int v : L->vertex) {
        const int d0 = dofs.u_dof(v, 0), d1 = dofs.u_dof(v, 1);
        c.lattice.first_row.push_back(d0 >= 0 && d1 == d0 + 1 ? d0 : -1);
    }
    for (int v : hilbert) {
        const int d0 = dofs.u_dof(v, 0), d1 = dofs.u_dof(v, 1);
        c.lattice.visit.push_back(d0 >= 0 ? d0 : d1);
    }
    c.row_of_hilbert_row.resize(static_cast<size_t>(dofs.n_dofs()));
    for (size_t v = 0; v < nv; ++v)
        for (int k = 0; k < 2; ++k)
            if (hdofs.u_dof(static_cast<int>(v), k) >= 0)
                c.row_of_hilbert_row[static_cast<size_t>(hdofs.u_dof(static_cast<int>(v), k))] =
                    dofs.u_dof(static_cast<int>(v), k);
    return c;
}

// The reference: block Gauss–Seidel in the smoother's order, part by part, each part reading
// the other parts' unknowns as they were before the sweep, on A's own rows (no stencil).
Vector reference_sweep(const LatticeGS& S, const SparseMatrix& A, const std::vector<Index>& starts,
                       const Vector& b, const Vector& x0, bool forward, double omega) {
    const Index n = A.rows();
    std::vector<Index> size_of(static_cast<size_t>(n), 0);
    for (size_t k = 0; k < starts.size(); ++k)
        size_of[static_cast<size_t>(starts[k])] =
            (k + 1 < starts.size() ? starts[k + 1] : n) - starts[k];
    std::vector<int> part_of(static_cast<size_t>(n), -1);
    std::vector<std::vector<Index>> orders;
    for (int p = 0; p < S.parts(); ++p) {
        orders.push_back(S.sweep_order_blocks(p));
        for (Index r : orders.back())
            for (Index k = 0; k < size_of[static_cast<size_t>(r)]; ++k)
                part_of[static_cast<size_t>(r + k)] = p;
    }
    Vector x = x0;
    for (int p = 0; p < S.parts(); ++p) {
        std::vector<Index> order = orders[static_cast<size_t>(p)];
        if (!forward) std::reverse(order.begin(), order.end());
        for (Index r : order) {
            const Index s = size_of[static_cast<size_t>(r)];
            Eigen::VectorXd res(s);
            Eigen::MatrixXd D = Eigen::MatrixXd::Zero(s, s);
            for (Index k = 0; k < s; ++k) {
                double a = b[r + k];
                for (SparseMatrix::InnerIterator it(A, r + k); it; ++it) {
                    const bool own = part_of[static_cast<size_t>(it.col())] == p;
                    a -= it.value() * (own ? x[it.col()] : x0[it.col()]);
                    if (it.col() >= r && it.col() < r + s) D(k, it.col() - r) = it.value();
                }
                res[k] = a;
            }
            const Eigen::VectorXd d = omega * D.fullPivLu().solve(res);
            for (Index k = 0; k < s; ++k)
                x[r + k] += d[k];
        }
    }
    return x;
}

using mlc::testutil::random_vector;

// One sweep of the lattice smoother is block Gauss–Seidel of c.A in its visit order (Jacobi
// across the parts), to round-off: forward and backward, omega 1 and 1.3.
void expect_gauss_seidel(const LatticeCase& c, unsigned seed) {
    const Index n = c.A.rows();
    const Vector b = random_vector(n, seed), x0 = random_vector(n, seed + 1);
    for (double omega : {1.0, 1.3})
        for (bool forward : {true, false}) {
            LatticeGS S(c.starts, c.lattice, {.omega = omega});
            S.setup(c.A);
            Vector x = x0;
            S.smooth(b, x, forward ? Sweep::forward : Sweep::backward, 1);
            const Vector ref = reference_sweep(S, c.A, c.starts, b, x0, forward, omega);
            EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm()) << omega << " " << forward;
        }
}

} // namespace

// In the Hilbert visit, one part (level 4) and two (level 6).
TEST(LatticeGS, SweepIsBlockGaussSeidelInItsVisitOrder) {
    for (int depth : {4, 6}) {
        const LatticeCase c = elastic_case(depth, true);
        LatticeGS S(c.starts, c.lattice, {});
        S.setup(c.A);
        EXPECT_EQ(S.parts(), depth == 4 ? 1 : 2);
        EXPECT_GT(S.semi_deep_points(), 0);
        if (depth == 4) {
            // (16-1)(16-2)/2 = 105 interior points per macro, of which i, j >= 2,
            // i + j <= 14: 66 deep; four macros.
            EXPECT_EQ(S.deep_points(), 4 * 66);
        } else {
            EXPECT_GT(S.deep_points(), 4 * 1500); // of 4 * 1830 (i, j >= 2, i + j <= 62)
            EXPECT_LT(S.deep_points(), 4 * 1830); // the parts' cut takes some
        }
        SCOPED_TRACE(depth);
        expect_gauss_seidel(c, 1);
    }
}

// With the Hilbert visit order the lattice-numbered sweep is BlockSOR's sweep of the
// Hilbert-numbered matrix (the multigrid smoother: unrolled kernel, hybrid parts), to round-off.
TEST(LatticeGS, IsTheBlockSmootherOfTheDefaultNumbering) {
    const LatticeCase lat = elastic_case(6, true), hil = elastic_case(6, false);
    const Index n = lat.A.rows();
    const Vector bh = random_vector(n, 7), xh = random_vector(n, 8);
    Vector bl(n), xl(n);
    for (Index i = 0; i < n; ++i) {
        bl[lat.row_of_hilbert_row[static_cast<size_t>(i)]] = bh[i];
        xl[lat.row_of_hilbert_row[static_cast<size_t>(i)]] = xh[i];
    }
    BlockSOR B({.omega = 1.0,
                .block_size = 2,
                .block_starts = hil.starts,
                .parts = 0,
                .kernel = Kernel::unrolled});
    B.setup(hil.A);
    LatticeGS S(lat.starts, lat.lattice, {});
    S.setup(lat.A);
    EXPECT_EQ(S.parts(), B.parts());
    Vector xb = xh;
    for (int sweep = 0; sweep < 2; ++sweep) {
        B.sweep(bh, xb, Sweep::backward);
        S.smooth(bl, xl, Sweep::backward, 1);
        double diff = 0.0;
        for (Index i = 0; i < n; ++i)
            diff = std::max(diff,
                            std::abs(xl[lat.row_of_hilbert_row[static_cast<size_t>(i)]] - xb[i]));
        EXPECT_LT(diff, 1e-12 * xb.cwiseAbs().maxCoeff()) << sweep;
    }
}

// A deep row that differs from its macro's stencil is swept by its own rows: still Gauss–Seidel
// of A; and update_values sees a changed deep row.
TEST(LatticeGS, ARowOffItsStencilIsSweptByItsRows) {
    LatticeCase c = elastic_case(4, true);
    const Index n = c.A.rows();
    const Vector b = random_vector(n, 3), x0 = random_vector(n, 4);
    LatticeGS S(c.starts, c.lattice, {});
    S.setup(c.A);
    const Index deep = S.deep_points();
    // A point of macro 1 with i, j >= 2 (point 40 of 105: row 4, deep).
    const Index r = c.lattice.first_row[static_cast<size_t>(105 + 40)];
    c.A.coeffRef(r, r) *= 1.5;
    S.update_values(c.A);
    EXPECT_EQ(S.deep_points(), deep - 1);
    Vector x = x0;
    S.smooth(b, x, Sweep::backward, 1);
    const Vector ref = reference_sweep(S, c.A, c.starts, b, x0, false, 1.0);
    EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm());
}

// Two sweeps in one call are two calls; forward_from_zero returns the residual.
TEST(LatticeGS, RepeatedSweepsAndTheSweepFromZero) {
    const LatticeCase c = elastic_case(4, true);
    const Index n = c.A.rows();
    const Vector b = random_vector(n, 5), x0 = random_vector(n, 6);
    LatticeGS S(c.starts, c.lattice, {});
    S.setup(c.A);
    Vector x1 = x0, x2 = x0;
    S.smooth(b, x1, Sweep::backward, 2);
    S.smooth(b, x2, Sweep::backward, 1);
    S.smooth(b, x2, Sweep::backward, 1);
    EXPECT_EQ(x1, x2);
    Vector z, res;
    S.forward_from_zero(b, z, res);
    Vector z2 = Vector::Zero(n);
    S.smooth(b, z2, Sweep::forward, 1);
    EXPECT_EQ(z, z2);
    EXPECT_LT((res - (b - c.A * z)).norm(), 1e-13 * b.norm());
}

// A new entry in a deep, a semi-deep or a row-swept row is a new pattern: update_values sets up
// again (the point becomes row-swept) and the sweep stays Gauss–Seidel of the new matrix.
TEST(LatticeGS, ANewPatternIsSetUpAgain) {
    // semi_moved: a semi-deep point's first column pair moved to the last two columns (the
    // same row lengths: only the semi-deep pattern check sees it).
    enum Kind { deep_row, semi_row, swept_row, semi_moved };
    for (Kind kind : {deep_row, semi_row, swept_row, semi_moved}) {
        LatticeCase c = elastic_case(4, true);
        const Index n = c.A.rows();
        LatticeGS S(c.starts, c.lattice, {});
        S.setup(c.A);
        const Index deep = S.deep_points(), semi = S.semi_deep_points();
        // Row of a deep point of macro 2 (point 40), of a semi-deep one (point 60, next to an
        // edge), or of a row-swept one (point 0, next to the fixed bottom edge), coupled to a far
        // row (the last one): an entry that was not there.
        const int point = kind == deep_row ? 40 : kind == swept_row ? 0 : 60;
        const Index r = c.lattice.first_row[static_cast<size_t>(2 * 105 + point)];
        std::vector<Triplet> t;
        const Index moved = SparseMatrix::InnerIterator(c.A, r).col(); // first column pair
        for (Index i = 0; i < n; ++i)
            for (SparseMatrix::InnerIterator it(c.A, i); it; ++it) {
                const bool move = kind == semi_moved && (i == r || i == r + 1) &&
                                  (it.col() == moved || it.col() == moved + 1);
                t.emplace_back(i, move ? it.col() - moved + n - 2 : it.col(), it.value());
            }
        if (kind != semi_moved) {
            t.emplace_back(r, n - 1, 1e-3);
            t.emplace_back(n - 1, r, 1e-3);
        }
        SparseMatrix B(n, n);
        B.setFromTriplets(t.begin(), t.end());
        B.makeCompressed();
        S.update_values(B);
        EXPECT_EQ(S.deep_points(), kind == deep_row ? deep - 1 : deep);
        // (The moved pair, on the macro's edge, is matched to its slot by value again: the point
        // stays semi-deep, now reading the moved column; the sweep below tells.)
        EXPECT_EQ(S.semi_deep_points(), kind == semi_row ? semi - 1 : semi);
        const Vector b = random_vector(n, 9), x0 = random_vector(n, 10);
        Vector x = x0;
        S.smooth(b, x, Sweep::forward, 1);
        const Vector ref = reference_sweep(S, B, c.starts, b, x0, true, 1.0);
        EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm()) << kind;
    }
}

namespace {
// A visit of each macro's interior in serpentine rows (row j eastwards when j is odd, westwards
// when even: runs of deep points stepping +2 and -2 rows), then every other block in row order.
std::vector<Index> serpentine_visit(const LatticeCase& c, const std::vector<Index>& starts) {
    const int N = c.lattice.n;
    const size_t np = static_cast<size_t>(N - 1) * static_cast<size_t>(N - 2) / 2;
    std::vector<Index> visit;
    std::vector<char> seen(static_cast<size_t>(c.A.rows()), 0);
    for (size_t m = 0; m * np < c.lattice.first_row.size(); ++m) {
        size_t base = m * np;
        for (int j = 1; j <= N - 2; ++j) {
            const int len = N - 1 - j;
            for (int k = 0; k < len; ++k) {
                const Index r =
                    c.lattice.first_row[base + static_cast<size_t>(j % 2 ? k : len - 1 - k)];
                if (r >= 0 && !seen[static_cast<size_t>(r)]) {
                    visit.push_back(r);
                    seen[static_cast<size_t>(r)] = 1;
                }
            }
            base += static_cast<size_t>(len);
        }
    }
    for (Index s : starts)
        if (!seen[static_cast<size_t>(s)]) visit.push_back(s);
    return visit;
}
} // namespace

// Visited in serpentine rows (the multigrid's visit), the deep points go by runs along each row in
// both directions, each point's update taking its predecessor last (x = c - G x_behind): still
// block Gauss–Seidel in that order to round-off, forward and backward, omega 1 and 1.3.
TEST(LatticeGS, SerpentineRowsAreBlockGaussSeidelInThatOrder) {
    LatticeCase c = elastic_case(6, true);
    c.lattice.visit = serpentine_visit(c, c.starts);
    // An east coupling that is not the west one's transpose (a convection-like term): the
    // predecessor's block differs with the direction of the run.
    const double d = 0.2 * c.A.diagonal().mean();
    for (Index i = 0; i < c.A.rows(); ++i)
        for (SparseMatrix::InnerIterator it(c.A, i); it; ++it)
            if (it.col() == i + 2) it.valueRef() += d;
    LatticeGS S(c.starts, c.lattice, {});
    S.setup(c.A);
    EXPECT_GT(S.deep_points(), 4 * 1500);
    expect_gauss_seidel(c, 11);
}

// multiply is A x (deep rows by the macro's stencil, the others by their rows), with the Hilbert
// and the serpentine visits, one part (level 4) and two (level 6); so is LatticeOperator.
TEST(LatticeGS, MultiplyIsTheMatrixProduct) {
    for (int depth : {4, 6})
        for (bool serpentine : {false, true}) {
            LatticeCase c = elastic_case(depth, true);
            if (serpentine) c.lattice.visit = serpentine_visit(c, c.starts);
            LatticeGS S(c.starts, c.lattice, {});
            S.setup(c.A);
            ASSERT_GT(S.deep_points(), 0);
            const Vector x = random_vector(c.A.rows(), 13);
            const Vector ref = c.A * x;
            Vector y;
            S.multiply(x, y);
            EXPECT_LT((y - ref).norm(), 1e-13 * c.A.norm() * x.norm()) << depth << serpentine;
            Vector z = Vector::Constant(c.A.rows(), 7.0);
            LatticeOperator(S).apply(x, z);
            EXPECT_EQ(y, z);
        }
}

TEST(LatticeGS, ItsPassesAreCountedAsStructured) {
    // A sweep and a product are one `structured` pass each (bench square's matrix figure leaves
    // them out), nothing under smoother or matvec; each counts its vectors (b read and x read and
    // written: 24 n; x read and y written: 16 n) and less than A's 12 bytes per entry for the
    // rows it still reads (most rows by the stencils).
    const LatticeCase c = elastic_case(6, true);
    LatticeGS S(c.starts, c.lattice, {});
    S.setup(c.A);
    ASSERT_GT(S.deep_points(), 0);
    const double n = static_cast<double>(c.A.rows());
    const double matrix = 12.0 * static_cast<double>(c.A.nonZeros());
    const Vector b = random_vector(c.A.rows(), 5);
    Vector x = Vector::Zero(c.A.rows()), y;
    const traffic::Account a0 = traffic::snapshot();
    S.smooth(b, x, Sweep::backward, 1);
    const traffic::Account a1 = traffic::snapshot();
    S.multiply(x, y);
    const traffic::Account a2 = traffic::snapshot();
    const traffic::Account sweep = a1 - a0, product = a2 - a1;
    for (const traffic::Account* d : {&sweep, &product}) {
        EXPECT_EQ(d->p(traffic::Kind::structured), 1.0);
        EXPECT_EQ(d->p(traffic::Kind::smoother), 0.0);
        EXPECT_EQ(d->p(traffic::Kind::matvec), 0.0);
    }
    EXPECT_GT(sweep.b(traffic::Kind::structured), 24.0 * n);
    EXPECT_LT(sweep.b(traffic::Kind::structured), 24.0 * n + 0.5 * matrix);
    EXPECT_GT(product.b(traffic::Kind::structured), 16.0 * n);
    EXPECT_LT(product.b(traffic::Kind::structured), 16.0 * n + 0.5 * matrix);
}
