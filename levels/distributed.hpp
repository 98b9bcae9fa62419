// SPDX-License-Identifier: MIT
/// @file The levels of a distributed run (docs/parallel.md#parallel-how): each process builds its part of every
/// level above the partition level p from mesh::distribute's local meshes, with the unknowns it
/// owns numbered first, the stiffness and prolongations as hypre ParCSR matrices
/// (solvers::ParMatrix), and the values of the unknowns at ghost vertices fetched from their
/// owners.
///
/// Numbering. A process's part of a level is a levels::Level built on its local mesh (owned and
/// ghost triangles) by build_level with a LevelPart: the owned vertices come first (in Hilbert
/// order), so the owned unknowns are the first `n_owned` of the part, and they are the global
/// unknowns [first_dof, first_dof + n_owned) (contiguous per process, in rank order: hypre's row
/// partition). The fixed components, prescribed values and multiplier counts of ghost vertices
/// are their owners' (a part's mesh may lack a ghost vertex's boundary edges). Contact elements
/// exist only at owned vertices. A node-on-rigid element couples its vertex's unknowns alone; a
/// two-body element couples its contactor with target vertices that other processes may own, so
/// each process also builds the elements of other processes' contact nodes that reach its owned
/// vertices (Level::ghost_contacts, through a ghost layer widened along the contact interface:
/// mesh::GhostReach). Every owned row of the residual and the Jacobian is then complete from local
/// data and the current ghost values; the Jacobian's off-diagonal block gains the contact
/// couplings to other processes' unknowns.
///
/// What is exact. The rows of the owned unknowns of the part's stiffness, loads and transfers are
/// those of the whole level: every triangle around an owned vertex is local (the ghost layer),
/// and every parent of an owned vertex is a local vertex of the level below. Rows of ghost
/// unknowns are incomplete and never used.
#pragma once

#include "core/communicator.hpp"
#include "levels/level.hpp"
#include "levels/problem.hpp"
#include "mesh/distributed.hpp"
#include "solvers/hypre/par_matrix.hpp"
#include "transfer/transfer.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace mlc::levels {

/// Fetches values held per vertex from the vertices' owners into the ghost vertices of a
/// process's part (one personalised exchange over the Communicator, which MPI carries).
class GhostExchange {
public:
    GhostExchange() = default;
    /// Collective: every process tells the owners which of their vertices it holds as ghosts.
    GhostExchange(const mesh::LocalLevel& part, const Communicator& comm);
    /// Collective: `records` holds `width` values per local vertex; the records of the ghost
    /// vertices are overwritten with their owners'.
    void vertex_records(std::vector<double>& records, int width) const;
    /// Collective: the entries of x (a part's unknowns, `dofs` numbering) at ghost vertices are
    /// overwritten with their owners' values. Every process must agree on which components of a
    /// vertex are unknowns (the ghost data of DistributedLevel ensures it).
    void update(const fem::DofMap& dofs, Vector& x) const;
    /// Vertices held as ghosts from each process (rank order), and sent to each.
    const std::vector<std::vector<int>>& ghosts_by_owner() const { return recv_; }

private:
    const Communicator* comm_ = nullptr;
    std::vector<std::vector<int>> recv_; ///< per owner: this part's ghost vertices it sends
    std::vector<std::vector<int>> send_; ///< per process: owned vertices it holds as ghosts
};

/// One process's part of one level of a distributed run.
struct DistributedLevel {
    mesh::LocalLevel part;    ///< the local mesh moved into `local`: part.mesh is empty
    Level local;              ///< the part as a Level (owned unknowns first)
    std::vector<int> n_extra; ///< multipliers per local vertex (ghosts: their owners')
    /// Multiplier components pinned by supports per local vertex (ContactElement::pinned;
    /// ghosts: their owners'), for the transfers.
    std::vector<unsigned char> pinned;
    GhostExchange ghosts;
    Index n_owned = 0;                    ///< owned unknowns: local unknowns [0, n_owned)
    std::int64_t first_dof = 0;           ///< global number of local unknown 0
    std::int64_t n_global_dofs = 0;       ///< unknowns of the level over all processes
    int n_global_contacts = 0;            ///< contact nodes of the level over all processes
    std::vector<std::int64_t> global_dof; ///< global number of every local unknown
    /// The stiffness's owned rows, the one copy of it (local.elastic.K is freed once they are
    /// cut from it), and K, the ParCSR matrix on their arrays.
    std::unique_ptr<solvers::RowBlocks> K_blocks; ///< (held by pointer: K points into its arrays)
    std::unique_ptr<solvers::ParMatrix> K;

