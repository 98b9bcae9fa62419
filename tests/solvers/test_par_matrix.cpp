// SPDX-License-Identifier: MIT
// The hypre ParCSR matrix of a distributed level against the serial stiffness, on any number of
// processes: ctest runs these tests alone (one process) and under mpirun -np 2 and -np 3 (label
// mpi). Each process assembles the rows of its owned vertices from its local triangles (owned
// and ghost); the mat-vec's entries must equal the serial mesh's to 1e-12 relative, vertex by
// vertex (matched by their exact coordinates). Only with hypre (solvers/hypre/par_matrix.cpp).
#if MLC_HAVE_HYPRE
#include "comm/world.hpp"
#include "core/check.hpp"
#include "fem/elasticity.hpp"
#include "mesh/distributed.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/par_matrix.hpp"
#include "solvers/krylov.hpp"
#include "solvers/process_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

using namespace mlc;

namespace {

const Communicator& W() {
    return comm::world();
}

using Point = std::pair<double, double>;

mesh::Mesh curved_rectangle() {
    mesh::Mesh m = mesh::structured_rectangle({0, 0}, {1, 0.6}, 5, 3, mesh::Diagonal::alternate);
    m.shapes.push_back({{0.5, -10.0}, 10.6});
    for (auto& e : m.boundary)
        if (e.tag == m.tag("top")) e.shape = 0;
    return m;
}

const fem::Material steel{.E = 2.0, .nu = 0.3};

/// The rows of the owned vertices' unknowns (2 per vertex, interleaved), assembled from the
/// local triangles, with global columns: 2 global_vertex + component.
solvers::DistributedRows owned_rows(const mesh::LocalLevel& L) {
    const int n = 2 * L.n_owned_vertices();
    std::vector<int> row_of(static_cast<size_t>(L.mesh.n_vertices()), -1);
    for (int i = 0; i < L.n_owned_vertices(); ++i)
        row_of[static_cast<size_t>(L.owned_vertices[static_cast<size_t>(i)])] = 2 * i;
    std::vector<Eigen::Triplet<double>> trip;
    for (const auto& t : L.mesh.cells) {
        const auto K = fem::element_stiffness(L.mesh.vertices[static_cast<size_t>(t[0])],
                                              L.mesh.vertices[static_cast<size_t>(t[1])],
                                              L.mesh.vertices[static_cast<size_t>(t[2])], steel);
        for (int a = 0; a < 3; ++a) {
            const int r = row_of[static_cast<size_t>(t[a])];
            if (r < 0) continue;
            for (int b = 0; b < 3; ++b) {
                const auto g = static_cast<int>(L.global_vertex[static_cast<size_t>(t[b])]);
                for (int ca = 0; ca < 2; ++ca)
                    for (int cb = 0; cb < 2; ++cb)
                        trip.emplace_back(r + ca, 2 * g + cb, K(2 * a + ca, 2 * b + cb));
            }
        }
    }
    SparseMatrix A(n, 2 * L.n_global_vertices);
    A.setFromTriplets(trip.begin(), trip.end());
    solvers::DistributedRows rows;
    rows.first_row = L.first_row();
    rows.row_ptr.assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
    rows.cols.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    rows.values.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
    return rows;
}

/// The serial stiffness of the whole mesh plus shift I (symmetric positive definite for
/// shift > 0), vertices in index order.
SparseMatrix serial_shifted(const mesh::Mesh& m, double shift) {
    const int n = 2 * m.n_vertices();
    std::vector<Eigen::Triplet<double>> trip;
    for (const auto& t : m.cells) {
        const auto K = fem::element_stiffness(m.vertices[static_cast<size_t>(t[0])],
                                              m.vertices[static_cast<size_t>(t[1])],
                                              m.vertices[static_cast<size_t>(t[2])], steel);
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b)
                trip.emplace_back(2 * t[a / 2] + a % 2, 2 * t[b / 2] + b % 2, K(a, b));
    }
    for (int i = 0; i < n; ++i)
        trip.emplace_back(i, i, shift);
    SparseMatrix A(n, n);
    A.setFromTriplets(trip.begin(), trip.end());
    return A;
}

