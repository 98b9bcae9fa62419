// SPDX-License-Identifier: MIT
/// @file Coarse/fine (CF) preconditioner of Alart & Lebon (1995, sect. 4.1, after Farhat & Sobh):
/// a block factorization of the fine matrix whose Schur complement is replaced by the coarse
/// operator A_H, with the fine block A_ff solved exactly (sparse LU), by inner CGS, or by any
/// other inner preconditioner (SORCF, solvers/sorcf.hpp).
///
/// With the fine unknowns split into coarse-vertex unknowns c and new-vertex unknowns f,
///
///     A = [[A_ff, A_fc], [A_cf, A_cc]],
///     C = [[A_ff, 0], [A_cf, S_H]] [[I, A_ff^{-1} A_fc], [0, I]],
///
/// where S_H stands for A_cc - A_cf A_ff^{-1} A_fc (the exact Schur complement, which makes C = A)
/// and is approximated by the coarse-mesh matrix A_H. C^{-1} r is (formulation.md sect. 5)
///
///     A_ff t_f = r_f;   A_H z_c = r_c - A_cf t_f;   A_ff z_f = r_f - A_fc z_c.
///
/// **Scaling between the levels.** The coarse set and the coarse unknowns are matched by
/// `coarse_dof`, with per-entry factors: the coarse right-hand side is
/// r_H[coarse_dof[k]] = restrict_scale[k] (r_c - A_cf t_f)[k] and the correction is
/// z_c[k] = prolong_scale[k] z_H[coarse_dof[k]], so the effective S_H is
/// diag(1/restrict_scale) A_H diag(1/prolong_scale) in the fine coarse-set numbering.
/// Displacements need no factor (both levels carry nodal displacements and nodal forces). A
/// multiplier is a nodal force: at a coarse contact vertex the fine node carries about half the
/// coarse force (Q: lambda_h = lambda_H / 2), and after condensation of the fine nodes the coarse
/// vertex's equilibrium row receives its own multiplier plus half of each neighbouring midpoint
/// multiplier, about 2 lambda_h = lambda_H; so S_H ~ A_H diag(1, 2) (columns), the rows (forces
/// in equilibrium rows, displacement units in multiplier rows) matching without a factor. Hence
/// prolong_scale = 1/2 (the factor of Q) and restrict_scale = 1 on multipliers. Numerically the
/// choice hardly matters on the square: with or without these factors (or with R = Q^T) CGS
/// takes the same number of iterations (6 at 8512 unknowns, 8 with mu = 0.3): the multipliers
/// are only a few dozen of the coarse unknowns.
///
/// **Inner solves.** In the nodal basis, A_cf A_ff^{-1} A_fc nearly cancels A_cc on smooth coarse
/// vectors (the Schur complement is O(h^2) smaller there), so a relative error delta in the
/// A_ff solve perturbs the coarse block by about delta h^-2 relative to the Schur complement:
/// an inexact A_ff spoils CF more and more as the mesh is refined. With the exact sparse LU of
/// A_ff (`InnerSolve::lu`, default) CGS needs 6-8 iterations at every level of the square; with
/// SSOR (SORCF, solvers/sorcf.hpp) the count grows about four-fold per refinement. The paper
/// solves A_ff by unpreconditioned CGS to a loose tolerance (`InnerSolve::cgs`), which also
/// makes C vary from one application to the next: outer CGS and GMRES (which assume a fixed C)
/// then diverge or stagnate; BiCGStab converges when the inner tolerance is tight enough
/// (1e-4 to 1e-6 at 8512 unknowns), at 20 to 30 times the cost of the exact inner solve.
#pragma once

