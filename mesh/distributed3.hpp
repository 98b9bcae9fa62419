// SPDX-License-Identifier: MIT
/// @file A tetrahedral mesh hierarchy distributed over the processes of a Communicator: the 3D
/// counterpart of mesh/distributed.hpp (read its file comment first). Level p is partitioned
/// (partition_tets), each process keeps its tetrahedra plus one layer of ghost tetrahedra and
/// refines them locally by Bey's rule (mesh/tet_refine.hpp), so every process holds a nested
/// hierarchy of its own part (docs/parallel.md#parallel-3d-mesh).
///
/// As in 2D every process holds the whole level-p mesh and partitions it alike, and only the
/// global numbers of the vertices a process sees but does not own are exchanged, once per level.
///
/// Ownership. A tetrahedron of level p belongs to its part; its descendants inherit that owner.
/// A vertex of a finer level lies on the level-p mesh at a level-p vertex (owner:
/// Partition::vertex_owner), inside a level-p edge (owner: the lowest part among all the level-p
/// tetrahedra around the edge), inside a level-p face (the lowest part of the one or two
/// tetrahedra beside it) or inside a level-p tetrahedron (its part). The owner always holds the
/// vertex in one of its own tetrahedra, and every process computes the same owner from the
/// redundant level-p data alone.
///
/// Ghosts. The ghost tetrahedra are those of level p that share a vertex with an owned
/// tetrahedron, refined with them: every tetrahedron around an owned vertex of any level is local.
///
/// Geometry. A vertex on a curved boundary surface (TetMesh::shapes) sits where the serial
/// refinement puts it, also when the boundary face that moves it there belongs to a tetrahedron
/// that is not local (a ghost tetrahedron touching a curved boundary by an edge only).
///
/// Global numbering (per level): the owned vertices of rank r have the global numbers
/// [first_vertex, first_vertex + n_owned_vertices), in local index order. Three unknowns per
/// vertex, interleaved, so rank r's rows start at 3 first_vertex. On one process the local mesh of
/// every level is the serially refined mesh itself (same numbering).
#pragma once

#include "core/communicator.hpp"
#include "mesh/distributed.hpp"
#include "mesh/io/vtu.hpp"
#include "mesh/partition.hpp"
#include "mesh/tet_mesh.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace mlc::mesh {

/// Where a vertex of a refined tetrahedral level lies on the partitioned level-p mesh: in the
/// relative interior of a level-p vertex, edge, face or tetrahedron.
struct TetLocation {
    enum class Kind : std::uint8_t { vertex, edge, face, tet };
    Kind kind = Kind::vertex;
    /// Level-p vertex, edge (DistributedTetHierarchy::edges), face
    /// (DistributedTetHierarchy::faces) or tetrahedron index.
    int id = -1;
};

/// One level of one process's part of a tetrahedral hierarchy.
struct LocalTetLevel {
    /// The local tetrahedra (owned and ghost) with their vertices, the tagged boundary faces that
    /// are faces of local tetrahedra, and the tagged lines that are their edges. Level p: the
    /// local vertices in increasing level-p index order, the tetrahedra in increasing level-p
    /// index order. Finer levels: refine() of the level above (children of local tetrahedron t
    /// are 8t..8t+7, `parents` in local indices of the level above).
    TetMesh mesh;
    std::vector<int> tet_ancestor; ///< level-p tetrahedron of every local tetrahedron
    std::vector<char> tet_owned;   ///< 1 where this process owns the tetrahedron
    std::vector<TetLocation> vertex_location;
    std::vector<int> vertex_owner;           ///< rank owning every local vertex
    std::vector<std::int64_t> global_vertex; ///< global number of every local vertex
    std::vector<int> owned_vertices;         ///< local indices of the owned vertices, in order
    std::int64_t first_vertex = 0;           ///< global number of owned_vertices[0]
    std::int64_t n_global_vertices = 0;      ///< vertices of this level over all processes
    std::int64_t n_global_tets = 0;          ///< tetrahedra of this level over all processes

    /// Local vertices this process owns.
    int n_owned_vertices() const { return static_cast<int>(owned_vertices.size()); }
    /// Local vertices owned by another process (the ghost vertices).
    int n_ghost_vertices() const { return mesh.n_vertices() - n_owned_vertices(); }
    /// First global row of this process's unknowns (three per vertex, interleaved).
    std::int64_t first_row() const { return 3 * first_vertex; }
};

/// One process's part of a tetrahedral hierarchy refined from a partitioned level p.
struct DistributedTetHierarchy {
    Partition partition; ///< of the level-p mesh (partition_tets), the same on every process
    /// The level-p edges (sorted vertex pairs, tet_edges order) that TetLocation::id of kind edge
    /// indexes.
    std::vector<std::array<int, 2>> edges;
    /// The level-p faces (sorted vertex triples, in order of first appearance over the
    /// tetrahedra) that TetLocation::id of kind face indexes.
    std::vector<std::array<int, 3>> faces;
    /// levels[k] is level p + k of this process's part, k = 0 .. n_refinements.
    std::vector<LocalTetLevel> levels;
    int rank = 0;
    int n_processes = 1;
};

/// Partitions the tetrahedra of `level_p` into comm.size() parts (partition_tets with `weights`)
/// and builds this process's part of it and of its `n_refinements` uniform refinements.
///
/// Collective: every process calls it with the same mesh, refinements, weights and reach.
/// `level_p` must pass check_quality and refine without error. Throws InvalidInput for
/// n_refinements < 0 or more processes than tetrahedra, on every process alike. `reach`
/// (GhostReach, mesh/distributed.hpp) widens the ghost layer along contact interfaces: the
/// level-p tetrahedra with a boundary face tagged one of its tags within its distance (face to
/// face, in the reference configuration) of a boundary face tagged one of its tags of a
/// tetrahedron of the one-layer local mesh become ghosts too.
DistributedTetHierarchy distribute(const TetMesh& level_p, int n_refinements,
                                   const Communicator& comm, const std::vector<int>& weights = {},
                                   const std::vector<GhostReach>& reach = {});

/// Writes a distributed tetrahedral level as one mesh: `file` (a .pvtu) and one .vtu piece per
/// process (piece_path), as write_distributed_vtu does in 2D. Each process writes its owned
/// tetrahedra (tet_owned) and the vertices they use with write_vtu for a TetMesh (binary, with
/// the cell field "body" first); `point_fields` hold values on the local vertices of `L` and
/// `cell_fields` on its local tetrahedra. Once every piece is written, process 0 writes `file`.
///
/// Collective. If writing fails on any process, every process throws (the failing ones their own
/// error, the others a std::runtime_error saying another process failed); `file` is then not
/// written.
void write_distributed_vtu(const std::filesystem::path& file, const LocalTetLevel& L,
                           const std::vector<Field>& point_fields,
                           const std::vector<Field>& cell_fields, const Communicator& comm);

} // namespace mlc::mesh
