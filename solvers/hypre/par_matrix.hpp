// SPDX-License-Identifier: MIT
/// @file A square matrix distributed by rows over the processes of a Communicator, held once as
/// hypre's ParCSR matrix (per process a diagonal and an off-diagonal block; hypre exchanges the
/// halo of a mat-vec), built and refreshed through hypre's IJ interface.
/// Compiled only with MLC_WITH_HYPRE (MLC_HAVE_HYPRE defined); without it the constructor throws
/// InvalidInput saying so. hypre and MPI stay in the .cpp.
#pragma once

#include "core/communicator.hpp"
#include "core/linear_operator.hpp"
#include "core/types.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace mlc::solvers {

/// This process's rows of a distributed matrix, in compressed sparse row form with global
/// column indices. The rows are the global rows [first_row, first_row + n_rows()), the same
/// contiguous block as the columns this process owns (the row and column partitions agree, as
/// for the operators of a distributed level: mesh::LocalLevel::first_row).
struct DistributedRows {
    std::int64_t first_row = 0;
    std::vector<int> row_ptr = {0}; ///< n_rows() + 1 offsets into cols and values
    std::vector<std::int64_t> cols; ///< global column of every entry
    std::vector<double> values;     ///< value of every entry
    int n_rows() const { return static_cast<int>(row_ptr.size()) - 1; }
};

/// This process's rows of a distributed matrix split as hypre's ParCSR stores them: the block of
/// the owned columns and the block of the others (the process's couplings across the cuts).
struct RowBlocks {
    std::int64_t first_row = 0; ///< global number of row 0
    std::int64_t first_col = 0; ///< global number of the first owned column
    SparseMatrix diag; ///< rows x owned columns (column j is global first_col + j), compressed
    SparseMatrix offd; ///< rows x col_map.size(), compressed (may have no entries)
    std::vector<std::int64_t> col_map; ///< global column of every offd column, increasing
};

/// The rows of `b` in compressed sparse row form with global columns: per row its owned columns
/// (diag, in their stored order) then the others (offd). For a ParMatrix built through IJ (what
/// hypre's own solvers want: IJ puts the diagonal entry first in its row).
DistributedRows distributed_rows(const RowBlocks& b);

/// A square ParCSR matrix whose rows are spread over the processes of `comm`.
///
/// Every process owns the rows (and the entries of vectors) [first_row, first_row + n_rows) of
/// its DistributedRows; the blocks of the processes follow each other in rank order and cover
/// [0, n_global). Vectors passed to apply() hold the owned entries only, so that, as a
/// LinearOperator, it is the square n_rows() x n_rows() operator each process sees: the Krylov
/// methods run on it with KrylovParams::comm set to the same communicator. Not thread-safe.
class ParMatrix final : public LinearOperator {
public:
    /// Collective. Copies `rows` into a hypre IJ matrix on the MPI communicator of `comm`
    /// (comm::mpi_handle; `comm` must outlive this object). Throws InvalidInput, on every
    /// process alike, when the blocks do not follow each other, when a column lies outside
    /// [0, n_global), when sizes disagree or a value is not finite (the last two are checked per
    /// process: a process with bad input throws, the others then fail in the next collective).
    ParMatrix(const Communicator& comm, const DistributedRows& rows);
    /// Collective. A rectangular matrix: the rows as above, the columns split into blocks
    /// [first_col, first_col + n_cols) that follow each other in rank order (e.g. a prolongation
    /// from a coarse level's unknowns, owned as that level's rows are). apply() maps vectors of
    /// n_cols() owned entries to n_rows(), apply_transpose() back.
    ParMatrix(const Communicator& comm, const DistributedRows& rows, std::int64_t first_col,
              int n_cols);
    /// Collective. A ParCSR matrix on `blocks`' arrays, not a copy: hypre reads blocks.diag and
    /// blocks.offd where they are, so values written into them later are the matrix's (what the
    /// smoother of a process's diagonal block and the Newton assembly write into: one copy of each
    /// operator). `blocks` must outlive this object and keep its patterns. The row and column
    /// partitions follow the blocks in rank order, as above. update_values() throws InvalidInput on
    /// such a matrix (write into the blocks).
    ParMatrix(const Communicator& comm, RowBlocks& blocks);
    ~ParMatrix() override;
    ParMatrix(const ParMatrix&) = delete;
    ParMatrix& operator=(const ParMatrix&) = delete;

    std::int64_t first_row() const;
    int n_rows() const;             ///< owned rows
    std::int64_t first_col() const; ///< first owned column (first_row() when square)
    int n_cols() const;             ///< owned columns (n_rows() when square)
    std::int64_t n_global() const;  ///< rows over all processes
    /// hypre's HYPRE_ParCSRMatrix of this matrix (as void*, so that hypre stays out of this
    /// header), for hypre's own solvers (solvers/hypre/ only). Owned by this object. A matrix
    /// built from RowBlocks keeps Eigen's column order in its diagonal block (the diagonal entry
    /// is not first in its row, as BoomerAMG's relaxation expects): give hypre's solvers a matrix
    /// built from DistributedRows (through IJ, which puts it first).
    void* hypre_handle() const;

    /// Owned rows (the local view's size).
    Index rows() const override { return n_rows(); }
    Index cols() const override { return n_cols(); }

    /// Collective: y = A x on the owned entries (x of size n_cols(); y resized to n_rows() and
    /// overwritten). The entries of x owned elsewhere come from their processes (hypre's halo
    /// exchange). Allocates nothing when y has the size already.
    void apply(const Vector& x, Vector& y) const override;
    /// Collective: y = A x as apply() does, with the diagonal block's product computed by
    /// `diag` (an operator of the same values, e.g. a structured kernel of a smoother that holds
    /// them) while the halo exchange is under way. Only for a matrix built on RowBlocks.
    void apply(const Vector& x, Vector& y, const LinearOperator& diag) const;
    /// Collective: y = A^T x on the owned entries (x of size n_rows(), y of n_cols(); hypre's
    /// transposed ParCSR mat-vec).
    void apply_transpose(const Vector& x, Vector& y) const override;

    /// Collective: the values of the columns this process's rows reference but does not own
    /// (hypre's off-diagonal columns, in its column-map order), fetched from their owners by
    /// hypre's halo exchange. With subtract_offdiagonal: y - A_offd x_ghost, the right-hand side
    /// of a process's diagonal block when the other processes' unknowns are held fixed (Jacobi
    /// across the cuts).
    void ghost_values(const Vector& x, Vector& ghost) const;
    /// y -= A_offd ghost on the owned rows (no communication; ghost from ghost_values).
    void subtract_offdiagonal(const Vector& ghost, Vector& y) const;

    /// Collective: new values for the same pattern (values.size() == the number of entries given
    /// to the constructor, in the same order), written in place into the ParCSR matrix, without
    /// building a new one: what a Newton step needs when only the values change.
    void update_values(const std::vector<double>& values);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace mlc::solvers
