// SPDX-License-Identifier: MIT
// The distributed 3D levels (levels/distributed3.hpp: elastic block) against the one-process
// levels (levels::build_hierarchy), on any number of processes: ctest runs these tests alone (one
// process) and under mpirun -np 1, 2 and 3 (label mpi). Every process compares the unknowns it
// owns with the one-process level's, matched by their vertices' exact coordinates (midpoints are
// computed by the same arithmetic on every process).
#include "core/check.hpp"

#include <gtest/gtest.h>

#if MLC_HAVE_HYPRE
#include "comm/world.hpp"
#include "levels/distributed3.hpp"
#include "scene/scene3.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/par_matrix.hpp"

#include <Eigen/SparseCholesky>

#include <array>
#include <cmath>
#include <map>

using namespace mlc;

namespace {

using P3 = std::array<double, 3>;

P3 p3(const mesh::Vec3& x) {
    return {x.x(), x.y(), x.z()};
}

/// A reproducible "random" value of serial unknown i (the same on every process).
double pseudo_random(Index i) {
    return std::sin(12.9898 * static_cast<double>(i) + 0.7) * 43758.5453 -
           std::floor(std::sin(12.9898 * static_cast<double>(i) + 0.7) * 43758.5453) - 0.5;
}

/// The serial unknown of every local unknown of a part (-1: none), matched by coordinates;
/// expects every local vertex in the serial mesh with the same fixed components.
std::vector<Index> serial_dofs(const levels::DistributedLevel3& d, const levels::Level3& s) {
    std::map<P3, int> serial_vertex;
    for (int v = 0; v < s.mesh.n_vertices(); ++v)
        serial_vertex[p3(s.mesh.vertices[static_cast<size_t>(v)])] = v;
    const auto& dofs = d.local.dofs;
    std::vector<Index> out(static_cast<size_t>(dofs.n_dofs()), -1);
    for (int v = 0; v < d.local.mesh.n_vertices(); ++v) {
        const auto it = serial_vertex.find(p3(d.local.mesh.vertices[static_cast<size_t>(v)]));
        EXPECT_NE(it, serial_vertex.end()) << "local vertex " << v << " is no serial vertex";
        if (it == serial_vertex.end()) continue;
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(d.local.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)],
                      s.fixed[static_cast<size_t>(it->second)][static_cast<size_t>(c)])
                << "vertex " << v << " component " << c;
            if (const int i = dofs.u_dof(v, c); i >= 0)
                out[static_cast<size_t>(i)] = s.dofs.u_dof(it->second, c);
        }
    }
    return out;
}

/// The serial vector x (of level s) at the owned unknowns of a part.
Vector owned_part(const std::vector<Index>& to_serial, Index n_owned, const Vector& x) {
    Vector y(n_owned);
    for (Index i = 0; i < n_owned; ++i)
        y[i] = x[to_serial[static_cast<size_t>(i)]];
    return y;
}

/// x with a reproducible value at every serial displacement unknown (0 at multipliers).
Vector serial_random(const levels::Level3& s) {
    Vector x = Vector::Zero(s.dofs.n_dofs());
    for (Index i = 0; i < x.size(); ++i)
        if (s.dofs.is_displacement(i)) x[i] = pseudo_random(i);
    return x;
}

struct Block3dLevels {
    levels::ElasticProblem3 p;
    levels::Hierarchy3 serial;
    levels::DistributedHierarchy3 dist;
};

/// block3d, levels 0-1, partitioned on level 0.
const Block3dLevels& block3d() {
    static const Block3dLevels b = [] {
        Block3dLevels r;
        r.p = scene::load_scene3("block3d");
        r.serial = levels::build_hierarchy(r.p, 1);
        r.dist = levels::build_distributed_hierarchy3(r.p, 0, 1, comm::world());
        return r;
    }();
    return b;
}

} // namespace

TEST(Distributed3Levels, NumberingCoversTheSerialUnknownsOnce) {
    const auto& b = block3d();
    const Communicator& comm = comm::world();
    ASSERT_EQ(b.dist.levels.size(), 2U);
    for (size_t l = 0; l < 2; ++l) {
        const auto& d = b.dist.levels[l];
        const auto& s = b.serial.levels[l];
        EXPECT_EQ(d.n_global_dofs, s.dofs.n_displacement_dofs()) << "level " << l;
        EXPECT_EQ(d.first_dof, comm.exclusive_sum(static_cast<std::int64_t>(d.n_owned)));
        const auto to_serial = serial_dofs(d, s);
        // Every serial displacement unknown is owned by exactly one process.
        std::vector<int> count(static_cast<size_t>(s.dofs.n_dofs()), 0);
        for (Index i = 0; i < d.n_owned; ++i) {
            ASSERT_GE(to_serial[static_cast<size_t>(i)], 0);
            ++count[static_cast<size_t>(to_serial[static_cast<size_t>(i)])];
        }
        comm.allreduce(std::span<int>(count), ReduceOp::sum);
        for (Index i = 0; i < s.dofs.n_dofs(); ++i)
            EXPECT_EQ(count[static_cast<size_t>(i)], s.dofs.is_displacement(i) ? 1 : 0)
                << "level " << l << " serial unknown " << i;
        // Ghost unknowns carry their owners' global numbers: the same serial unknown.
        std::vector<std::int64_t> serial_of_global(static_cast<size_t>(d.n_global_dofs), 0);
        for (Index i = 0; i < d.n_owned; ++i)
            serial_of_global[static_cast<size_t>(d.first_dof + i)] =
                to_serial[static_cast<size_t>(i)];
        comm.allreduce(std::span<std::int64_t>(serial_of_global), ReduceOp::sum);
        for (Index i = d.n_owned; i < d.local.dofs.n_dofs(); ++i)
            EXPECT_EQ(serial_of_global[static_cast<size_t>(d.global_dof[static_cast<size_t>(i)])],
                      to_serial[static_cast<size_t>(i)])
                << "level " << l << " ghost unknown " << i;
    }
}

