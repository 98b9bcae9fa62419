// SPDX-License-Identifier: MIT
/// @file Internal to solvers/hypre/ (the only folder that includes hypre and MPI; named .h, not
/// .hpp, so that it is not installed with the public headers, which must not need hypre): a CSR
/// matrix copied into a hypre IJ / ParCSR matrix with two IJ vectors, and a BoomerAMG configured
/// from BoomerAMGParams. Shared by the BoomerAMG and MGR preconditioners. Single process
/// (MPI_COMM_SELF), rows 0..n-1.
#pragma once

#include "core/types.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <HYPRE.h>
#include <HYPRE_krylov.h>
#include <HYPRE_parcsr_ls.h>

#include <vector>

namespace mlc::solvers::hypre_detail {

/// The hypre objects of one matrix: IJ matrix and two IJ vectors (b, x) with their ParCSR views.
/// Calls ensure_hypre_initialized().
struct IJSystem {
    HYPRE_IJMatrix ij_A = nullptr;
    HYPRE_ParCSRMatrix A = nullptr;
    HYPRE_IJVector ij_b = nullptr, ij_x = nullptr;
    HYPRE_ParVector b = nullptr, x = nullptr;
    std::vector<HYPRE_BigInt> rows; ///< 0..n-1
    HYPRE_Int n = 0;

    explicit IJSystem(const SparseMatrix& M);
    ~IJSystem();
    IJSystem(const IJSystem&) = delete;
    IJSystem& operator=(const IJSystem&) = delete;
    void set_vector(HYPRE_IJVector v, const Vector& src) const;
    void get_vector(HYPRE_IJVector v, Vector& dst) const;
};

/// A BoomerAMG solver set up from `p` (one V-cycle, tolerance 0, when `as_preconditioner`).
/// `dof_func` (may be empty: unknown i has function i % num_functions) gives the function of each
/// of the `n` rows of the matrix it will be set up on; hypre takes a copy. The caller destroys
/// the solver (HYPRE_BoomerAMGDestroy).
HYPRE_Solver create_boomeramg(const BoomerAMGParams& p, bool as_preconditioner,
                              const std::vector<int>& dof_func, HYPRE_Int n);

} // namespace mlc::solvers::hypre_detail
