// SPDX-License-Identifier: MIT
// A row-distributed square matrix as hypre ParCSR, built and refreshed through IJ.
#include "solvers/hypre/par_matrix.hpp"

#include "comm/world.hpp"
#include "core/check.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_mv.h>
#include <mpi.h>

#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>

namespace mlc::solvers {

namespace {

void check(HYPRE_Int code, const char* call) {
    if (code == 0) return;
    char text[256] = {0};
    HYPRE_DescribeError(code, text);
    HYPRE_ClearAllErrors();
    throw std::runtime_error(std::string("ParMatrix: ") + call + " failed: " + text);
}

/// Runs check() on every process; if it threw on any, rethrows there and throws elsewhere, so
/// that bad input on one process fails all of them instead of leaving them in a collective.
template <class Check> void on_every_process(const Communicator& comm, Check&& check_input) {
    std::exception_ptr error;
    try {
        check_input();
    } catch (...) {
        error = std::current_exception();
    }
    if (comm.max(error ? 1 : 0) == 0) return;
    if (error) std::rethrow_exception(error);
    throw InvalidInput("ParMatrix: the rows of another process are invalid (see its message)");
}

} // namespace

struct ParMatrix::Impl {
    std::int64_t first = 0, n_global = 0;
    int n = 0;
    std::int64_t first_col = 0, n_global_cols = 0;
    int n_cols = 0;
    std::vector<HYPRE_BigInt> rows, col_ids, cols; // owned rows, owned columns, entries' columns
    std::vector<HYPRE_Int> ncols;
    HYPRE_IJMatrix ij_A = nullptr;
    HYPRE_ParCSRMatrix A = nullptr;
    HYPRE_IJVector ij_x = nullptr, ij_y = nullptr;
    HYPRE_ParVector x = nullptr, y = nullptr;

    ~Impl() {
        if (ij_A) HYPRE_IJMatrixDestroy(ij_A);
        if (ij_x) HYPRE_IJVectorDestroy(ij_x);
        if (ij_y) HYPRE_IJVectorDestroy(ij_y);
    }
};

namespace {
/// The size of a partition whose blocks [first, first + n) must follow each other in rank order.
std::int64_t partition_size(const Communicator& comm, std::int64_t first, std::int64_t n,
                            const char* what) {
    const auto firsts = comm.allgather(std::span<const std::int64_t>(&first, 1));
    const auto counts = comm.allgather(std::span<const std::int64_t>(&n, 1));
    std::int64_t next = 0;
    for (size_t q = 0; q < firsts.size(); ++q) {
        MLC_CHECK(counts[q] >= 0 && firsts[q] == next,
                  "ParMatrix: the " << what << " of process " << q << " start at " << firsts[q]
                                    << " instead of " << next
                                    << " (blocks must follow each other in rank order)");
        next += counts[q];
    }
    return next;
}
} // namespace

ParMatrix::ParMatrix(const Communicator& comm, const DistributedRows& r)
    : ParMatrix(comm, r, r.first_row, r.n_rows()) {}

ParMatrix::ParMatrix(const Communicator& comm, const DistributedRows& r, std::int64_t first_col,
                     int n_cols)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.first = r.first_row;
    m.n = r.n_rows();
    const std::int64_t n = m.n;
    m.n_global = partition_size(comm, m.first, n, "rows");
    m.first_col = first_col;
    m.n_cols = n_cols;
    m.n_global_cols = partition_size(comm, first_col, n_cols, "columns");
    MLC_CHECK(m.n_global_cols <= std::numeric_limits<HYPRE_BigInt>::max(),
              "ParMatrix: " << m.n_global_cols << " columns exceed hypre's index type");
    MLC_CHECK(m.n_global <= std::numeric_limits<HYPRE_BigInt>::max(),
              "ParMatrix: " << m.n_global << " rows exceed hypre's index type (32-bit build)");
    on_every_process(comm, [&] {
        MLC_CHECK(!r.row_ptr.empty() && r.row_ptr.front() == 0,
                  "ParMatrix: row_ptr must start with 0");
        for (int i = 0; i < m.n; ++i)
            MLC_CHECK(r.row_ptr[static_cast<size_t>(i) + 1] >= r.row_ptr[static_cast<size_t>(i)],
                      "ParMatrix: row_ptr decreases at row " << i);
        const auto nnz = static_cast<size_t>(r.row_ptr.back());
        MLC_CHECK(r.cols.size() == nnz && r.values.size() == nnz,
                  "ParMatrix: " << r.cols.size() << " columns and " << r.values.size()
                                << " values for " << nnz << " entries");
        for (size_t k = 0; k < nnz; ++k) {
            MLC_CHECK(r.cols[k] >= 0 && r.cols[k] < m.n_global_cols,
                      "ParMatrix: column " << r.cols[k] << " outside [0, " << m.n_global_cols
                                           << ")");
            MLC_CHECK(std::isfinite(r.values[k]),
                      "ParMatrix: entry " << k << " is " << r.values[k]);
        }
    });
    ensure_hypre_initialized();
    const MPI_Comm c = MPI_Comm_f2c(comm::mpi_handle(comm));
    const auto lo = static_cast<HYPRE_BigInt>(m.first);
    const auto hi = static_cast<HYPRE_BigInt>(m.first + n - 1);
    const auto clo = static_cast<HYPRE_BigInt>(m.first_col);
    const auto chi = static_cast<HYPRE_BigInt>(m.first_col + m.n_cols - 1);
    m.rows.resize(static_cast<size_t>(m.n));
    std::iota(m.rows.begin(), m.rows.end(), lo);
    m.col_ids.resize(static_cast<size_t>(m.n_cols));
    std::iota(m.col_ids.begin(), m.col_ids.end(), clo);
    m.cols.assign(r.cols.begin(), r.cols.end());
    m.ncols.resize(static_cast<size_t>(m.n));
    std::vector<HYPRE_Int> diag(static_cast<size_t>(m.n), 0), offd(static_cast<size_t>(m.n), 0);
    for (int i = 0; i < m.n; ++i) {
        const auto b = static_cast<size_t>(r.row_ptr[static_cast<size_t>(i)]);
        const auto e = static_cast<size_t>(r.row_ptr[static_cast<size_t>(i) + 1]);
        m.ncols[static_cast<size_t>(i)] = static_cast<HYPRE_Int>(e - b);
        for (size_t k = b; k < e; ++k)
            ++(r.cols[k] >= m.first_col && r.cols[k] < m.first_col + m.n_cols
                   ? diag
                   : offd)[static_cast<size_t>(i)];
    }
    check(HYPRE_IJMatrixCreate(c, lo, hi, clo, chi, &m.ij_A), "HYPRE_IJMatrixCreate");
    check(HYPRE_IJMatrixSetObjectType(m.ij_A, HYPRE_PARCSR), "HYPRE_IJMatrixSetObjectType");
    check(HYPRE_IJMatrixSetDiagOffdSizes(m.ij_A, diag.data(), offd.data()),
          "HYPRE_IJMatrixSetDiagOffdSizes");
    check(HYPRE_IJMatrixInitialize(m.ij_A), "HYPRE_IJMatrixInitialize");
    check(HYPRE_IJMatrixSetValues(m.ij_A, m.n, m.ncols.data(), m.rows.data(), m.cols.data(),
                                  r.values.data()),
          "HYPRE_IJMatrixSetValues");
    check(HYPRE_IJMatrixAssemble(m.ij_A), "HYPRE_IJMatrixAssemble");
    check(HYPRE_IJMatrixGetObject(m.ij_A, reinterpret_cast<void**>(&m.A)),
          "HYPRE_IJMatrixGetObject");
    // x in the column space, y in the row space.
    for (auto [ij, par, a, b] : {std::tuple{&m.ij_x, &m.x, clo, chi}, std::tuple{&m.ij_y, &m.y, lo, hi}}) {
        check(HYPRE_IJVectorCreate(c, a, b, ij), "HYPRE_IJVectorCreate");
        check(HYPRE_IJVectorSetObjectType(*ij, HYPRE_PARCSR), "HYPRE_IJVectorSetObjectType");
        check(HYPRE_IJVectorInitialize(*ij), "HYPRE_IJVectorInitialize");
        check(HYPRE_IJVectorAssemble(*ij), "HYPRE_IJVectorAssemble");
        check(HYPRE_IJVectorGetObject(*ij, reinterpret_cast<void**>(par)),
              "HYPRE_IJVectorGetObject");
    }
}

