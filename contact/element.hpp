// SPDX-License-Identifier: MIT
/// @file Contact elements (node on rigid, node on node, node on facet): relative displacement in
/// the local frame (the tangents t, then the normal n), the Alart–Curnier residual, and the
/// element tangent A_ce, in 2D and 3D (the dimension a template parameter; of the element
/// builders only node_on_facet, with its two target vertices, is 2D alone).
#pragma once

#include "contact/law.hpp"
#include "contact/obstacle.hpp"
#include "core/types.hpp"
#include "fem/dof_map.hpp"
#include "mesh/mesh.hpp"

#include <array>
#include <string_view>
#include <type_traits>
#include <vector>

namespace mlc::contact {

/// How a node-on-facet element spreads its contactor node's force over the target.
enum class FacetIntegration {
    /// The papers' one-pass element: the target facet under the node, weights
    /// (1, -(1-alpha), -alpha) (nodal interpolation of the contactor's forces on the target).
    nodal,
    /// Segment-integrated (mortar-type, lumped; El-Abbasi & Bathe 2001): weights
    /// (1, -M_ik / D_i) over the target vertices k under the support of the contactor node's
    /// shape function N_i, D_i = int N_i ds, M_ik = int N_i N_k ds (node_on_facet_search).
    segment,
    /// Segment-integrated with dual (biorthogonal) test functions psi_i = 3 N_i - 1 on each
    /// contactor edge (Wohlmuth 2000): M_ik = int psi_i N_k ds, D_i = int N_i ds. Identity weights
    /// on matching meshes, no smoothing of the contactor by the target.
    dual
};

/// "nodal", "segment", "dual".
std::string_view to_string(FacetIntegration f);

/// One contact element in `dim` dimensions: a contactor vertex and any number of target vertices
/// with weights w so that the relative displacement is u_rel = sum_j w_j u_(vertex j)
/// (docs/theory.md#theory-contact-elements): node on rigid (1), node on node (1, -1), node on
/// facet (1, -(1-alpha), -alpha), segment-integrated node on facet (1, -M_i1 / D_i, ...,
/// -M_im / D_i). `vertex` and `weight` have one entry per node of the element (n_nodes(), at
/// least 1): vertex[0] the contactor with weight[0] = 1, then the targets. A default-constructed
/// element is a node on rigid whose contactor is not set yet: vertex {-1}, weight {1}. The
/// frame: n the unit normal of the target toward the contactor and the dim - 1 tangents t
/// (columns; contact::tangent_basis: 2D t = (n_y, -n_x), 3D t1 = normalize(e x n) with e the
/// axis least aligned with n, t2 = n x t1). Frictional elements carry dim multipliers (the
/// tangents' then the normal's), frictionless ones lambda_n only.
template <int dim> struct BasicContactElement {
    static_assert(dim == 2 || dim == 3, "contact elements are for dim = 2 or 3");
    using Point = Eigen::Matrix<double, dim, 1>;
    using Tangents = Eigen::Matrix<double, dim, dim - 1>; ///< 2D: a Vec2
    /// The element's vertices: vertex[0] the contactor node, then the target vertices.
    std::vector<int> vertex{-1};
    /// One weight per vertex: weight[0] = 1 (the contactor), the targets' summing to -1.
    std::vector<double> weight{1.0};
    Point n = Point::Unit(dim - 1);  ///< unit normal of the target, toward the contactor
    Tangents t = default_tangents(); ///< the tangents (columns)
    double g0 = 0.0;                 ///< initial normal gap (>= 0 apart)
    double mu = 0.0;                 ///< Coulomb coefficient (0: frictionless)
    double r = 1.0;                  ///< augmentation parameter (force / length)
    int pair = 0;                    ///< index of the contact pair in the scene
    /// Multiplier components pinned to zero because supports prescribe the relative displacement
    /// along them (kPinnedT: every tangential one, kPinnedN; pin_held_components). A pinned
    /// component keeps its unknown, but its Phi and its row and column of M are zero: its
    /// equation reads lambda = 0, and the reaction goes to the support. A pinned normal pins
    /// every component (a contact that carries no normal force carries no friction).
    unsigned char pinned = 0;
    /// The number of nodes: the contactor and its targets (vertex.size(), weight.size() alike).
    int n_nodes() const { return static_cast<int>(vertex.size()); }
    /// Frictional elements carry (lambda_t, lambda_n); frictionless ones lambda_n only.
    bool frictional() const { return mu > 0.0; }
    int n_multipliers() const { return frictional() ? dim : 1; }
    /// Bits of `pinned`: the tangential multipliers, the normal one, and (3D) the first tangent
    /// alone (turn_first_tangent_onto_axis: t1 along a held axis, t2 free).
    static constexpr unsigned char kPinnedT = 1, kPinnedN = 2, kPinnedT1 = 4;

private:
    /// The tangents of the default normal e_(dim-1): 2D (1, 0), 3D tangent_basis(e_z).
    static Tangents default_tangents() {
        if constexpr (dim == 2)
            return Tangents(1.0, 0.0);
        else
            return tangent_basis<dim>(Point::Unit(dim - 1));
    }
};

/// The 2D element.
using ContactElement = BasicContactElement<2>;
/// The 3D element.
using ContactElement3 = BasicContactElement<3>;

/// Directions closer than this (in the norm of their free part, for unit directions) to the
/// span of the prescribed displacement components count as held.
inline constexpr double kHeldDirectionTolerance = 1e-8;

/// What the supports leave of an element's multipliers (held_components).
struct HeldComponents {
    unsigned char pinned = 0; ///< ContactElement::pinned for the element
    /// With kPinnedT1 (3D): the held axis the element's first tangent must be turned onto
    /// (turn_first_tangent_onto_axis) before `pinned` applies; -1 otherwise.
    int pinned_axis = -1;
    /// true when a multiplier component the supports do not hold still has a part along a
    /// held direction (an obstacle inclined to a support's axes, with friction): the support
    /// and the contact then share a force direction and the multipliers are not unique.
    bool ambiguous = false;
};

/// The multiplier components of `e` along which every vertex of the element (nonzero weight)
/// has its displacement prescribed, fixed[v][c] true when component c of vertex v is: the
/// relative displacement along them is prescribed, so their equation d = 0 holds no unknown
/// and their multiplier appears in no equation. A direction g counts as held when its part
/// along the components some vertex leaves free has norm at most kHeldDirectionTolerance. The
/// normal held pins every component; otherwise every tangent held pins the tangential
/// multipliers. In 3D, when exactly one component c is held and n lies across e_c (to
/// kHeldDirectionTolerance), the first tangent alone is pinned (kPinnedT1, pinned_axis = c: the
/// frame must be turned with turn_first_tangent_onto_axis): a symmetry plane crossing frictional
/// contact nodes holds their tangential force across the plane and leaves the other tangent's
/// friction to the law (the Coulomb disc reduced to an interval). Any other frame that meets the
/// held directions in part is `ambiguous`. Rigid obstacles
/// (one vertex) pin where the contactor's components are held; two-body elements only where
/// the target vertices' matching components are held too.
template <int dim>
HeldComponents
held_components(const BasicContactElement<dim>& e,
                const std::type_identity_t<std::vector<std::array<bool, dim>>>& fixed);

/// Turns the tangents of 3D element `e` so that t1 is the unit part of e_axis across n and
/// t2 = n x t1 (the frame held_components asks for with kPinnedT1).
void turn_first_tangent_onto_axis(BasicContactElement<3>& e, int axis);

/// Node-on-rigid elements for the given contactor vertices against an obstacle (frame and gap
/// from BasicObstacle::frame and tangent_basis).
template <int dim>
std::vector<BasicContactElement<dim>>
node_on_rigid(const mesh::SimplexMesh<dim>& m, const std::vector<int>& contactors,
              const BasicObstacle<dim>& obstacle, double mu, double r, int pair);

/// Node-on-facet element: contactor vertex c against the target facet (a, b), the projection of
/// c at barycentric coordinate alpha in [0, 1] (0 at a, 1 at b): weights (1, -(1-alpha), -alpha),
/// n the unit facet normal toward the contactor, t = (n_y, -n_x), g0 the initial signed gap.
/// Throws InvalidInput for alpha outside [0, 1] or a normal that is not of unit length.
ContactElement node_on_facet(int c, int a, int b, double alpha, const Vec2& n, double g0, double mu,
                             double r, int pair);

/// Node-on-facet element with given target vertices and weights (segment integration, or the
/// barycentric weights of a 3D facet): vertex c with weight 1, then targets[k] with weights[k],
/// as many as given. n the unit target normal toward the contactor, t = tangent_basis(n) (2D
/// (n_y, -n_x)), g0 the initial signed gap. Throws InvalidInput when targets and weights differ
/// in number or are empty, a target is c or repeats, a weight is not finite, the weights do not
/// sum to -1 (to 1e-10: rigid translations must give no gap), or the normal is not unit.
template <int dim>
BasicContactElement<dim> node_on_facet_weighted(int c, const std::vector<int>& targets,
                                                const std::vector<double>& weights,
                                                const Eigen::Matrix<double, dim, 1>& n, double g0,
                                                double mu, double r, int pair);

/// Node-on-node element: contactor vertex c against target vertex a (a matching interface):
/// weights (1, -1), n the unit target normal toward the contactor, t = tangent_basis(n) (2D
/// (n_y, -n_x)). Throws InvalidInput for a normal that is not of unit length or c == a.
template <int dim>
BasicContactElement<dim> node_on_node(int c, int a, const Eigen::Matrix<double, dim, 1>& n,
                                      double g0, double mu, double r, int pair);

/// Local state of an element at (u, lambda).
template <int dim> struct BasicElementState {
    double d_n = 0.0; ///< normal gap g0 + n . u_rel
    /// slip increment t . (u_rel - u_rel_prev), one per tangent
    Eigen::Matrix<double, dim - 1, 1> d_t = Eigen::Matrix<double, dim - 1, 1>::Zero();
    /// (lambda_t, lambda_n): the tangents' multipliers (0 when frictionless), then the normal's
    Eigen::Matrix<double, dim, 1> lambda = Eigen::Matrix<double, dim, 1>::Zero();
    LawProjection<dim> proj; ///< Phi(lambda + r d) and M
};
using ElementState = BasicElementState<2>;

/// Evaluates element e: relative displacements from the full nodal displacement vectors
/// (dim per vertex) of the current iterate and of the previous converged load step, and the
/// multipliers from the unknowns x at `lambda_dof` (the tangents' then lambda_n, or lambda_n
/// alone). Pinned components (BasicContactElement::pinned): pinned tangents project as
/// sigma_t = 0 (stick or gap by the normal alone) with Phi_t = 0 and M's tangential rows and
/// columns zero; a pinned normal gives Phi = 0, M = 0 and status gap. Either way a pinned
/// component's residual row reads -lambda / r and its tangent row and column hold only -1 / r on
/// the diagonal.
template <int dim>
BasicElementState<dim> evaluate(const BasicContactElement<dim>& e, const Vector& u_full,
                                const Vector& u_prev_full, const Vector& x, int lambda_dof);

/// Adds the element's residual to R: R_u += sum_j w_j (t Phi_t + Phi_n n) at the free
/// displacement unknowns of its vertices; R_lambda = -(1/r) (lambda - Phi).
template <int dim>
void add_residual(const BasicContactElement<dim>& e, const BasicElementState<dim>& s,
                  const fem::BasicDofMap<dim>& dofs, int lambda_dof, Vector& R);

/// Element tangent entries (docs/theory.md#theory-element-blocks) in a fixed order: every (row,
/// col) pair of the element's free unknowns appears once, whatever the status, so the Jacobian
/// pattern never changes. Calls `add(row, col, value)` for each.
///   uu: w_j w_k r G M G^T, u-lambda: w_j G M, lambda-u: w_k M G^T, lambda-lambda: (M - I) / r,
/// with G = [t n] (for frictionless elements only the n column/row and M_nn).
template <int dim, class Add>
void for_each_tangent_entry(const BasicContactElement<dim>& e,
                            const Eigen::Matrix<double, dim, dim>& M,
                            const fem::BasicDofMap<dim>& dofs, int lambda_dof, Add&& add) {
    using Mat = Eigen::Matrix<double, dim, dim>;
    Mat G;
    G.template leftCols<dim - 1>() = e.t;
    G.col(dim - 1) = e.n;
    const int nm = e.n_multipliers();
    const int m0 = nm == dim ? 0 : dim - 1; // first local multiplier component (t or n)
    const Mat GMGt = G * M * G.transpose();
    const Mat GM = G * M;
    const Mat MGt = M * G.transpose();
    for (int j = 0; j < e.n_nodes(); ++j) {
        const int vj = e.vertex[static_cast<size_t>(j)];
        const double wj = e.weight[static_cast<size_t>(j)];
        for (int a = 0; a < dim; ++a) {
            const int row = dofs.u_dof(vj, a);
            if (row < 0) continue;
            for (int k = 0; k < e.n_nodes(); ++k) {
                const int vk = e.vertex[static_cast<size_t>(k)];
                const double wk = e.weight[static_cast<size_t>(k)];
                for (int b = 0; b < dim; ++b) {
                    const int col = dofs.u_dof(vk, b);
                    if (col >= 0) add(row, col, wj * wk * e.r * GMGt(a, b));
                }
            }
            for (int q = m0; q < dim; ++q)
                add(row, lambda_dof + q - m0, wj * GM(a, q));
        }
    }
    for (int q = m0; q < dim; ++q) {
        const int row = lambda_dof + q - m0;
        for (int k = 0; k < e.n_nodes(); ++k) {
            const int vk = e.vertex[static_cast<size_t>(k)];
            const double wk = e.weight[static_cast<size_t>(k)];
            for (int b = 0; b < dim; ++b) {
                const int col = dofs.u_dof(vk, b);
                if (col >= 0) add(row, col, wk * MGt(q, b));
            }
        }
        for (int p = m0; p < dim; ++p)
            add(row, lambda_dof + p - m0, (M(q, p) - (q == p ? 1.0 : 0.0)) / e.r);
    }
}

} // namespace mlc::contact
