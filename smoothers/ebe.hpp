// SPDX-License-Identifier: MIT
/// @file Element-by-element (EBE) preconditioner of Hughes & Winget extended to frictional contact
/// elements (Alart, Barboteu & Lebon 1997): the two-pass product form C1 and the global
/// factorization-like variants C4 and C5.
///
/// Notation (1997 paper, eqs. 14-31; formulation.md sect. 5). A = sum_e A_e over elastic
/// elements (ee) and contact elements (ce). A set U of *unit-scaled* unknowns is where the
/// diagonal of A may vanish and W~ = 1 (the paper's "i in ce", see UnitScaling for the two
/// readings: every unknown of a contact element, or only the multipliers):
///
///   W~_ii   = 1 on U, A_ii elsewhere,
///   W~_e,ii = 0 on U, (A_e)_ii elsewhere (so sum_e W~_e = W~ J),
///   J_ii    = 0 on U, 1 elsewhere,
///   A       = W~^{1/2} (J + sum_e W~^{-1/2} (A_e - W~_e) W~^{-1/2}) W~^{1/2}   (exact, eq. 28).
///
/// Element factors, each on the element's unknowns in increasing global order (eq. 30):
///   A^_e = J_e + W~^{-1/2} (A_e - W~_e) W~^{-1/2} = L_e U_e,
/// L_e unit lower and U_e upper triangular (LU without pivoting), with J_e = I_e for an elastic
/// element (Winget regularization: unit diagonal off U) and J_e = J restricted to the element
/// for a contact element, which is therefore factored unregularized on U: A^_ce = A_ce when
/// every unknown of the element is in U, as in the paper.
///
/// **Which unknowns are unit-scaled.** formulation.md reads "W = 1 on every unknown of a contact
/// element" (UnitScaling::contact_unknowns). Then the contactor displacements carry W~ = 1 next
/// to elastic factors whose diagonal there is 1 + (K_e)_ii (about E), and the product of those
/// factors is far from A: on the square, C1 diverges and C5 needs twice the iterations. The
/// papers' contact element is drawn as the contactor node plus a "multiplier node"; reading
/// "i in ce" as the multiplier node's unknowns (UnitScaling::multipliers, the default: the
/// unknowns of no elastic element) keeps W~ = diag(A) > 0 on every displacement, so the
/// contactor displacements are regularized like any other, and only the multiplier block of a
/// contact element is left unregularized. Its factors then have no zero pivot in gap, stick or
/// flat slip.
///
/// **Reading of the contact factorizations (eqs. 33-39)**, for unit-scaled contact elements (all
/// of their unknowns in U, as with UnitScaling::contact_unknowns). A_ce = [[r M, M], [M, (M -
/// I)/r]] is singular in gap (M = 0) and in slip (M = (n - eps mu t) n^T is rank one): the paper's
/// factors for these statuses (eq. 33: U = diag(0, -I/r); eq. 38: L_M = I, U_M = M with M_11 = 0)
/// have a zero pivot in U, which would make C1 singular. We factor the dense element matrix by LU
/// without pivoting in the increasing global order (u_x, u_y, lambda_t, lambda_n) and replace a
/// zero pivot (|u_kk| <= zero_pivot_tol max|A^_e|) by 1, the value of W~ and of the identity of
/// the regularization on U; the factors then satisfy L_e U_e = A^_e + (diagonal
/// on the replaced pivots only). This reproduces eq. 34 (stick: L = [[I, 0], [I/r, I]],
/// U = [[r I, I], [0, -I/r]]) exactly, eq. 33 (gap) with its zero pivots set to 1, and in slip
/// on a flat obstacle (M_11 = M_21 = 0, the paper's first special case, eq. 38) factors of
/// A_ce + e_t e_t^T, where eq. 38 with the pivot set to 1 would also perturb the (lambda_t, u_t)
/// entry. The same rule covers obliquely oriented obstacles (rotated M) and node-on-node and
/// node-on-facet elements (eq. 40-41), where the paper gives no formula.
///
/// **Variants.** With the elements ordered by colour (same-coloured elements share no unknown,
/// so their factors commute):
/// - C1 = W~^{1/2} (prod_e L_e) (prod_e' U_e') W~^{1/2} (L in element order, U in reverse
///   order; eqs. 16-19, 29). Applied by a forward pass z <- L_e^{-1} z over the elements and a
///   backward pass z <- U_e^{-1} z, each colour in parallel (OpenMP).
/// - Our reading of C2-C4 (eqs. 20-23, garbled): split every factor in the global numbering into
///   L_e = I_e + E_e (E_e strict lower) and U_e = D_e + F_e (D_e diagonal, F_e strict upper); C2
///   keeps the product over elements of the one-array storage I + E_e + (D_e - I_e) + F_e (the
///   first-order expansion of L_e U_e), C3 replaces that product by the sum
///   I + sum_e (E_e + D_e - I_e + F_e) (again first order), and C4 refactors the sum as a product
///   of global triangular matrices: C4 = W~^{1/2} (I + E)(D + F) W~^{1/2}, with E = sum_e E_e,
///   D = sum_e D_e, F = sum_e F_e gathered into global sparse matrices. C2 and C3 are not
///   implemented (C2 costs as much as C1; C3 has no cheap inverse).
/// - C5 (eq. 31): C4 with D replaced, off U (the paper: on the unknowns of no contact element),
///   by the initial diagonal of A, i.e. 1 in the W~-scaled system (D_ii kept on U). Since D_ii
///   sums the pivots of every element at unknown i (about the number of elements there) while
///   the scaled diagonal of A is 1, this is the correction the paper found to give a steady,
///   monotone residual decrease. C4 and C5 are applied by two sparse triangular solves.
#pragma once