#include "core/linear_operator.hpp"

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::solvers {

/// Coarse/fine splitting of the unknowns of a fine matrix, as plain data (no level types).
struct CoarseFineSplit {
    /// Fine unknowns living on coarse vertices (displacements and coarse contact multipliers).
    std::vector<int> coarse_set;
    /// The other fine unknowns. coarse_set and fine_set partition 0 .. n-1.
    std::vector<int> fine_set;
    /// For each coarse_set entry, the coarse unknown it corresponds to (distinct, in
    /// [0, n_coarse)).
    std::vector<int> coarse_dof;
    /// Number of coarse unknowns (size of the vectors given to the coarse solve).
    Index n_coarse = 0;
    /// Per coarse_set entry, factor applied to the residual passed down (empty: all 1).
    std::vector<double> restrict_scale;
    /// Per coarse_set entry, factor applied to the coarse correction passed up (empty: all 1).
    std::vector<double> prolong_scale;
    /// Optional first positions (within fine_set order) of the diagonal blocks of A_ff, e.g.
    /// one block per vertex with its multipliers, for block inner solvers (SORCF with block=1).
    /// Strictly increasing, starting at 0; empty when not given.
    std::vector<Index> fine_block_starts;

    /// Throws mlc::InvalidInput unless the sets partition 0 .. n-1, coarse_dof is distinct and
    /// in range, the scale vectors are empty or of coarse_set's size, and fine_block_starts is
    /// valid.
    void validate(Index n) const;
};

/// Exact solve of the coarse operator: z_coarse = A_H^{-1} r_coarse (both of size n_coarse;
/// z_coarse is resized and overwritten). In the multilevel Newton this calls the coarse level's
/// Newton-system solver with the converged coarse statuses, reusing its factorization.
using CoarseSolve = std::function<void(const Vector& r_coarse, Vector& z_coarse)>;

/// How A_ff is solved inside CF.
enum class InnerSolve {
    lu, ///< exact, sparse LU (Eigen SparseLU, partial pivoting): a fixed preconditioner
    cgs ///< unpreconditioned CGS to a relative tolerance (the 1995 paper): a varying one
};

/// "lu" or "cgs".
std::string_view to_string(InnerSolve s);
/// Streams `to_string(s)`.
std::ostream& operator<<(std::ostream& os, InnerSolve s);
/// Parses "lu" or "cgs"; anything else throws mlc::InvalidInput.
InnerSolve parse_inner_solve(std::string_view name);

/// How multiplier entries pass between the levels in CF and SORCF, with q the factor of Q at a
/// coarse contact vertex (1/2 for the paper's rule): "q" (z_c = q z_H, r_H = r_c; the default),
/// "none" (no factor), "qt" (z_c = q z_H, r_H = q r_c, as R = Q^T would), "qinv"
/// (z_c = q z_H, r_H = r_c / q).
enum class MultiplierScale { q, none, qt, qinv };

/// Parses "q", "none", "qt" or "qinv"; anything else throws mlc::InvalidInput.
MultiplierScale parse_multiplier_scale(std::string_view name);

/// Parameters of `make_coarse_fine`.
struct CoarseFineParams {
    /// Inner solver of A_ff. Default lu: exact, so C is a fixed operator and any Krylov method
    /// applies; A_ff holds the high frequencies and factors cheaply (no coarse-scale fill).
    InnerSolve inner = InnerSolve::lu;
    /// Relative tolerance of the inner CGS, in (0, 1). Default 1e-2: the paper's loose inner
    /// solve. (A_ff is better conditioned than A, but with the contact multipliers in it
    /// unpreconditioned CGS still needs about 90 iterations for 1e-2 and 180 for 1e-4 on the
    /// square at 8512 unknowns.)
    double inner_tol = 1e-2;
    /// Largest number of inner CGS iterations per solve, >= 1. Default 1000: several times what
    /// the tolerances above need; reaching it leaves the last (possibly poor: the CGS residual
    /// is erratic) iterate.
    int inner_max_iter = 1000;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const CoarseFineParams& p);

/// z ~ A^{-1} r by unpreconditioned CGS to a relative tolerance (the paper's inner solve of
/// A_ff). A varying operator: a nonlinear function of r.
///
/// `setup` stores a reference to A: A must outlive this object (or the next `setup`). `apply`
/// allocates CGS's work vectors on every call; not thread-safe (iteration counters).
class InnerCGS final : public Preconditioner {
public:
    /// `rel_tol` in (0, 1), `max_iter` >= 1.
    InnerCGS(double rel_tol, int max_iter);
    /// Stores a reference to A (square, compressed). Does not allocate.
    void setup(const SparseMatrix& A) override;
    /// z = CGS(A, r) from z0 = 0. Allocates.
    void apply(const Vector& r, Vector& z) const override;
    /// "cgs(tol=T)".
    std::string name() const override;
    /// Number of `apply` calls and of CGS iterations summed over them, since construction.
    long n_applies() const { return n_applies_; }
    long n_iterations() const { return n_iterations_; }

private:
    double rel_tol_;
    int max_iter_;
    const SparseMatrix* A_ = nullptr;
    mutable long n_applies_ = 0;
    mutable long n_iterations_ = 0;
};

/// The CF preconditioner (see the file comment).
///
/// Owns the inner solver of A_ff and the blocks A_ff, A_fc, A_cf extracted from A at `setup`
/// (A need not outlive it). The coarse solve is a borrowed callable: what it refers to must
/// outlive this object.
///
/// `apply` does not allocate itself (mutable work vectors sized at `setup`), but the inner
/// solver and the coarse solve may: SparseLU solves and inner CGS allocate, and so does the
/// coarse Newton-system solver. Not thread-safe.
class CoarseFinePreconditioner final : public Preconditioner {
public:
    /// @param split  the coarse/fine splitting (validated at `setup` against A's size)
    /// @param coarse_solve  z_H = A_H^{-1} r_H
    /// @param inner  solver of A_ff (set up on A_ff by `setup`), e.g. SparseLUPreconditioner
    /// @param label  name prefix: name() is label + "(" + inner->name() + ")"
    CoarseFinePreconditioner(CoarseFineSplit split, CoarseSolve coarse_solve,
                             std::unique_ptr<Preconditioner> inner, std::string label = "cf");

    /// Extracts A_ff, A_fc, A_cf and sets the inner solver up on A_ff. Allocates.
    void setup(const SparseMatrix& A) override;
    /// Same pattern, new values: refreshes the blocks and calls inner->update_values.
    void update_values(const SparseMatrix& A) override;
    /// z = C^{-1} r (three sub-solves, two block mat-vecs).
    void apply(const Vector& r, Vector& z) const override;
    /// label(inner name), e.g. "cf(lu)", "cf(cgs(tol=0.01))", "sorcf(gssor(omega=1.2,block=0))".
    std::string name() const override;

    /// The fine block A_ff (rows and columns in fine_set order), after `setup`.
    const SparseMatrix& A_ff() const { return A_ff_; }
    /// The inner solver.
    const Preconditioner& inner() const { return *inner_; }
    /// The splitting in effect.
    const CoarseFineSplit& split() const { return split_; }

private:
    void extract(const SparseMatrix& A);

    CoarseFineSplit split_;
    CoarseSolve coarse_solve_;
    std::unique_ptr<Preconditioner> inner_;
    std::string label_;
    Index n_ = 0;
    SparseMatrix A_ff_, A_fc_, A_cf_;
    mutable Vector rf_, tf_, wc_, rH_, zH_, zc_, zf_;
};

/// CF with the inner solve of `params` (sparse LU or inner CGS). See CoarseFinePreconditioner.
std::unique_ptr<CoarseFinePreconditioner> make_coarse_fine(CoarseFineSplit split,
                                                           CoarseSolve coarse_solve,
                                                           const CoarseFineParams& params = {});

} // namespace mlc::solvers