TEST(Distributed3Levels, StiffnessTimesARandomVectorAndLoadAreTheSerialOnes) {
    const auto& b = block3d();
    for (size_t l = 0; l < 2; ++l) {
        const auto& d = b.dist.levels[l];
        const auto& s = b.serial.levels[l];
        const auto to_serial = serial_dofs(d, s);
        const Vector x = serial_random(s);
        const Vector Kx = s.elastic.K * x;
        Vector y;
        d.K->apply(owned_part(to_serial, d.n_owned, x), y);
        ASSERT_EQ(y.size(), d.n_owned);
        const double scale = Kx.cwiseAbs().maxCoeff();
        ASSERT_GT(scale, 0.0);
        const Vector ref = owned_part(to_serial, d.n_owned, Kx);
        for (Index i = 0; i < d.n_owned; ++i)
            EXPECT_NEAR(y[i], ref[i], 1e-12 * scale) << "level " << l << " row " << i;
        const Vector f = d.owned_load();
        const Vector f_ref = owned_part(to_serial, d.n_owned, s.elastic.f);
        const double f_scale = s.elastic.f.cwiseAbs().maxCoeff();
        ASSERT_GT(f_scale, 0.0);
        for (Index i = 0; i < d.n_owned; ++i)
            EXPECT_NEAR(f[i], f_ref[i], 1e-12 * f_scale) << "level " << l << " row " << i;
    }
}

TEST(Distributed3Levels, TransferTimesACoarseVectorIsTheSerialOne) {
    const auto& b = block3d();
    ASSERT_EQ(b.dist.transfers.size(), 1U);
    const auto& dc = b.dist.levels[0];
    const auto& df = b.dist.levels[1];
    const auto& sc = b.serial.levels[0];
    const auto& sf = b.serial.levels[1];
    const Vector xc = serial_random(sc);
    const Vector Tx = b.serial.transfers[0].T * xc;
    Vector y;
    b.dist.transfers[0].T->apply(owned_part(serial_dofs(dc, sc), dc.n_owned, xc), y);
    ASSERT_EQ(y.size(), df.n_owned);
    const Vector ref = owned_part(serial_dofs(df, sf), df.n_owned, Tx);
    const double scale = Tx.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    for (Index i = 0; i < df.n_owned; ++i)
        EXPECT_NEAR(y[i], ref[i], 1e-12 * scale) << "fine row " << i;
    // The transpose too (restriction of a fine vector).
    const Vector xf = serial_random(sf);
    const Vector Rx = b.serial.transfers[0].R * xf;
    Vector z;
    b.dist.transfers[0].T->apply_transpose(owned_part(serial_dofs(df, sf), df.n_owned, xf), z);
    ASSERT_EQ(z.size(), dc.n_owned);
    const Vector zref = owned_part(serial_dofs(dc, sc), dc.n_owned, Rx);
    const double zscale = Rx.cwiseAbs().maxCoeff();
    for (Index i = 0; i < dc.n_owned; ++i)
        EXPECT_NEAR(z[i], zref[i], 1e-12 * zscale) << "coarse row " << i;
}

TEST(Distributed3Levels, BoomerAmgPcgSolutionIsTheSerialDirectOne) {
    const auto& b = block3d();
    const Communicator& comm = comm::world();
    const auto& d = b.dist.levels[1];
    const auto& s = b.serial.levels[1];
    // Serial: K on the displacements (the empty multiplier rows and columns made identity).
    SparseMatrix K = s.elastic.K;
    for (Index i = 0; i < K.rows(); ++i)
        if (!s.dofs.is_displacement(i)) K.coeffRef(i, i) = 1.0;
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(K);
    ASSERT_EQ(ldlt.info(), Eigen::Success);
    const Vector x_serial = ldlt.solve(s.elastic.f);
    const double scale = x_serial.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    // Distributed: BoomerAMG-PCG on K through IJ, three functions interleaved.
    const solvers::ParMatrix Kp(comm, d.K_rows());
    const std::vector<int> func = d.dof_function();
    for (const int c : func)
        ASSERT_TRUE(c >= 0 && c < 3);
    solvers::BoomerAMGParams amg;
    amg.num_functions = 3;
    Vector x = Vector::Zero(d.n_owned);
    const SolveResult r = solvers::boomeramg_pcg_par(Kp, d.owned_load(), x, 1e-13, 500, amg, func);
    EXPECT_TRUE(r.converged) << r.iterations << " iterations, relative residual "
                             << r.relative_residual;
    const Vector ref = owned_part(serial_dofs(d, s), d.n_owned, x_serial);
    for (Index i = 0; i < d.n_owned; ++i)
        EXPECT_NEAR(x[i], ref[i], 1e-8 * scale) << "row " << i;
}

TEST(Distributed3Levels, LoadingPathIsRefusedOnEveryProcess) {
    levels::ElasticProblem3 p = scene::load_scene3("block3d");
    p.loads[0].factors = {0.5, 1.0};
    p.loads[1].factors = {0.5, 1.0};
    EXPECT_THROW(levels::build_distributed_hierarchy3(p, 0, 0, comm::world()), InvalidInput);
}

#endif
