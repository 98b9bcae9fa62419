// SPDX-License-Identifier: MIT
// Micro-benchmark of the kernels of the default Newton-system solve (BiCGStab + mg V(0,2)) on the
// square at level L, on the finest level's first Newton system of a real run (one load step):
//   vcycle            one Multigrid::apply (the run's multigrid);
//   matvec            one product with the finest Jacobian (MatrixOperator, MatVec::unrolled);
//   sweep             one backward sweep of a smoother built as the multigrid's finest one
//                     (vertex blocks, unrolled kernel, smoothers::kHybridParts parts);
//   sweep single      the same sweep with single-precision values and block inverses
//                     (mg:precision=single);
//   smoother refresh  BlockSOR::update_values on the same matrix (what each Newton system after
//                     the first costs the finest level's smoother: checks and block inverses);
//   smoother refresh single  the same with single-precision data (values and inverses rounded);
//   smoother setup    BlockSOR::setup on the same matrix (a level's first Newton system);
//   vectors           BiCGStab's vector statements of one iteration as solvers/krylov.cpp has
//                     them (Eigen whole-vector statements, one thread);
//   vectors threaded  the same statements threaded and fused into four passes with chunked
//                     reductions (a candidate, not used: its sums differ in the last bits).
//   two sweeps        two backward sweeps of that smoother (what the default cycle does);
//   two sweeps lattice, sweep lattice, lattice refresh, lattice setup: the same for
//                     smoothers::LatticeGS (mg:smoother=lattice) on the finest level's lattice;
//                     only with --numbering lattice (the level's Level::lattice).
//   restriction csr, prolongation csr, restriction lattice, prolongation lattice: R r and T e
//                     between level L-1 and level L (csr_multiply against solvers::LatticeTransfer,
//                     the same values bit for bit); only with --numbering lattice and L >= 5.
// The variants alternate in one process, so that a slow phase of the machine hits them alike:
// compare them with each other, not with another run's. Output: one JSON object on stdout
// (times in ms: median and minimum over --reps).
//
// usage: bench_kernels [--levels L] [--reps R] [--numbering hilbert|lattice] [--pc SPEC]
//        (defaults 6, 15, hilbert and the run's mg:pre=0,post=2; --pc sets the run's
//        preconditioner, whose cycle the vcycle row times)
#include "core/first_touch.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "levels/hierarchy.hpp"
#include "levels/level.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"
#include "smoothers/block_sor.hpp"
#include "smoothers/lattice_gs.hpp"
#include "solvers/lattice_transfer.hpp"
#include "solvers/mg.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

using namespace mlc;