#include "core/linear_operator.hpp"

#include <Eigen/Dense>

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::smoothers {

/// One element contribution A_e to the global matrix, as plain data.
struct ElementMatrix {
    /// Global unknowns of the element (distinct, any order; the EBE class sorts them). At most
    /// `EBE::max_element_dofs`.
    std::vector<int> dofs;
    /// The dense element matrix, dofs.size() x dofs.size(), rows and columns in the order of
    /// `dofs`. Elastic matrices are symmetric positive semi-definite; contact ones need not be.
    Eigen::MatrixXd A;
    /// true for a contact element (no Winget identity on its unit-scaled unknowns).
    bool is_contact = false;
};

/// Which EBE preconditioner of the 1997 paper's chain.
enum class EBEVariant {
    c1, ///< classical two-pass product of element factors (parallel by colour)
    c4, ///< global (I + E)(D + F) gathered from the element factors
    c5  ///< C4 with D = 1 (the scaled diagonal of A) off the unit-scaled unknowns
};

/// "c1", "c4" or "c5".
std::string_view to_string(EBEVariant v);
/// Streams `to_string(v)`.
std::ostream& operator<<(std::ostream& os, EBEVariant v);
/// Parses "c1", "c4" or "c5"; anything else throws mlc::InvalidInput listing the valid names.
EBEVariant parse_ebe_variant(std::string_view name);

/// Where the EBE scaling W~ is 1 instead of diag(A) (the paper's "i in ce").
enum class UnitScaling {
    /// Every unknown of a contact element, displacements of the contactor included (the reading
    /// of formulation.md): contact elements are factored unscaled and unregularized.
    contact_unknowns,
    /// Only the unknowns of no elastic element, i.e. the multipliers (the contact element's own
    /// "multiplier node" of the papers): the contactor displacements keep W~ = diag(A) and the
    /// identity of the regularization, in elastic and contact elements alike; only the
    /// multiplier block of a contact element is left unregularized.
    multipliers
};

/// "contact" or "multipliers".
std::string_view to_string(UnitScaling u);

/// Parameters of `EBE`.
struct EBEParams {
    /// Variant of the chain. Default c1: the classical EBE the 1997 paper starts from.
    EBEVariant variant = EBEVariant::c1;
    /// Where W~ = 1. Default multipliers: with contact_unknowns (formulation.md's reading) the
    /// contactor displacements are left unscaled next to elastic factors of diagonal 1 + K_ii,
    /// and on the square C1 diverges (CGS, levels 1 and 2) and C5 needs twice the iterations.
    UnitScaling unit_scaling = UnitScaling::multipliers;
    /// A pivot u_kk of an element factor is replaced by 1 when |u_kk| <= zero_pivot_tol *
    /// max |entry of the element matrix|, in [0, 1). Default 1e-12: catches the exact zeros of
    /// singular contact elements (gap, slip) and their round-off remnants in rotated frames,
    /// while the genuine multiplier pivots -1/r are about 1/r^2 relative to r M, far larger
    /// for any sensible r.
    double zero_pivot_tol = 1e-12;
    /// Run the C1 passes in parallel over the elements of one colour (OpenMP), when OpenMP is
    /// available. Default true; the result does not depend on it (same-coloured factors
    /// commute).
    bool parallel = true;
    /// Fewest elements of one colour for which a parallel region is opened, >= 1. Default 256:
    /// below that the fork/join costs more than the element solves (about 100 flops each).
    int min_parallel_elements = 256;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const EBEParams& p);

/// The EBE preconditioner C1, C4 or C5 (see the file comment for the formulas).
///
/// The element list is borrowed: it must outlive this object, and `setup`/`update_values`
/// read the current element matrices (so a Newton solver refreshes the contact element
/// matrices in place and calls `update_values`). The elements must sum to the matrix A given
/// to `setup` (not checked, except the sizes: A only provides W~ = diag(A)).
///
/// `setup` allocates (element factors, colouring, and for C4/C5 the global E and F). `apply`
/// and `apply_transpose` do not allocate once z has the right size; they keep no mutable state
/// and may be called concurrently. r and z may not be the same object.
class EBE final : public Preconditioner {
public:
    /// Largest number of unknowns of one element (a node-on-facet contact element has 8).
    static constexpr int max_element_dofs = 16;

    /// `elements` must outlive this object. Validates `params`.
    explicit EBE(const std::vector<ElementMatrix>& elements, EBEParams params = {});

    /// Builds W~, the element factors, the colouring and (C4/C5) E, D, F. A square, compressed,
    /// finite; every element unknown in range; A_ii > 0 on every unknown that is not unit-scaled
    /// (else InvalidInput naming the row). A need not outlive this call.
    void setup(const SparseMatrix& A) override;
    /// z = C^{-1} r. No allocation once z has the right size.
    void apply(const Vector& r, Vector& z) const override;
    /// z = C^{-T} r (transposed factors in reverse order). No allocation.
    void apply_transpose(const Vector& r, Vector& z) const override;
    /// "ebe(c1)", "ebe(c4)" or "ebe(c5)".
    std::string name() const override;

    /// Number of colours of the last `setup` (same-coloured elements share no unknown).
    int n_colours() const { return static_cast<int>(colour_start_.size()) - 1; }
    /// The elements in the order of the product (sorted by colour), as indices into the list.
    const std::vector<int>& element_order() const { return order_; }
    /// Colour c holds element_order()[colour_starts()[c] .. colour_starts()[c + 1]).
    const std::vector<int>& colour_starts() const { return colour_start_; }
    /// The scaling W~ (diagonal), one entry per unknown.
    const Vector& scaling() const { return w_; }
    /// Number of zero pivots replaced by 1 at the last `setup` (contact elements in gap or slip).
    int n_replaced_pivots() const { return n_replaced_; }
    /// Factors of element `e` (index into the list) as one dense matrix in the increasing order
    /// of its unknowns: strict lower part = L_e (unit diagonal implied), upper part = U_e.
    /// Allocates; for tests and reports.
    Eigen::MatrixXd element_factors(int e, std::vector<int>& sorted_dofs) const;
    /// true when unknown i belongs to a contact element.
    bool is_contact_unknown(Index i) const { return (contact_[static_cast<size_t>(i)] & 1) != 0; }
    /// true when W~_ii = 1 (see UnitScaling).
    bool is_unit_scaled(Index i) const { return unit_[static_cast<size_t>(i)] != 0; }
    /// The parameters in effect.
    const EBEParams& params() const { return params_; }

private:
    void colour_elements();
    void pack_factors();
    template <class Kernel> void element_pass(Vector& z, bool reverse, const Kernel& kernel) const;
    void gather_global_factors();

    const std::vector<ElementMatrix>& elements_;
    EBEParams params_;
    Index n_ = 0;
    int n_replaced_ = 0;
    Vector w_;                   // W~
    Vector isw_;                 // W~^{-1/2}
    std::vector<char> contact_;  // bit 1: in a contact element, bit 2: in an elastic one
    std::vector<char> unit_;     // W~ = 1 here
    std::vector<int> dof_start_; // per element: offset into dofs_ (sorted), size n_el + 1
    std::vector<int> dofs_;      // sorted global unknowns of all elements
    std::vector<int> fac_start_; // per element: offset into fac_ (row-major n_e x n_e)
    std::vector<double> fac_;    // combined L\U per element
    // C1: the factors packed in colour order (see pack_factors in the .cpp).
    std::vector<int> pk_dof_start_, pk_tri_start_, pk_dofs_;
    std::vector<double> pk_lo_, pk_up_, pk_ip_;
    std::vector<int> order_;        // elements sorted by colour
    std::vector<int> colour_start_; // colour c = order_[colour_start_[c] .. colour_start_[c+1])
    // C4/C5: unit lower I + E (strict part stored) and upper D + F (diagonal separately).
    SparseMatrix E_, F_;
    Vector d_inv_;
};

} // namespace mlc::smoothers
