// SPDX-License-Identifier: MIT
/// @file The levels of a distributed 3D run: the counterpart of levels/distributed.hpp (read its
/// file comment first) on mesh::distribute's tetrahedral parts (mesh/distributed3.hpp,
/// docs/parallel.md#parallel-3d-mesh).
///
/// Numbering. A process's part of a level is a Level3 on its local mesh (owned and ghost
/// tetrahedra) numbered by the vertex order owned vertices first (LocalTetLevel::owned_vertices,
/// in their global order), then the ghosts (in local index order): the free components of a
/// vertex, interleaved, then its multipliers. The owned unknowns are the first `n_owned` of the
/// part and the global unknowns [first_dof, first_dof + n_owned) (contiguous per process, in
/// rank order: hypre's row partition). The fixed components, prescribed values, multiplier
/// counts and pinned multipliers of ghost vertices are their owners' (a part's mesh may lack a
/// ghost vertex's boundary faces). On one process the part is the serial level with the serial
/// numbering (levels::build_level on the same mesh, its contact elements included).
///
/// Contact. The contact elements exist at owned contact nodes only, built as build_level builds
/// them (detail::find_contact_nodes3 on the owned vertices: the same claims in pair order, the
/// same search decided on the level-0 target faces, the same pinned components). A node-on-rigid
/// element couples its vertex's unknowns alone; a two-body element couples its contactor with
/// target vertices that other processes may own, so each process also builds the elements of
/// other processes' contact nodes that reach its owned vertices (Level3::ghost_contacts), through
/// a ghost layer widened along the contact interfaces (contact_ghost_reach3). Every owned row of
/// the contact residual and Jacobian is then complete from local data and the ghost values
/// GhostExchange3::update fetches (multipliers included).
///
/// What is exact. The owned rows of the part's stiffness K, load f and transfers are those of
/// the whole level: every tetrahedron around an owned vertex is local (the ghost layer), with the
/// boundary faces of its owned faces, and every parent of an owned vertex is a local vertex of
/// the level below. Rows of ghost unknowns are incomplete and never used. K's multiplier rows
/// and columns are empty, as build_level's; T's too (3D transfers act on the displacements).
///
/// These levels are solved by levels/distributed_solve3.hpp (Newton with a NewtonDistribution,
/// GMRES with DistributedMultigrid3); the elastic block alone can be solved by hypre's
/// BoomerAMG-PCG on K_rows(). What is not yet here: a loading path
/// (ElasticProblem3::n_path_points() > 1) is refused with InvalidInput; the loading is the full
/// load (K, f at load factor 1, u_fixed) as with proportional loading.
#pragma once

#include "core/communicator.hpp"
#include "levels/elastic3d_levels.hpp"
#include "levels/level.hpp"
#include "mesh/distributed3.hpp"
#include "solvers/hypre/par_matrix.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace mlc::levels {

/// Fetches values held per vertex from the vertices' owners into the ghost vertices of a
/// process's part of a tetrahedral level (one personalised exchange over the Communicator), as
/// GhostExchange does for a triangular part.
class GhostExchange3 {
public:
    GhostExchange3() = default;
    /// Collective: every process tells the owners which of their vertices it holds as ghosts.
    GhostExchange3(const mesh::LocalTetLevel& part, const Communicator& comm);
    /// Collective: `records` holds `width` values per local vertex; the records of the ghost
    /// vertices are overwritten with their owners'.
    void vertex_records(std::vector<double>& records, int width) const;
    /// Collective: the entries of x (a part's unknowns, `dofs` numbering) at ghost vertices are
    /// overwritten with their owners' values: per vertex its free components, then its extra
    /// unknowns (multipliers). Every process must agree on which components of a vertex are
    /// unknowns and on its extra unknowns (build_distributed_level3 takes the fixed flags and
    /// multiplier counts of ghost vertices from their owners).
    void update(const fem::DofMap3& dofs, Vector& x) const;
    /// Vertices held as ghosts from each process (rank order).
    const std::vector<std::vector<int>>& ghosts_by_owner() const { return recv_; }

private:
    const Communicator* comm_ = nullptr;
    std::vector<std::vector<int>> recv_; ///< per owner: this part's ghost vertices it sends
    std::vector<std::vector<int>> send_; ///< per process: owned vertices it holds as ghosts
};

/// One process's part of one 3D level of a distributed run.
struct DistributedLevel3 {
    mesh::LocalTetLevel part; ///< the local mesh moved into `local`: part.mesh is empty
    /// The part as a Level3 (owned unknowns first; contacts at owned contact nodes, with
    /// lambda_dof; ghost_contacts and ghost_lambda_dof: other processes' elements reaching owned
    /// vertices).
    Level3 local;
    std::vector<int> n_extra; ///< multipliers per local vertex (ghosts: their owners')
    /// Multiplier components pinned by supports per local vertex (ContactElement3::pinned;
    /// ghosts: their owners').
    std::vector<unsigned char> pinned;
    GhostExchange3 ghosts;
    Index n_owned = 0;                    ///< owned unknowns: local unknowns [0, n_owned)
    std::int64_t first_dof = 0;           ///< global number of local unknown 0
    std::int64_t n_global_dofs = 0;       ///< unknowns of the level over all processes
    int n_global_contacts = 0;            ///< contact nodes of the level over all processes
    std::vector<std::int64_t> global_dof; ///< global number of every local unknown
    /// The stiffness's owned rows, the one copy of it (local.elastic.K is freed once they are
    /// cut from it), and K, the ParCSR matrix on their arrays (for hypre's own solvers, which
    /// want the diagonal entry first in its row, build one from owned_rows instead).
    std::unique_ptr<solvers::RowBlocks> K_blocks; ///< (held by pointer: K points into its arrays)
    std::unique_ptr<solvers::ParMatrix> K;

