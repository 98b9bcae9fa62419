// SPDX-License-Identifier: MIT
// Micro-benchmark of mlc::parallel against OpenMP on a CSR mat-vec, y = A x, with 14 nonzeros per
// row (columns near the diagonal, as for mesh numbered along a space-filling curve):
//   spmv    one region over the finest matrix (2M rows by default), repeated;
//   vcycle  a V-cycle-like sequence of 42 regions over 6 levels, 2M rows down to ~2k and back
//           (4 mat-vecs per level on the way down and up, 2 on the coarsest);
//   coarse  the same sequence restricted to the levels of 125k rows and fewer (26 short regions).
// Variants: omp (#pragma omp parallel for schedule(static)), pool (mlc::parallel::for_rows),
// serial (one thread). All give bit-identical y (checked).
//
// usage: bench_parallel [--rows N] [--reps R] [omp|pool|serial ...]
#include "core/parallel.hpp"
#include "core/timer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace {

struct Csr {
    std::size_t rows = 0;
    std::vector<std::uint32_t> ptr, col;
    std::vector<double> val;
};

/// rows x rows, 14 nonzeros per row at columns within +-2 sqrt(rows) of the diagonal.
Csr random_matrix(std::size_t rows, std::uint32_t seed) {
    constexpr int per_row = 14;
    Csr a;
    a.rows = rows;
    a.ptr.resize(rows + 1);
    a.col.resize(rows * per_row);
    a.val.resize(rows * per_row);
    std::mt19937 gen(seed);
    const long band = std::max(8L, long(2 * std::sqrt(double(rows))));
    std::uniform_int_distribution<long> offset(-band, band);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    for (std::size_t i = 0; i < rows; ++i) {
        a.ptr[i] = std::uint32_t(i * per_row);
        for (int k = 0; k < per_row; ++k) {
            const long j = std::clamp(long(i) + offset(gen), 0L, long(rows) - 1);
            a.col[i * per_row + k] = std::uint32_t(j);
            a.val[i * per_row + k] = value(gen);
        }
        std::sort(a.col.begin() + long(i * per_row), a.col.begin() + long((i + 1) * per_row));
    }
    a.ptr[rows] = std::uint32_t(rows * per_row);
    return a;
}

inline void multiply_rows(const Csr& a, const double* x, double* y, std::size_t begin,
                          std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
        double s = 0.0;
        for (std::uint32_t k = a.ptr[i]; k < a.ptr[i + 1]; ++k)
            s += a.val[k] * x[a.col[k]];
        y[i] = s;
    }
}

enum class Variant { omp, pool, serial };

const char* name(Variant v) {
    switch (v) {
    case Variant::omp:
        return "omp";
    case Variant::pool:
        return "pool";
    default:
        return "serial";
    }
}

void multiply(Variant v, const Csr& a, const double* x, double* y) {
    switch (v) {
    case Variant::omp: {
        const long n = long(a.rows);
#pragma omp parallel for schedule(static)
        for (long i = 0; i < n; ++i)
            multiply_rows(a, x, y, std::size_t(i), std::size_t(i) + 1);
        break;
    }
    case Variant::pool:
        mlc::parallel::for_rows(a.rows, 1024, [&](std::size_t begin, std::size_t end) {
            multiply_rows(a, x, y, begin, end);
        });
        break;
    case Variant::serial:
        multiply_rows(a, x, y, 0, a.rows);
        break;
    }
}

struct Level {
    Csr a;
    std::vector<double> x, y;
};

/// The level sequence of a V-cycle from `first` to the coarsest and back.
std::vector<int> vcycle(int first, int levels) {
    std::vector<int> seq;
    for (int l = first; l + 1 < levels; ++l)
        seq.insert(seq.end(), 4, l);
    seq.insert(seq.end(), 2, levels - 1);
    for (int l = levels - 2; l >= first; --l)
        seq.insert(seq.end(), 4, l);
    return seq;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

} // namespace