ParMatrix::~ParMatrix() = default;

std::int64_t ParMatrix::first_row() const {
    return impl_->first;
}
int ParMatrix::n_rows() const {
    return impl_->n;
}
std::int64_t ParMatrix::first_col() const {
    return impl_->first_col;
}
int ParMatrix::n_cols() const {
    return impl_->n_cols;
}
std::int64_t ParMatrix::n_global() const {
    return impl_->n_global;
}

namespace {

template <class Product>
void owned_product(const char* who, HYPRE_IJVector ij_x, HYPRE_IJVector ij_y,
                   const std::vector<HYPRE_BigInt>& in, const std::vector<HYPRE_BigInt>& out,
                   const Vector& x, Vector& y, Product&& product) {
    const auto n = static_cast<Index>(in.size());
    MLC_CHECK(x.size() == n, who << ": x has " << x.size() << " entries for " << n << " owned");
    y.resize(static_cast<Index>(out.size()));
    check(HYPRE_IJVectorSetValues(ij_x, static_cast<HYPRE_Int>(n), in.data(), x.data()),
          "HYPRE_IJVectorSetValues");
    product();
    check(HYPRE_IJVectorGetValues(ij_y, static_cast<HYPRE_Int>(out.size()), out.data(), y.data()),
          "HYPRE_IJVectorGetValues");
}

} // namespace

void ParMatrix::apply(const Vector& x, Vector& y) const {
    const Impl& m = *impl_;
    owned_product("ParMatrix::apply", m.ij_x, m.ij_y, m.col_ids, m.rows, x, y, [&] {
        check(HYPRE_ParCSRMatrixMatvec(1.0, m.A, m.x, 0.0, m.y), "HYPRE_ParCSRMatrixMatvec");
    });
}

void ParMatrix::apply_transpose(const Vector& x, Vector& y) const {
    const Impl& m = *impl_;
    owned_product("ParMatrix::apply_transpose", m.ij_y, m.ij_x, m.rows, m.col_ids, x, y, [&] {
        check(HYPRE_ParCSRMatrixMatvecT(1.0, m.A, m.y, 0.0, m.x), "HYPRE_ParCSRMatrixMatvecT");
    });
}

void ParMatrix::update_values(const std::vector<double>& values) {
    Impl& m = *impl_;
    MLC_CHECK(values.size() == m.cols.size(),
              "ParMatrix::update_values: " << values.size() << " values for " << m.cols.size()
                                           << " entries");
    // Rows owned here, pattern unchanged: hypre writes into its diagonal and off-diagonal blocks.
    check(HYPRE_IJMatrixSetValues(m.ij_A, m.n, m.ncols.data(), m.rows.data(), m.cols.data(),
                                  values.data()),
          "HYPRE_IJMatrixSetValues");
    check(HYPRE_IJMatrixAssemble(m.ij_A), "HYPRE_IJMatrixAssemble");
}

} // namespace mlc::solvers