    /// The owned rows of a matrix on the part's unknowns (rows and columns in local numbering,
    /// owned rows first) with global column numbers.
    solvers::DistributedRows owned_rows(const SparseMatrix& A) const;
    /// The owned rows of A split as hypre stores them (DistributedLevel::row_blocks).
    solvers::RowBlocks row_blocks(const SparseMatrix& A) const;
    /// The owned entries of local.elastic.f (the load at factor 1 on the owned unknowns).
    Vector owned_load() const { return local.elastic.f.head(n_owned); }
    /// The owned rows of K (K_blocks) with global columns, for a ParMatrix built through IJ
    /// (what solvers::boomeramg_pcg_par needs).
    solvers::DistributedRows K_rows() const;
    /// The component (0, 1 or 2) of every owned unknown: BoomerAMG's dof_func (-1 at a
    /// multiplier).
    std::vector<int> dof_function() const;
};

/// Collective: builds this process's part of a 3D level from its local mesh (`part`, a level of
/// mesh::distribute of a refinement of p.mesh0; its mesh is moved out): supports (a point
/// support is the local vertex at its position, held by the processes that have it), contact
/// elements (see the file comment), body materials, face loads and body forces at the full load,
/// the numbering above, K and f assembled on the local tetrahedra, and the owned rows of K as a
/// ParMatrix. For two-body pairs `part` must hold the ghost layer contact_ghost_reach3 asks
/// mesh::distribute for. Throws InvalidInput on every process alike for a loading path
/// (n_path_points() > 1), a support point that is a vertex of no process's part, a contact pair
/// with no contactor node (or, two-body, none that found a target) on any process, and for the
/// errors build_level throws on a contact node (an ambiguous pinning, a degenerate target face):
/// the lowest failing process's message, with its rank when there are several processes. p must
/// have passed validate().
DistributedLevel3 build_distributed_level3(const ElasticProblem3& p, mesh::LocalTetLevel part,
                                           const Communicator& comm);

/// The ghost layer a distributed 3D run needs along the interfaces of `p`'s two-body pairs on the
/// partitioned level `level_p` (mesh::distribute's `reach`; empty without two-body pairs), the
/// 2D rule of contact_ghost_reach on faces. Per pair, its contactor and target faces within
/// twice the reach R of its search:
///   node on facet: R = (search_radius + 2) h0 + 2 hp,
///   node on node:  R = (match_tolerance + 2) h0 + 2 hp,
/// h0 the longest edge of the level-0 target faces (search_radius h0 bounds the distance at which
/// a node is kept on every level; the element's facet lies within one more h0, and the facets
/// whose normals its edge or vertex normal averages within another) and hp the longest level-p
/// edge of the pair's faces (a segment-integrated node's contactor patch; the finer vertices of a
/// curved face leave the level-p face by less). One R covers the faces an owned contact node
/// needs; the second the faces of another process's contact node whose element reaches an owned
/// vertex (Level3::ghost_contacts).
std::vector<mesh::GhostReach> contact_ghost_reach3(const ElasticProblem3& p,
                                                   const mesh::TetMesh& level_p);

/// The transfer between consecutive distributed 3D levels (fine refined from coarse), the
/// full_prolongation3 of the serial levels on the owned fine rows, as a ParMatrix (owned fine
/// rows, coarse unknowns as columns): the displacements by the local T
/// (transfer::vertex_prolongation of the fine part restricted to the free displacements,
/// transfer::restrict_to_unknowns, as build_hierarchy's), the multipliers of the owned fine
/// contact nodes by the surface transfer Q of the contactor faces (transfer/surface_q.hpp, its
/// coarse masses P^T m_h and the coarse nodes' frames taken from their owners), in each node's
/// frame.
struct DistributedTransfer3 {
    std::unique_ptr<solvers::ParMatrix> T;
};

/// Collective. `fine`'s part must be the refinement of `coarse`'s (levels k + 1 and k of one
/// mesh::distribute of p).
DistributedTransfer3 build_distributed_transfer3(const ElasticProblem3& p,
                                                 const DistributedLevel3& coarse,
                                                 const DistributedLevel3& fine,
                                                 const Communicator& comm);

/// The distributed levels p .. p + n_refinements of a 3D problem and the transfers between
/// them: levels[k] is level p + k, transfers[k] from levels[k] to levels[k + 1].
struct DistributedHierarchy3 {
    std::vector<DistributedLevel3> levels;
    std::vector<DistributedTransfer3> transfers;
};

/// Collective: refines p.mesh0 `p_level` times serially (mesh::refine, every process alike),
/// distributes that level (mesh::distribute with `n_refinements` and contact_ghost_reach3's
/// reach) and builds every part and transfer. Throws InvalidInput for p_level < 0 or
/// n_refinements < 0.
DistributedHierarchy3 build_distributed_hierarchy3(const ElasticProblem3& p, int p_level,
                                                   int n_refinements, const Communicator& comm);

} // namespace mlc::levels