namespace {

struct Stat {
    std::vector<double> ms;
    double median() const {
        std::vector<double> v = ms;
        std::sort(v.begin(), v.end());
        return v.empty() ? 0.0 : v[v.size() / 2];
    }
    double min() const { return ms.empty() ? 0.0 : *std::min_element(ms.begin(), ms.end()); }
};

double time_ms(const std::function<void()>& f) {
    const double t0 = wall_seconds();
    f();
    return 1e3 * (wall_seconds() - t0);
}

constexpr size_t kChunk = size_t{1} << 14; // rows per chunk of the threaded vector statements

template <size_t K, class Fn> std::array<double, K> chunk_sums(Index n, Fn&& fn) {
    const parallel::RowChunks rc = parallel::row_chunks(static_cast<size_t>(n), kChunk);
    std::vector<std::array<double, K>> part(rc.count);
    parallel::for_chunks(rc.count, [&](size_t c) {
        part[c] = fn(static_cast<Index>(rc.begin(c)), static_cast<Index>(rc.end(c) - rc.begin(c)));
    });
    std::array<double, K> s = part[0];
    for (size_t c = 1; c < rc.count; ++c)
        for (size_t k = 0; k < K; ++k)
            s[k] += part[c][k];
    return s;
}

class Probe final : public levels::ForwardingSystemSolver {
public:
    Probe(std::unique_ptr<levels::NewtonSystemSolver> inner, const levels::Level& level, int reps,
          std::map<std::string, Stat>& out)
        : levels::ForwardingSystemSolver(std::move(inner)), reps_(reps), out_(out),
          lattice_(level.lattice) {
        std::vector<int> owner(static_cast<size_t>(level.n_unknowns()));
        for (Index i = 0; i < level.n_unknowns(); ++i)
            owner[static_cast<size_t>(i)] = level.dofs.vertex_of(i);
        block_starts_ = solvers::vertex_block_starts(owner);
    }
    using levels::NewtonSystemSolver::solve;
    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        SolveResult r = inner().solve(M, b, dx, forcing);
        if (done_) return r;
        done_ = true;
        const solvers::Multigrid* mg = inner().multigrid();
        if (mg == nullptr || mg->finest_operator() == nullptr) return r;
        const MatrixOperator op(*mg->finest_operator(), MatVec::unrolled);
        const Index n = b.size();
        smoothers::BlockSOR sor({.omega = 1.0,
                                 .block_size = 2,
                                 .block_starts = block_starts_,
                                 .parts = 0,
                                 .kernel = smoothers::Kernel::unrolled});
        sor.setup(*mg->finest_operator());
        smoothers::BlockSOR sor32({.omega = 1.0,
                                   .block_size = 2,
                                   .block_starts = block_starts_,
                                   .parts = 0,
                                   .kernel = smoothers::Kernel::unrolled,
                                   .precision = Precision::float32});
        sor32.setup(*mg->finest_operator());
        Vector z = parallel::zeros(n), y = parallel::zeros(n), xs = parallel::zeros(n);
        std::unique_ptr<smoothers::LatticeGS> lat;
        if (lattice_) {
            lat = std::make_unique<smoothers::LatticeGS>(block_starts_, *lattice_);
            lat->setup(*mg->finest_operator());
            std::cerr << "bench_kernels: lattice smoother " << lat->name() << ", "
                      << lat->deep_points() << " deep and " << lat->semi_deep_points()
                      << " semi-deep points of " << n / 2 << " vertices\n";
        }
        Vector xl = parallel::zeros(n);
        for (int k = 0; k < reps_; ++k) {
            out_["vcycle"].ms.push_back(time_ms([&] { mg->apply(b, z); }));
            out_["matvec"].ms.push_back(time_ms([&] { op.apply(z, y); }));
            out_["sweep"].ms.push_back(
                time_ms([&] { sor.sweep(b, xs, smoothers::Sweep::backward); }));
            out_["sweep single"].ms.push_back(
                time_ms([&] { sor32.sweep(b, xs, smoothers::Sweep::backward); }));
            out_["smoother refresh"].ms.push_back(
                time_ms([&] { sor.update_values(*mg->finest_operator()); }));
            out_["smoother refresh single"].ms.push_back(
                time_ms([&] { sor32.update_values(*mg->finest_operator()); }));
            out_["smoother setup"].ms.push_back(
                time_ms([&] { sor.setup(*mg->finest_operator()); }));
            out_["two sweeps"].ms.push_back(time_ms([&] {
                sor.sweep(b, xs, smoothers::Sweep::backward);
                sor.sweep(b, xs, smoothers::Sweep::backward);
            }));
            if (lat) {
                out_["two sweeps lattice"].ms.push_back(
                    time_ms([&] { lat->smooth(b, xl, smoothers::Sweep::backward, 2); }));
                out_["sweep lattice"].ms.push_back(
                    time_ms([&] { lat->smooth(b, xl, smoothers::Sweep::backward, 1); }));
                out_["lattice refresh"].ms.push_back(
                    time_ms([&] { lat->update_values(*mg->finest_operator()); }));
                out_["lattice setup"].ms.push_back(
                    time_ms([&] { lat->setup(*mg->finest_operator()); }));
            }
        }
        // One BiCGStab iteration's vector statements, as krylov.cpp has them and threaded.
        Vector r0 = b, rh = b, p = z, v = y, ph = z, sh = z, t = y, x = z;
        const double a = 0.3, w = 0.7, beta = 0.9;
        for (int k = 0; k < reps_; ++k) {
            double sink = 0.0; // used below, so the reductions are kept
            out_["vectors"].ms.push_back(time_ms([&] {
                sink += rh.dot(r0);
                p = r0 + beta * (p - w * v);
                sink += rh.dot(v);
                r0 -= a * v;
                sink += r0.norm();
                sink += t.squaredNorm() + t.dot(r0);
                x += a * ph + w * sh;
                r0 -= w * t;
                sink += r0.norm();
            }));
            out_["vectors threaded"].ms.push_back(time_ms([&] {
                parallel::for_rows(size_t(n), kChunk, [&](size_t i, size_t e) {
                    const Index l = Index(e - i);
                    p.segment(Index(i), l) =
                        r0.segment(Index(i), l) +
                        beta * (p.segment(Index(i), l) - w * v.segment(Index(i), l));
                });
                sink += chunk_sums<1>(n, [&](Index i, Index l) {
                    return std::array<double, 1>{rh.segment(i, l).dot(v.segment(i, l))};
                })[0];
                sink += chunk_sums<1>(n, [&](Index i, Index l) {
                    auto s = r0.segment(i, l);
                    s -= a * v.segment(i, l);
                    return std::array<double, 1>{s.squaredNorm()};
                })[0];
                const auto tt = chunk_sums<2>(n, [&](Index i, Index l) {
                    const auto ts = t.segment(i, l);
                    return std::array<double, 2>{ts.squaredNorm(), ts.dot(r0.segment(i, l))};
                });
                const auto rr = chunk_sums<2>(n, [&](Index i, Index l) {
                    x.segment(i, l) += a * ph.segment(i, l) + w * sh.segment(i, l);
                    auto s = r0.segment(i, l);
                    s -= w * t.segment(i, l);
                    return std::array<double, 2>{s.squaredNorm(), rh.segment(i, l).dot(s)};
                });
                sink += tt[0] + tt[1] + rr[0] + rr[1];
            }));
            if (!std::isfinite(sink)) std::cerr << "bench_kernels: non-finite vector sums\n";
            r0 = b; // keep the values bounded
            x = z;
        }
        return r;
    }

private:
    int reps_;
    std::map<std::string, Stat>& out_;
    std::vector<Index> block_starts_;
    std::shared_ptr<const smoothers::LatticeRows> lattice_; // with --numbering lattice
    bool done_ = false;
};

} // namespace