/// The test field at every vertex of a whole mesh, (sin 3x + y, xy - 1/2), vertices in index
/// order (owned_field gives the same values at a process's owned vertices).
Vector serial_field(const mesh::Mesh& m) {
    Vector x(2 * m.n_vertices());
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec2& p = m.vertices[static_cast<size_t>(v)];
        x[2 * v] = std::sin(3 * p.x()) + p.y();
        x[2 * v + 1] = p.x() * p.y() - 0.5;
    }
    return x;
}

/// Largest difference, over all processes, between the owned entries of a distributed vector x
/// and the entries of the serial vector xs at the same vertices (matched by coordinates).
double max_owned_difference(const mesh::LocalLevel& L, const Vector& x, const mesh::Mesh& serial,
                            const Vector& xs) {
    std::map<Point, int> serial_vertex;
    for (int v = 0; v < serial.n_vertices(); ++v)
        serial_vertex[{serial.vertices[static_cast<size_t>(v)].x(),
                       serial.vertices[static_cast<size_t>(v)].y()}] = v;
    double diff = 0;
    for (int i = 0; i < L.n_owned_vertices(); ++i) {
        const Vec2& p =
            L.mesh.vertices[static_cast<size_t>(L.owned_vertices[static_cast<size_t>(i)])];
        const int v = serial_vertex.at({p.x(), p.y()});
        diff = std::max(
            {diff, std::abs(x[2 * i] - xs[2 * v]), std::abs(x[2 * i + 1] - xs[2 * v + 1])});
    }
    return W().max(diff);
}

/// Serial stiffness of the whole mesh times serial_field, by vertex coordinates.
std::map<Point, Vec2> serial_product(const mesh::Mesh& m) {
    const SparseMatrix A = serial_shifted(m, 0.0);
    const Vector y = A * serial_field(m);
    std::map<Point, Vec2> out;
    for (int v = 0; v < m.n_vertices(); ++v)
        out[{m.vertices[static_cast<size_t>(v)].x(), m.vertices[static_cast<size_t>(v)].y()}] =
            Vec2(y[2 * v], y[2 * v + 1]);
    return out;
}

Vector owned_field(const mesh::LocalLevel& L) {
    Vector x(2 * L.n_owned_vertices());
    for (int i = 0; i < L.n_owned_vertices(); ++i) {
        const Vec2& p =
            L.mesh.vertices[static_cast<size_t>(L.owned_vertices[static_cast<size_t>(i)])];
        x[2 * i] = std::sin(3 * p.x()) + p.y();
        x[2 * i + 1] = p.x() * p.y() - 0.5;
    }
    return x;
}

/// max over the owned vertices of |y - serial| / max |serial|, over all processes.
double relative_difference(const mesh::LocalLevel& L, const Vector& y,
                           const std::map<Point, Vec2>& serial) {
    double scale = 0, diff = 0;
    for (const auto& [p, s] : serial)
        scale = std::max(scale, s.cwiseAbs().maxCoeff());
    for (int i = 0; i < L.n_owned_vertices(); ++i) {
        const Vec2& p =
            L.mesh.vertices[static_cast<size_t>(L.owned_vertices[static_cast<size_t>(i)])];
        const Vec2& s = serial.at({p.x(), p.y()});
        diff = std::max(diff, std::max(std::abs(y[2 * i] - s.x()), std::abs(y[2 * i + 1] - s.y())));
    }
    return W().max(diff) / scale;
}

} // namespace