    /// The owned rows of a matrix on the part's unknowns (rows and columns in local numbering,
    /// owned rows first) with global column numbers.
    solvers::DistributedRows owned_rows(const SparseMatrix& A) const;
    /// The owned rows of A split as hypre stores them: owned columns (local numbers, which are
    /// global - first_dof) and the others (compacted, in increasing global order).
    solvers::RowBlocks row_blocks(const SparseMatrix& A) const;
    /// Contact nodes of every local vertex with multipliers (ghosts included), for transfer/.
    transfer::ContactNodes contact_nodes() const;
};

/// Collective: builds this process's part of a level from its local mesh (`part`, from
/// mesh::distribute; its mesh is moved out). Throws InvalidInput on every process when a contact
/// pair has no contactor node on any process or a support point is not a vertex of the level.
/// For two-body pairs `part` must hold the ghost layer solve_distributed asks mesh::distribute
/// for (contact_ghost_reach).
DistributedLevel build_distributed_level(const Problem& problem, mesh::LocalLevel part,
                                         const Communicator& comm);

/// The ghost layer a distributed run needs along the interfaces of `problem`'s two-body pairs on
/// the partitioned level `level_p` (mesh::distribute's `reach`; empty without two-body pairs).
/// Per pair, its contactor and target boundaries within twice the reach R of its search:
///   node on facet: R = (search_radius + 2) h0 + 2 hp,  node on node: R = (match_tolerance + 2)
///   h0 + 2 hp,
/// h0 the longest level-0 target facet (search_radius h0 bounds the search distance of every
/// level, a segment-integrated element reaches one more facet and one contactor edge) and hp
/// the longest level-p edge of the pair's boundaries (the finer vertices of a curved boundary
/// leave the level-p polygon by less). One R covers the facets an owned contact node needs; the
/// second the facets of another process's contact node whose element reaches an owned vertex
/// (Level::ghost_contacts).
std::vector<mesh::GhostReach> contact_ghost_reach(const Problem& problem,
                                                  const mesh::Mesh& level_p);

/// The ghost reach of one two-body pair (2D ContactPair or 3D ContactPair3): 2 R with
/// R = (search_radius + 2) h0 + 2 hp for node on facet, match_tolerance in place of
/// search_radius for node on node (contact_ghost_reach's rule; h0 and hp as there).
template <class Pair> double contact_reach_distance(const Pair& pair, double h0, double hp) {
    const double factor = pair.element == ContactElementKind::node_on_facet ? pair.search_radius
                                                                            : pair.match_tolerance;
    return 2.0 * ((factor + 2.0) * h0 + 2.0 * hp);
}

/// The transfer between consecutive distributed levels (fine refined from coarse): the local
/// LevelTransfer of the two parts (whose owned fine rows are exact) and its T as a ParMatrix
/// (owned fine rows, coarse unknowns as columns).
struct DistributedTransfer {
    transfer::LevelTransfer local;
    std::unique_ptr<solvers::ParMatrix> T;
};

/// Collective.
DistributedTransfer build_distributed_transfer(const DistributedLevel& coarse,
                                               const DistributedLevel& fine,
                                               const Communicator& comm,
                                               transfer::QRule rule = transfer::QRule::paper);

/// The partition level of a run on `n_processes` processes (docs/parallel.md#parallel-partition-level): the coarsest level
/// with at least kTrianglesPerProcess triangles per process, and at most `finest - 1` (so that at
/// least one level above it is distributed), at least 0. `level0_triangles`: the triangles of level
/// 0 (each level has four times those of the one below).
inline constexpr int kTrianglesPerProcess = 2000;
int partition_level(std::int64_t level0_triangles, int finest, int n_processes);

} // namespace mlc::levels