int main(int argc, char** argv) {
    int levels = 6, reps = 15;
    bool lattice_numbering = false;
    std::string pc = "mg:pre=0,post=2";
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--levels"))
            levels = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--reps"))
            reps = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--pc"))
            pc = argv[i + 1];
        else if (!std::strcmp(argv[i], "--numbering"))
            lattice_numbering = !std::strcmp(argv[i + 1], "lattice");
        else {
            std::cerr << "usage: bench_kernels [--levels L] [--reps R] [--numbering "
                         "hilbert|lattice] [--pc SPEC]\n";
            return 2;
        }
    }
    if (levels < 1 || reps < 1) {
        std::cerr << "bench_kernels: --levels and --reps must be >= 1\n";
        return 2;
    }
    levels::Problem pr = scene::load_scene("square");
    pr.levels = levels;
    pr.load_steps = 1;
    if (lattice_numbering) pr.numbering = levels::Problem::Numbering::lattice;
    levels::SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::bicgstab,
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = 1e-8};
    std::map<std::string, Stat> out;
    Index n = 0;
    levels::SolverWrapper wrap(
        [&](int level, const levels::Level& L, std::unique_ptr<levels::NewtonSystemSolver> s)
            -> std::unique_ptr<levels::NewtonSystemSolver> {
            if (level != levels) return s;
            return std::make_unique<Probe>(std::move(s), L, reps, out);
        });
    const levels::RunResult r = levels::solve(pr, so, &wrap);
    n = r.finest().n_unknowns();
    if (lattice_numbering && levels >= 5) {
        const levels::Hierarchy& h = r.hierarchy;
        const auto& tr = h.transfers[static_cast<size_t>(levels - 1)];
        const auto& fine_rows = *h.levels[static_cast<size_t>(levels)].lattice;
        const auto& coarse_rows = *h.levels[static_cast<size_t>(levels - 1)].lattice;
        for (int k = 0; k < 3; ++k)
            out["lattice transfer setup"].ms.push_back(time_ms(
                [&] { const solvers::LatticeTransfer t(tr.T, tr.R, fine_rows, coarse_rows); }));
        const solvers::LatticeTransfer lt(tr.T, tr.R, fine_rows, coarse_rows);
        std::cerr << "bench_kernels: lattice transfer, " << lt.structured_rows_T() << " of "
                  << tr.T.rows() << " rows of T and " << lt.structured_rows_R() << " of "
                  << tr.R.rows() << " rows of R structured\n";
        Vector f = parallel::zeros(tr.T.rows()), c = parallel::zeros(tr.T.cols());
        for (Index i = 0; i < f.size(); ++i)
            f[i] = std::sin(0.001 * static_cast<double>(i));
        for (int k = 0; k < reps; ++k) {
            out["restriction csr"].ms.push_back(time_ms([&] { csr_multiply(tr.R, f, c); }));
            out["prolongation csr"].ms.push_back(time_ms([&] { csr_multiply(tr.T, c, f); }));
            out["restriction lattice"].ms.push_back(time_ms([&] { lt.restrict_residual(f, c); }));
            out["prolongation lattice"].ms.push_back(time_ms([&] { lt.prolongate(c, f, false); }));
        }
    }
    std::cout << "{\"levels\": " << levels << ", \"unknowns\": " << n
              << ", \"threads\": " << parallel::num_threads() << ", \"reps\": " << reps;
    for (const auto& [k, s] : out)
        std::cout << ",\n \"" << k << "\": {\"median_ms\": " << s.median()
                  << ", \"min_ms\": " << s.min() << "}";
    std::cout << "}\n";
    return out.empty() ? 1 : 0;
}