TEST(ParMatrix, StiffnessMatvecEqualsTheSerialOneOnEveryLevel) {
    const mesh::Mesh m0 = curved_rectangle();
    const auto H = mesh::distribute(m0, 2, W());
    mesh::Mesh serial = m0;
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        if (l > 0) serial = mesh::refine(serial);
        const mesh::LocalLevel& L = H.levels[l];
        const solvers::ParMatrix A(W(), owned_rows(L));
        EXPECT_EQ(A.n_global(), 2 * serial.n_vertices());
        EXPECT_EQ(A.first_row(), L.first_row());
        const Vector x = owned_field(L);
        Vector y(x.size());
        A.apply(x, y);
        const double rel = relative_difference(L, y, serial_product(serial));
        EXPECT_LT(rel, 1e-12);
    }
}

// New values for the same pattern, written in place: twice the values give twice the product,
// as a matrix built from the doubled values does.
TEST(ParMatrix, UpdateValuesInPlace) {
    const auto H = mesh::distribute(curved_rectangle(), 1, W());
    const mesh::LocalLevel& L = H.levels.back();
    auto rows = owned_rows(L);
    solvers::ParMatrix A(W(), rows);
    const Vector x = owned_field(L);
    Vector y1(x.size()), y2(x.size()), y3(x.size());
    A.apply(x, y1);
    for (double& v : rows.values)
        v *= 2;
    A.update_values(rows.values);
    A.apply(x, y2);
    const solvers::ParMatrix B(W(), rows);
    B.apply(x, y3);
    const double scale = W().max(y1.cwiseAbs().maxCoeff());
    EXPECT_LT(W().max((y2 - 2 * y1).cwiseAbs().maxCoeff()), 1e-14 * scale);
    EXPECT_LT(W().max((y2 - y3).cwiseAbs().maxCoeff()), 1e-14 * scale);
    EXPECT_THROW(A.update_values(std::vector<double>(rows.values.size() + 1)), InvalidInput);
}

