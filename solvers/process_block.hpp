// SPDX-License-Identifier: MIT
/// @file Block Jacobi across processes: a preconditioner of each process's diagonal block of a
/// row-distributed matrix (ParMatrix), so that a process smooths with its own rows and columns
/// and treats the couplings to other processes' unknowns as a Jacobi method does
/// (docs/parallel.md#parallel-how: block Gauss-Seidel inside each process and Jacobi across process
/// cuts, as the threads of core/parallel.hpp do with their chunks). No hypre: the block is cut from
/// DistributedRows.
#pragma once

#include "core/linear_operator.hpp"
#include "solvers/hypre/par_matrix.hpp"

#include <memory>
#include <string>

namespace mlc::solvers {

/// The block of `rows` in this process's own columns, [first_row, first_row + n_rows()), with
/// local indices (global - first_row): n_rows() x n_rows(). Entries in other processes' columns
/// are left out. Throws InvalidInput for a column index outside the matrix (negative).
SparseMatrix diagonal_block(const DistributedRows& rows);

/// z = M_p^{-1} r on the owned entries, M_p a preconditioner (any: ILU, SSOR, ...) set up on the
/// process's diagonal block. Communication-free; with one process it is the local preconditioner
/// of the whole matrix.
class ProcessBlockPreconditioner final : public Preconditioner {
public:
    /// `local` is owned; it is set up by setup_rows() or setup().
    explicit ProcessBlockPreconditioner(std::unique_ptr<Preconditioner> local);
    /// Cuts the diagonal block of `rows` (kept here: the local preconditioner may hold a
    /// reference to it) and sets up the local preconditioner on it.
    void setup_rows(const DistributedRows& rows);
    /// Sets up on a diagonal block given directly (copied).
    void setup(const SparseMatrix& block) override;
    /// z = M_p^{-1} r (no communication).
    void apply(const Vector& r, Vector& z) const override;
    std::string name() const override;

private:
    std::unique_ptr<Preconditioner> local_;
    SparseMatrix block_;
};

} // namespace mlc::solvers
