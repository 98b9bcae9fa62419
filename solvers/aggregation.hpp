// SPDX-License-Identifier: MIT
/// @file An algebraic level hierarchy for `Multigrid` on a mesh that has no coarser levels (a
/// fine mesh brought from Gmsh, `--levels 0`): vertices are grouped into aggregates, each
/// aggregate becomes one coarse "vertex" carrying the displacement components and contact
/// multipliers of its members, and the prolongation T from the coarse unknowns is
///
///     displacements:  T_u = (I - omega D^-1 K) P_tent,   P_tent = blockdiag(Q_a), B_a = Q_a R_a
///                     (smoothed aggregation, Vanek, Mandel & Brezina 1996): B_a is the near-null
///                     space of K (the rigid modes: translations and rotation) on the
///                     displacements of aggregate a, Q_a its orthonormal basis, so P_tent
///                     reproduces every rigid mode of every aggregate, and the coarse near-null
///                     space is R_a; D the vertex-block diagonal of K, omega = smoothing /
///                     rho(D^-1 K);
///     multipliers:    Q(i, J) = 1 / m_{a,c} when fine unknown i is multiplier component c
///                     (lambda_t or lambda_n) of a contact node of aggregate a, J that component of
///                     a, and m_{a,c} the number of contact nodes of a with component c.
///
/// Q carries multipliers the way the geometric hierarchy's Q does (transfer/transfer.hpp): a
/// multiplier is a nodal force, so a coarse force is shared among the fine contact nodes it stands
/// for and their sum equals it (sum_i Q(i, J) = 1 for every coarse multiplier J, the resultant
/// preserved component by component, like QRule::conservative); t goes to t and n to n. Aggregates
/// are grown from the contact nodes first, so that each one that holds contact nodes holds a few
/// consecutive ones along the contact boundary (a vertex and its graph neighbours). Q is not
/// smoothed, and neither is any multiplier row: only K (the elastic block, whose multiplier rows
/// and columns are empty) smooths T_u. The coarse operators are the Galerkin products R A T
/// (Multigrid with CoarseOperators::galerkin, R = T^T), so T's column scaling (the 1 / m) does not
/// change the preconditioner; it makes T^T map fine forces to their coarse resultant.
///
/// The coarse unknowns of an aggregate are contiguous, in the order rigid modes (3, fewer when
/// the aggregate cannot carry them), lambda_t, lambda_n (those its members have), so the coarse
/// vertex-block Gauss–Seidel sees the aggregate's displacements and multipliers in one block, as
/// the geometric levels see a contact vertex's. Coarsening stops when a level has at most
/// `coarse_size` unknowns (solved by sparse LU).
#pragma once

#include "core/types.hpp"
#include "solvers/mg.hpp"

#include <Eigen/Dense>

#include <ostream>
#include <vector>

namespace mlc::solvers {

/// What an unknown is: a displacement component, a contact multiplier component, or on a coarse
/// level the coefficient of one of an aggregate's rigid modes (a displacement too).
enum class UnknownKind : int { ux = 0, uy = 1, lambda_t = 2, lambda_n = 3, rigid_mode = 4 };

/// True for lambda_t and lambda_n.
inline bool is_multiplier(UnknownKind k) {
    return k == UnknownKind::lambda_t || k == UnknownKind::lambda_n;
}

/// Parameters of the aggregation hierarchy.
struct AggregationParams {
    /// Stop coarsening when a level has at most this many unknowns: its sparse LU then costs
    /// about what a smoothing sweep on the finest level does (a few thousand unknowns).
    int coarse_size = 3000;
    /// Most levels, the finest included (>= 2: there is always at least one coarse level).
    int max_levels = 10;
    /// omega * rho(D^-1 K) of the prolongation smoothing, in [0, 2); 0 keeps the tentative P.
    /// 4/3 minimizes the energy of the smoothed basis for the highest mode (Vanek et al. 1996).
    double smoothing = 4.0 / 3.0;
    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const AggregationParams& p);

/// One level to coarsen: the elastic operator and what each unknown is.
struct AggregationInput {
    /// K on all unknowns of the level (rows and columns of multipliers empty), compressed;
    /// its off-diagonal vertex couplings are the aggregation graph. Borrowed for the call.
    const SparseMatrix* K = nullptr;
    /// Owner of each unknown (any ids; each vertex's unknowns contiguous, as fem::DofMap numbers
    /// them): one smoother block and one aggregation node per run of equal owners.
    std::vector<int> vertex;
    /// Kind of each unknown; within a vertex its displacements (u_x, u_y, or rigid modes), then
    /// lambda_t, lambda_n (those it has).
    std::vector<UnknownKind> kind;
    /// Near-null space of K on the displacements (rows of multipliers zero), one column per mode:
    /// on a mesh the translations and the rotation (1, 0), (0, 1), (-y, x). Empty: the
    /// translations, from the kinds u_x and u_y.
    Eigen::MatrixXd near_null;
    /// Throws mlc::InvalidInput when the sizes disagree, K is not square or not compressed, or
    /// a multiplier row of K holds an entry.
    void validate() const;
};

/// One coarsening step: the aggregates, the tentative and smoothed prolongations, and the
/// coarse level as the input of the next step.
struct AggregationStep {
    /// Aggregate of each node (run of unknowns of one vertex in AggregationInput::vertex).
    std::vector<int> aggregate_of_node;
    int n_aggregates = 0;
    SparseMatrix P_tentative;       ///< fine unknowns x coarse unknowns, unsmoothed (P_tent and Q)
    SparseMatrix T;                 ///< smoothed on the displacements (the file comment's T)
    SparseMatrix K_coarse;          ///< T^T K T (multiplier rows and columns empty)
    std::vector<int> coarse_vertex; ///< aggregate of each coarse unknown
    std::vector<UnknownKind> coarse_kind; ///< kind of each coarse unknown
    /// The near-null space on the coarse unknowns: P_tentative near_null_coarse equals the
    /// input's near-null space (R_a of each aggregate's QR; zero rows on multipliers).
    Eigen::MatrixXd near_null_coarse;
    double omega = 0.0; ///< the smoothing factor used (smoothing / rho)
};

/// Aggregates the nodes of `in` and builds the step (see the file comment). Validates both.
AggregationStep aggregate_once(const AggregationInput& in, const AggregationParams& params);

/// The levels of a Multigrid with Galerkin coarse operators over `in` (coarsest first, the
/// finest last; every level's smoother blocks are its vertex runs, aggregates on the coarse
/// levels; each level above the coarsest owns its T and R = T^T through
/// MultigridLevelData::T_storage and R_storage). At least two levels; coarsens while a level
/// has more than params.coarse_size unknowns and the last step shrank it by at least 1.2x.
std::vector<MultigridLevelData> aggregation_levels(const AggregationInput& in,
                                                   const AggregationParams& params);

} // namespace mlc::solvers