// One process's communicator on every process: the same product from each process's own copy.
TEST(ParMatrix, SerialCommunicatorOnEveryProcess) {
    const SerialCommunicator one;
    const mesh::Mesh m = mesh::refine(curved_rectangle());
    const auto H = mesh::distribute(m, 0, one);
    const mesh::LocalLevel& L = H.levels.back();
    const solvers::ParMatrix A(one, owned_rows(L));
    const Vector x = owned_field(L);
    Vector y(x.size());
    A.apply(x, y);
    const auto serial = serial_product(m);
    double diff = 0, scale = 0;
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        const Vec2& s = serial.at({L.mesh.vertices[v].x(), L.mesh.vertices[v].y()});
        scale = std::max(scale, s.cwiseAbs().maxCoeff());
        diff = std::max(diff, (Vec2(y[2 * v], y[2 * v + 1]) - s).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(diff, 1e-12 * scale);
}

TEST(ParMatrix, RejectsBlocksOutOfOrderAndColumnsOutOfRangeOnEveryProcess) {
    const auto H = mesh::distribute(curved_rectangle(), 0, W());
    auto rows = owned_rows(H.levels.back());
    auto shifted = rows;
    shifted.first_row += 1;
    EXPECT_THROW(solvers::ParMatrix(W(), shifted), InvalidInput);
    auto bad = rows;
    if (W().rank() + 1 == W().size() && !bad.cols.empty()) bad.cols.back() = -1;
    EXPECT_THROW(solvers::ParMatrix(W(), bad), InvalidInput);
}

namespace {

// The owned rows of K + shift I on one process's part of a level.
solvers::DistributedRows shifted_owned_rows(const mesh::LocalLevel& L, double shift) {
    auto rows = owned_rows(L);
    for (int i = 0; i < rows.n_rows(); ++i)
        for (int k = rows.row_ptr[static_cast<size_t>(i)];
             k < rows.row_ptr[static_cast<size_t>(i) + 1]; ++k)
            if (rows.cols[static_cast<size_t>(k)] == rows.first_row + i)
                rows.values[static_cast<size_t>(k)] += shift;
    return rows;
}

} // namespace

// CGS, BiCG, BiCGStab and GMRES with global reductions (KrylovParams::comm) on the distributed
// operator K + 0.05 I of level 2: the owned entries of the solution equal the one-process
// (Eigen) solve's to 1e-8 relative, vertex by vertex, in about as many iterations.
TEST(ParMatrix, KrylovWithGlobalReductionsMatchesOneProcess) {
    const double shift = 0.05;
    const mesh::Mesh m0 = curved_rectangle();
    const auto H = mesh::distribute(m0, 2, W());
    const mesh::LocalLevel& L = H.levels.back();
    const auto rows = shifted_owned_rows(L, shift);
    const solvers::ParMatrix A(W(), rows);
    const Vector b = owned_field(L);
    const mesh::Mesh serial = mesh::refine(mesh::refine(m0));
    const SparseMatrix As = serial_shifted(serial, shift);
    const Vector bs = serial_field(serial);
    std::map<Point, int> serial_vertex;
    for (int v = 0; v < serial.n_vertices(); ++v)
        serial_vertex[{serial.vertices[static_cast<size_t>(v)].x(),
                       serial.vertices[static_cast<size_t>(v)].y()}] = v;
    const IdentityPreconditioner none;
    for (auto method : {solvers::Krylov::cgs, solvers::Krylov::bicg, solvers::Krylov::bicgstab,
                        solvers::Krylov::gmres}) {
        SCOPED_TRACE(std::string(solvers::to_string(method)));
        Vector x, xs;
        const auto r =
            solvers::solve(method, A, none, b, x,
                           solvers::KrylovParams{.rel_tol = 1e-12, .max_iter = 3000, .comm = &W()});
        const auto rs = solvers::solve(method, As, none, bs, xs,
                                       solvers::KrylovParams{.rel_tol = 1e-12, .max_iter = 3000});
        EXPECT_TRUE(r.converged) << r.message;
        EXPECT_TRUE(rs.converged) << rs.message;
        // Within 10% (at least 2): the sums of inner products and mat-vec rows are ordered
        // differently, and CGS and BiCGStab without a preconditioner amplify the rounding (their
        // counts at 1e-12 move by up to 7% between orderings, one process included).
        EXPECT_LE(std::abs(r.iterations - rs.iterations), std::max(2, rs.iterations / 10))
            << r.iterations << " vs " << rs.iterations;
        EXPECT_GT(r.iterations, 10); // a real solve, not a trivial one
        EXPECT_LT(max_owned_difference(L, x, serial, xs), 1e-8 * xs.cwiseAbs().maxCoeff());
        // Every process stopped at the same iteration with the same residual.
        EXPECT_EQ(W().max(r.iterations), W().min(r.iterations));
        EXPECT_EQ(W().max(r.final_residual), W().min(r.final_residual));
    }
}
// hypre's ParCSR PCG with BoomerAMG (boomeramg_pcg_par, the distributed bench elastic's
// reference) on the distributed K + 0.05 I of level 2: it converges to the tolerance by its own
// and by the true residual (computed with global reductions), in the same iterations on every
// process, and its owned entries equal the one-process boomeramg_pcg solution to 1e-8.
TEST(ParMatrix, BoomerAMGPcgMatchesOneProcess) {
    const double shift = 0.05;
    const mesh::Mesh m0 = curved_rectangle();
    const auto H = mesh::distribute(m0, 2, W());
    const mesh::LocalLevel& L = H.levels.back();
    const solvers::ParMatrix A(W(), shifted_owned_rows(L, shift));
    const Vector b = owned_field(L);
    const mesh::Mesh serial = mesh::refine(mesh::refine(m0));
    const SparseMatrix As = serial_shifted(serial, shift);
    const Vector bs = serial_field(serial);
    Vector x, xs;
    const auto r = solvers::boomeramg_pcg_par(A, b, x, 1e-11, 200);
    const auto rs = solvers::boomeramg_pcg(As, bs, xs, 1e-11, 200);
    EXPECT_TRUE(r.converged);
    EXPECT_TRUE(rs.converged);
    EXPECT_LE(r.relative_residual, 1e-11);
    EXPECT_GT(r.iterations, 1);
    EXPECT_LT(r.iterations, 100);
    EXPECT_EQ(W().max(r.iterations), W().min(r.iterations));
    EXPECT_EQ(W().max(r.relative_residual), W().min(r.relative_residual));
    ASSERT_EQ(x.size(), A.n_rows());
    EXPECT_LT(max_owned_difference(L, x, serial, xs), 1e-8 * xs.cwiseAbs().maxCoeff());
    // Input errors throw on every process alike (here: b of the wrong size on every process).
    Vector bad = Vector::Zero(A.n_rows() + 1), y;
    EXPECT_THROW(solvers::boomeramg_pcg_par(A, bad, y, 1e-8, 10), InvalidInput);
}

// ILU(0) on each process's diagonal block (Jacobi across the cuts) preconditions CGS on the
// distributed K + 0.05 I: the solution equals the one-process solve to 1e-8; with one process
// the block is the whole matrix and the iterations are the serial ILU(0) solve's (within 10%);
// with more, the cuts cost iterations but fewer than without a preconditioner.
TEST(ParMatrix, ProcessBlockIluPreconditionsCgs) {
    const double shift = 0.05;
    const mesh::Mesh m0 = curved_rectangle();
    const auto H = mesh::distribute(m0, 2, W());
    const mesh::LocalLevel& L = H.levels.back();
    const auto rows = shifted_owned_rows(L, shift);
    const solvers::ParMatrix A(W(), rows);
    solvers::ProcessBlockPreconditioner M(solvers::make_preconditioner("ilu:0"));
    M.setup_rows(rows);
    EXPECT_EQ(M.name(), "process-block(" + solvers::make_preconditioner("ilu:0")->name() + ")");
    const SparseMatrix B = solvers::diagonal_block(rows);
    EXPECT_EQ(B.rows(), rows.n_rows());
    // The block keeps exactly the entries in own columns.
    Index own = 0;
    for (auto c : rows.cols)
        own += c >= rows.first_row && c < rows.first_row + rows.n_rows();
    EXPECT_EQ(B.nonZeros(), own);
    const Vector b = owned_field(L);
    const solvers::KrylovParams kp{.rel_tol = 1e-12, .max_iter = 3000, .comm = &W()};
    Vector x, x0;
    const auto r = solvers::cgs(A, M, b, x, kp);
    const auto r0 = solvers::cgs(A, IdentityPreconditioner(), b, x0, kp);
    ASSERT_TRUE(r.converged) << r.message;
    ASSERT_TRUE(r0.converged) << r0.message;
    EXPECT_LT(r.iterations, r0.iterations / 2) << r.iterations << " vs " << r0.iterations;
    // One process: the serial ILU(0) solve.
    const mesh::Mesh serial = mesh::refine(mesh::refine(m0));
    const SparseMatrix As = serial_shifted(serial, shift);
    const Vector bs = serial_field(serial);
    Vector xs;
    auto Ms = solvers::make_preconditioner("ilu:0");
    Ms->setup(As);
    const auto rs = solvers::cgs(MatrixOperator(As), *Ms, bs, xs,
                                 solvers::KrylovParams{.rel_tol = 1e-12, .max_iter = 3000});
    ASSERT_TRUE(rs.converged);
    if (W().size() == 1) {
        EXPECT_LE(std::abs(r.iterations - rs.iterations), std::max(2, rs.iterations / 10));
    }
    EXPECT_LT(max_owned_difference(L, x, serial, xs), 1e-8 * xs.cwiseAbs().maxCoeff());
}
#endif