int main(int argc, char** argv) {
    std::size_t rows = 2000000;
    int reps = 10;
    std::vector<Variant> variants;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--rows" && i + 1 < argc)
            rows = std::strtoul(argv[++i], nullptr, 10);
        else if (a == "--reps" && i + 1 < argc)
            reps = std::max(1, std::atoi(argv[++i]));
        else if (a == "omp")
            variants.push_back(Variant::omp);
        else if (a == "pool")
            variants.push_back(Variant::pool);
        else if (a == "serial")
            variants.push_back(Variant::serial);
        else {
            std::cerr << "usage: bench_parallel [--rows N] [--reps R] [omp|pool|serial ...]\n";
            return 1;
        }
    }
    if (variants.empty()) variants = {Variant::omp, Variant::pool, Variant::serial};

    const int n_levels = 6;
    std::vector<Level> levels(n_levels);
    for (int l = 0; l < n_levels; ++l) {
        const std::size_t m = std::max<std::size_t>(16, rows >> (2 * l));
        levels[l].a = random_matrix(m, 1234u + std::uint32_t(l));
        levels[l].x.resize(m);
        std::mt19937 gen(99u + std::uint32_t(l));
        std::uniform_real_distribution<double> value(-1.0, 1.0);
        for (double& xi : levels[l].x)
            xi = value(gen);
        levels[l].y.assign(m, 0.0);
    }
    const std::vector<int> full = vcycle(0, n_levels), coarse = vcycle(2, n_levels);

    int omp_threads = 1;
#ifdef _OPENMP
    omp_threads = omp_get_max_threads();
#endif
    std::cout << "rows per level:";
    for (const Level& l : levels)
        std::cout << " " << l.a.rows;
    std::cout << "\nregions: vcycle " << full.size() << ", coarse " << coarse.size()
              << "; omp threads " << omp_threads << ", pool threads "
              << mlc::parallel::num_threads() << "; " << reps << " repetitions\n";
    std::cout << std::left << std::setw(8) << "variant" << std::right << std::setw(14) << "spmv ms"
              << std::setw(14) << "vcycle ms" << std::setw(14) << "coarse ms"
              << "   (mean per repetition; median in brackets)\n";

    std::vector<double> reference;
    bool identical = true;
    for (Variant v : variants) {
        const auto run_seq = [&](const std::vector<int>& seq) {
            for (int l : seq)
                multiply(v, levels[l].a, levels[l].x.data(), levels[l].y.data());
        };
        const auto time_reps = [&](int n, auto&& body) {
            std::vector<double> t;
            for (int r = 0; r < n; ++r) {
                const double start = mlc::wall_seconds();
                body();
                t.push_back(1e3 * (mlc::wall_seconds() - start));
            }
            double mean = 0.0;
            for (double s : t)
                mean += s;
            return std::pair(mean / double(n), median(t));
        };
        run_seq(full); // warm-up: threads started, pages touched
        Level& fine = levels[0];
        const auto spmv =
            time_reps(reps, [&] { multiply(v, fine.a, fine.x.data(), fine.y.data()); });
        const auto vc = time_reps(reps, [&] { run_seq(full); });
        const auto co = time_reps(10 * reps, [&] { run_seq(coarse); });
        std::cout << std::left << std::setw(8) << name(v) << std::right << std::fixed
                  << std::setprecision(2);
        for (const auto& [mean, med] : {spmv, vc, co})
            std::cout << std::setw(8) << mean << " [" << std::setw(6) << med << "]";
        std::cout << std::defaultfloat << std::endl;

        std::vector<double> result;
        for (const Level& l : levels)
            result.insert(result.end(), l.y.begin(), l.y.end());
        if (reference.empty())
            reference = result;
        else if (std::memcmp(result.data(), reference.data(), result.size() * sizeof(double)))
            identical = false;
        // Let the OpenMP workers stop spinning before the next variant.
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
    std::cout << "results " << (identical ? "bit-identical" : "DIFFER") << " across variants\n";
    return identical ? 0 : 2;
}
