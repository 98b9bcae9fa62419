// SPDX-License-Identifier: MIT
// A row-distributed square matrix as hypre ParCSR, built and refreshed through IJ.
#include "solvers/hypre/par_matrix.hpp"

#include "comm/world.hpp"
#include "core/check.hpp"
#include "core/csr.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_mv.h>
#include <_hypre_parcsr_mv.h>
#include <mpi.h>

#include <algorithm>
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
    /// Where every entry given to the constructor lives in the ParCSR blocks: p >= 0 at the
    /// diagonal block's data[p], p < 0 at the off-diagonal block's data[-p - 1].
    std::vector<HYPRE_Int> position;
    mutable std::vector<double> send; ///< ghost_values' send buffer

    hypre_ParCSRMatrix* view = nullptr; ///< a matrix on RowBlocks' arrays (not IJ's)
    const RowBlocks* blocks = nullptr;  ///< its blocks
    mutable Vector ghost;               ///< apply's ghost values (view matrices)

    ~Impl() {
        if (view) {
            // The arrays are RowBlocks'; hypre frees its own objects only.
            for (hypre_CSRMatrix* b :
                 {hypre_ParCSRMatrixDiag(view), hypre_ParCSRMatrixOffd(view)}) {
                hypre_CSRMatrixI(b) = nullptr;
                hypre_CSRMatrixJ(b) = nullptr;
                hypre_CSRMatrixData(b) = nullptr;
            }
            hypre_ParCSRMatrixDestroy(view);
        }
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
    for (auto [ij, par, a, b] :
         {std::tuple{&m.ij_x, &m.x, clo, chi}, std::tuple{&m.ij_y, &m.y, lo, hi}}) {
        check(HYPRE_IJVectorCreate(c, a, b, ij), "HYPRE_IJVectorCreate");
        check(HYPRE_IJVectorSetObjectType(*ij, HYPRE_PARCSR), "HYPRE_IJVectorSetObjectType");
        check(HYPRE_IJVectorInitialize(*ij), "HYPRE_IJVectorInitialize");
        check(HYPRE_IJVectorAssemble(*ij), "HYPRE_IJVectorAssemble");
        check(HYPRE_IJVectorGetObject(*ij, reinterpret_cast<void**>(par)),
              "HYPRE_IJVectorGetObject");
    }
    // The positions of the entries in hypre's blocks (hypre keeps the diagonal entry first in
    // the rows of a square diagonal block, so the input order is not the stored one).
    auto* A = reinterpret_cast<hypre_ParCSRMatrix*>(m.A);
    hypre_CSRMatrix* D = hypre_ParCSRMatrixDiag(A);
    hypre_CSRMatrix* O = hypre_ParCSRMatrixOffd(A);
    const HYPRE_Int* DI = hypre_CSRMatrixI(D);
    const HYPRE_Int* DJ = hypre_CSRMatrixJ(D);
    const HYPRE_Int* OI = hypre_CSRMatrixI(O);
    const HYPRE_Int* OJ = hypre_CSRMatrixJ(O);
    const HYPRE_BigInt* cmap = hypre_ParCSRMatrixColMapOffd(A);
    m.position.resize(m.cols.size());
    for (int i = 0; i < m.n; ++i)
        for (int k = r.row_ptr[static_cast<size_t>(i)]; k < r.row_ptr[static_cast<size_t>(i) + 1];
             ++k) {
            const std::int64_t col = r.cols[static_cast<size_t>(k)];
            HYPRE_Int pos = 0;
            bool found = false;
            if (col >= m.first_col && col < m.first_col + m.n_cols) {
                for (HYPRE_Int j = DI[i]; j < DI[i + 1] && !found; ++j)
                    if (DJ[j] == col - m.first_col) pos = j, found = true;
            } else {
                for (HYPRE_Int j = OI[i]; j < OI[i + 1] && !found; ++j)
                    if (cmap[OJ[j]] == col) pos = -j - 1, found = true;
            }
            MLC_CHECK(found, "ParMatrix: hypre's blocks lack entry (" << m.first + i << ", " << col
                                                                      << ")");
            m.position[static_cast<size_t>(k)] = pos;
        }
    if (!hypre_ParCSRMatrixCommPkg(A)) hypre_MatvecCommPkgCreate(A);
}

ParMatrix::ParMatrix(const Communicator& comm, RowBlocks& b) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.first = b.first_row;
    m.n = static_cast<int>(b.diag.rows());
    m.first_col = b.first_col;
    m.n_cols = static_cast<int>(b.diag.cols());
    m.n_global = partition_size(comm, m.first, m.n, "rows");
    m.n_global_cols = partition_size(comm, m.first_col, m.n_cols, "columns");
    on_every_process(comm, [&] {
        MLC_CHECK(b.diag.isCompressed() && b.offd.isCompressed(),
                  "ParMatrix: the blocks must be compressed");
        MLC_CHECK(b.offd.rows() == m.n && b.offd.cols() == static_cast<Index>(b.col_map.size()),
                  "ParMatrix: the off-diagonal block is " << b.offd.rows() << " x " << b.offd.cols()
                                                          << " for " << m.n << " rows and "
                                                          << b.col_map.size() << " columns");
        for (size_t j = 0; j < b.col_map.size(); ++j) {
            MLC_CHECK(b.col_map[j] >= 0 && b.col_map[j] < m.n_global_cols &&
                          (b.col_map[j] < m.first_col || b.col_map[j] >= m.first_col + m.n_cols),
                      "ParMatrix: off-diagonal column " << b.col_map[j]
                                                        << " is owned here or out of range");
            MLC_CHECK(j == 0 || b.col_map[j] > b.col_map[j - 1],
                      "ParMatrix: the off-diagonal columns must increase");
        }
    });
    ensure_hypre_initialized();
    const MPI_Comm c = MPI_Comm_f2c(comm::mpi_handle(comm));
    HYPRE_BigInt rs[2] = {static_cast<HYPRE_BigInt>(m.first),
                          static_cast<HYPRE_BigInt>(m.first + m.n)};
    HYPRE_BigInt cs[2] = {static_cast<HYPRE_BigInt>(m.first_col),
                          static_cast<HYPRE_BigInt>(m.first_col + m.n_cols)};
    const auto ncols_offd = static_cast<HYPRE_Int>(b.col_map.size());
    hypre_ParCSRMatrix* A = hypre_ParCSRMatrixCreate(
        c, static_cast<HYPRE_BigInt>(m.n_global), static_cast<HYPRE_BigInt>(m.n_global_cols), rs,
        cs, ncols_offd, static_cast<HYPRE_Int>(b.diag.nonZeros()),
        static_cast<HYPRE_Int>(b.offd.nonZeros()));
    m.view = A;
    m.blocks = &b;
    for (auto [blk, src] : {std::pair{hypre_ParCSRMatrixDiag(A), &b.diag},
                            std::pair{hypre_ParCSRMatrixOffd(A), &b.offd}}) {
        hypre_CSRMatrixI(blk) = src->outerIndexPtr();
        hypre_CSRMatrixJ(blk) = src->innerIndexPtr();
        hypre_CSRMatrixData(blk) = src->valuePtr();
        hypre_CSRMatrixOwnsData(blk) = 0;
        hypre_CSRMatrixMemoryLocation(blk) = HYPRE_MEMORY_HOST;
    }
    HYPRE_BigInt* cmap = hypre_CTAlloc(HYPRE_BigInt, ncols_offd, HYPRE_MEMORY_HOST);
    for (HYPRE_Int j = 0; j < ncols_offd; ++j)
        cmap[j] = static_cast<HYPRE_BigInt>(b.col_map[static_cast<size_t>(j)]);
    hypre_ParCSRMatrixColMapOffd(A) = cmap;
    hypre_ParCSRMatrixSetNumNonzeros(A);
    hypre_MatvecCommPkgCreate(A);
    m.A = reinterpret_cast<HYPRE_ParCSRMatrix>(A);
    const auto lo = rs[0], hi = rs[1] - 1, clo = cs[0], chi = cs[1] - 1;
    for (auto [ij, par, a, e] :
         {std::tuple{&m.ij_x, &m.x, clo, chi}, std::tuple{&m.ij_y, &m.y, lo, hi}}) {
        check(HYPRE_IJVectorCreate(c, a, e, ij), "HYPRE_IJVectorCreate");
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
void* ParMatrix::hypre_handle() const {
    return impl_->A;
}

namespace {

/// Runs f with the local data of hypre's vectors x and y pointing at the given arrays (no copy),
/// restoring hypre's own arrays afterwards.
template <class F>
void on_arrays(HYPRE_ParVector x, const double* xp, HYPRE_ParVector y, double* yp, F&& f) {
    hypre_Vector* lx = hypre_ParVectorLocalVector(reinterpret_cast<hypre_ParVector*>(x));
    hypre_Vector* ly = hypre_ParVectorLocalVector(reinterpret_cast<hypre_ParVector*>(y));
    double* const ox = hypre_VectorData(lx);
    double* const oy = hypre_VectorData(ly);
    hypre_VectorData(lx) = const_cast<double*>(xp);
    hypre_VectorData(ly) = yp;
    try {
        f();
    } catch (...) {
        hypre_VectorData(lx) = ox;
        hypre_VectorData(ly) = oy;
        throw;
    }
    hypre_VectorData(lx) = ox;
    hypre_VectorData(ly) = oy;
}

} // namespace

namespace {
/// Starts hypre's halo exchange of x (owned columns) into ghost (the off-diagonal columns, in
/// the column map's order); the caller ends it with hypre_ParCSRCommHandleDestroy.
template <class Impl>
hypre_ParCSRCommHandle* start_halo(const Impl& m, const Vector& x, Vector& ghost) {
    auto* A = reinterpret_cast<hypre_ParCSRMatrix*>(m.A);
    hypre_ParCSRCommPkg* pkg = hypre_ParCSRMatrixCommPkg(A);
    const HYPRE_Int sends = hypre_ParCSRCommPkgNumSends(pkg);
    const HYPRE_Int begin = hypre_ParCSRCommPkgSendMapStart(pkg, 0);
    const HYPRE_Int end = hypre_ParCSRCommPkgSendMapStart(pkg, sends);
    m.send.resize(static_cast<size_t>(end - begin));
    for (HYPRE_Int i = begin; i < end; ++i)
        m.send[static_cast<size_t>(i - begin)] = x[hypre_ParCSRCommPkgSendMapElmt(pkg, i)];
    ghost.resize(hypre_CSRMatrixNumCols(hypre_ParCSRMatrixOffd(A)));
    return hypre_ParCSRCommHandleCreate(1, pkg, m.send.data(), ghost.data());
}
/// y += sign A_offd ghost on the owned rows (hypre's off-diagonal block).
template <class Impl>
void add_offdiagonal(const Impl& m, const Vector& ghost, Vector& y, double sign) {
    auto* A = reinterpret_cast<hypre_ParCSRMatrix*>(m.A);
    const hypre_CSRMatrix* O = hypre_ParCSRMatrixOffd(A);
    MLC_CHECK(ghost.size() == hypre_CSRMatrixNumCols(O) && y.size() == m.n,
              "ParMatrix: " << ghost.size() << " ghost values and " << y.size() << " rows");
    if (hypre_CSRMatrixNumNonzeros(O) == 0) return;
    const HYPRE_Int* I = hypre_CSRMatrixI(O);
    const HYPRE_Int* J = hypre_CSRMatrixJ(O);
    const double* a = hypre_CSRMatrixData(O);
    for (int i = 0; i < m.n; ++i) {
        double s = 0.0;
        for (HYPRE_Int k = I[i]; k < I[i + 1]; ++k)
            s += a[k] * ghost[J[k]];
        y[i] += sign * s;
    }
}
} // namespace

void ParMatrix::apply(const Vector& x, Vector& y, const LinearOperator& diag) const {
    const Impl& m = *impl_;
    MLC_CHECK(m.view, "ParMatrix::apply with a diagonal-block operator: only for a matrix on "
                      "RowBlocks");
    MLC_CHECK(x.size() == m.n_cols && diag.rows() == m.n && diag.cols() == m.n_cols,
              "ParMatrix::apply: x has "
                  << x.size() << " entries, the diagonal block's operator is " << diag.rows()
                  << " x " << diag.cols() << ", the matrix " << m.n << " x " << m.n_cols);
    hypre_ParCSRCommHandle* h = start_halo(m, x, m.ghost);
    diag.apply(x, y);
    hypre_ParCSRCommHandleDestroy(h);
    add_offdiagonal(m, m.ghost, y, 1.0);
}

void ParMatrix::apply(const Vector& x, Vector& y) const {
    const Impl& m = *impl_;
    MLC_CHECK(x.size() == m.n_cols, "ParMatrix::apply: x has " << x.size() << " entries for "
                                                               << m.n_cols << " owned columns");
    if (m.view) {
        // Our row kernel on the diagonal block while hypre's halo exchange is under way, then
        // the off-diagonal block on the ghost values (the result is hypre's product's).
        hypre_ParCSRCommHandle* h = start_halo(m, x, m.ghost);
        csr_multiply(m.blocks->diag, x, y);
        hypre_ParCSRCommHandleDestroy(h);
        add_offdiagonal(m, m.ghost, y, 1.0);
        return;
    }
    y.resize(m.n);
    on_arrays(m.x, x.data(), m.y, y.data(), [&] {
        check(HYPRE_ParCSRMatrixMatvec(1.0, m.A, m.x, 0.0, m.y), "HYPRE_ParCSRMatrixMatvec");
    });
}

void ParMatrix::apply_transpose(const Vector& x, Vector& y) const {
    const Impl& m = *impl_;
    MLC_CHECK(x.size() == m.n, "ParMatrix::apply_transpose: x has " << x.size() << " entries for "
                                                                    << m.n << " owned rows");
    y.resize(m.n_cols);
    on_arrays(m.y, x.data(), m.x, y.data(), [&] {
        check(HYPRE_ParCSRMatrixMatvecT(1.0, m.A, m.y, 0.0, m.x), "HYPRE_ParCSRMatrixMatvecT");
    });
}

void ParMatrix::ghost_values(const Vector& x, Vector& ghost) const {
    const Impl& m = *impl_;
    MLC_CHECK(x.size() == m.n_cols, "ParMatrix::ghost_values: x has " << x.size() << " entries for "
                                                                      << m.n_cols
                                                                      << " owned columns");
    hypre_ParCSRCommHandleDestroy(start_halo(m, x, ghost));
}

void ParMatrix::subtract_offdiagonal(const Vector& ghost, Vector& y) const {
    add_offdiagonal(*impl_, ghost, y, -1.0);
}

void ParMatrix::update_values(const std::vector<double>& values) {
    Impl& m = *impl_;
    MLC_CHECK(!m.view, "ParMatrix::update_values: this matrix is a view of RowBlocks; write the "
                       "new values into its blocks");
    MLC_CHECK(values.size() == m.cols.size(),
              "ParMatrix::update_values: " << values.size() << " values for " << m.cols.size()
                                           << " entries");
    // Pattern unchanged: the values go straight into hypre's diagonal and off-diagonal blocks
    // (no IJ pass, no communication: every entry is in an owned row).
    auto* A = reinterpret_cast<hypre_ParCSRMatrix*>(m.A);
    hypre_CSRMatrix* D = hypre_ParCSRMatrixDiag(A);
    hypre_CSRMatrix* O = hypre_ParCSRMatrixOffd(A);
    double* dd = hypre_CSRMatrixData(D);
    double* od = hypre_CSRMatrixData(O);
    std::fill(dd, dd + hypre_CSRMatrixNumNonzeros(D), 0.0);
    if (od) std::fill(od, od + hypre_CSRMatrixNumNonzeros(O), 0.0);
    for (size_t k = 0; k < values.size(); ++k) {
        const HYPRE_Int p = m.position[k];
        (p >= 0 ? dd[p] : od[-p - 1]) += values[k]; // repeated entries add, as IJ does
    }
}

} // namespace mlc::solvers
