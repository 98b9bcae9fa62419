// SPDX-License-Identifier: MIT
/// @file A mesh hierarchy distributed over the processes of a Communicator: one level p is
/// partitioned, each process keeps its triangles plus one layer of ghost triangles and refines
/// them locally, so every process holds a nested hierarchy of its own part (docs/parallel.md#parallel-how).
///
/// Every process holds the whole level-p mesh (the levels up to p are small and redundant) and
/// partitions it the same way (partition_triangles is deterministic), so building the hierarchy
/// needs no mesh to be sent: communication is only the resolution of the global numbers of the
/// vertices a process sees but does not own, one personalised exchange per level.
///
/// Ownership. A triangle of level p belongs to its part; its descendants inherit that owner. A
/// vertex of a finer level lies on the level-p mesh either at a level-p vertex (owner:
/// Partition::vertex_owner), inside a level-p edge (owner: the lowest part among the one or two
/// triangles beside it) or inside a level-p triangle (owner: its part). The owner therefore
/// always holds the vertex in one of its own triangles, and every process computes the same
/// owner for a vertex from the redundant level-p data alone.
///
/// Ghosts. The ghost triangles are those of level p that share a vertex with an owned triangle,
/// refined with them. Every triangle around an owned vertex of any level is then local, so a
/// process assembles the complete rows of its owned unknowns from its local triangles alone.
///
/// Global numbering (per level): the owned vertices of rank r have the global numbers
/// [first_vertex, first_vertex + n_owned_vertices), in local index order, with first_vertex the
/// number of vertices owned by lower ranks. Unknowns are interleaved by node, so rank r's rows are
/// [2 first_vertex, 2 (first_vertex + n_owned_vertices)): hypre's contiguous row partition
/// (HYPRE_IJMatrixCreate with ilower = 2 first_vertex). On one process the numbering is the
/// serial mesh's: the local mesh of every level is the serially refined mesh itself.
#pragma once

#include "core/communicator.hpp"
#include "mesh/io/vtu.hpp"
#include "mesh/mesh.hpp"
#include "mesh/partition.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <utility>
#include <vector>

namespace mlc::mesh {

/// Where a vertex of a refined level lies on the partitioned level-p mesh.
struct Location {
    enum class Kind : std::uint8_t { vertex, edge, triangle };
    Kind kind = Kind::vertex;
    int id = -1; ///< level-p vertex, edge (DistributedHierarchy::edges) or triangle index
};

/// One level of one process's part.
struct LocalLevel {
    /// The local triangles (owned and ghost) with their vertices, boundary edges and lines.
    /// Level p: the local vertices in increasing level-p index order, the triangles in increasing
    /// level-p index order. Finer levels: refine() of the level above (children of local triangle
    /// t are 4t..4t+3, `parents` in local indices of the level above).
    Mesh mesh;
    std::vector<int> triangle_ancestor; ///< level-p triangle of every local triangle
    std::vector<char> triangle_owned;   ///< 1 where this process owns the triangle
    std::vector<Location> vertex_location;
    std::vector<int> vertex_owner;           ///< rank owning every local vertex
    std::vector<std::int64_t> global_vertex; ///< global number of every local vertex
    std::vector<int> owned_vertices;         ///< local indices of the owned vertices, in order
    std::int64_t first_vertex = 0;           ///< global number of owned_vertices[0]
    std::int64_t n_global_vertices = 0;      ///< vertices of this level over all processes
    std::int64_t n_global_triangles = 0;     ///< triangles of this level over all processes

    int n_owned_vertices() const { return static_cast<int>(owned_vertices.size()); }
    /// Local vertices owned by another process (the ghost vertices).
    int n_ghost_vertices() const { return mesh.n_vertices() - n_owned_vertices(); }
    /// First global row of this process's unknowns (two per vertex, interleaved).
    std::int64_t first_row() const { return 2 * first_vertex; }
};

/// A deeper ghost layer along a contact interface (two-body contact pairs): the
/// level-p triangles with a boundary edge tagged one of `tags` lying within `distance` of a
/// boundary edge tagged one of `tags` of a triangle of the one-layer local mesh become ghosts too
/// (with their refinements), so that the contact search of every local contact node, and of the
/// contact nodes of other processes whose elements reach an owned vertex, sees every target facet
/// it needs on every level.
struct GhostReach {
    std::vector<int> tags; ///< tags of the level-p mesh (contactor and target boundaries)
    double distance = 0.0; ///< (edge to edge, in the reference configuration)
};

/// One process's part of a hierarchy refined from a partitioned level p.
struct DistributedHierarchy {
    Partition partition; ///< of the level-p mesh, the same on every process
    /// The level-p edges (sorted vertex pairs) that Location::id of kind edge indexes.
    std::vector<std::array<int, 2>> edges;
    /// levels[k] is level p + k of this process's part, k = 0 .. n_refinements.
    std::vector<LocalLevel> levels;
    int rank = 0;
    int n_processes = 1;
};

/// Partitions `level_p` into comm.size() parts (partition_triangles with `weights`, e.g. the
/// number of finest triangles each stands for: all equal under uniform refinement) and builds
/// this process's part of it and of its `n_refinements` uniform refinements.
///
/// Collective: every process calls it with the same mesh, refinements, weights and reach.
/// `level_p` must pass check_quality. Throws InvalidInput for n_refinements < 0 or more processes
/// than triangles, on every process alike. `reach` (GhostReach) widens the ghost layer along
/// contact interfaces; empty: the one-triangle layer.
DistributedHierarchy distribute(const Mesh& level_p, int n_refinements, const Communicator& comm,
                                const std::vector<int>& weights = {},
                                const std::vector<GhostReach>& reach = {});

/// The name of process `rank`'s piece of the parallel file `file`: "<stem>_<rank>.vtu" in the
/// folder of `file` (solution.pvtu -> solution_0.vtu, solution_1.vtu, ...).
std::filesystem::path piece_path(const std::filesystem::path& file, int rank);

/// Writes a distributed level as one mesh: `file` (a .pvtu) and one .vtu piece
/// per process (piece_path), which ParaView and vtkXMLPUnstructuredGridReader open as one mesh.
///
/// Each process writes its owned triangles (triangle_owned) and the vertices they use, with
/// write_vtu and `format`; `point_fields` hold values on the local vertices of `L` and
/// `cell_fields` on its local triangles (as write_vtu expects them on L.mesh), and each piece
/// gets the values of what it holds. A vertex on a cut between processes appears in the pieces of
/// every process with a triangle around it, with the same coordinates and the values each
/// process holds for it. Once every piece is written, process 0 writes `file` listing the pieces
/// in rank order (its appearance means the set is complete).
///
/// Collective. If writing fails on any process, every process throws: the failing ones their own
/// error (InvalidInput for bad fields, std::runtime_error for I/O), the others a
/// std::runtime_error saying that another process failed; `file` is then not written.
void write_distributed_vtu(const std::filesystem::path& file, const LocalLevel& L,
                           const std::vector<Field>& point_fields,
                           const std::vector<Field>& cell_fields, const Communicator& comm,
                           VtuFormat format = VtuFormat::binary);

/// What the 2D and 3D hierarchies (mesh/distributed3.hpp) share.
namespace detail {

/// The global numbers of the vertices of one local level.
struct VertexNumbers {
    std::vector<std::int64_t> global_vertex; ///< of every local vertex
    std::vector<int> owned_vertices;         ///< local indices of the owned vertices, in order
    std::int64_t first_vertex = 0;           ///< global number of owned_vertices[0]
    std::int64_t n_global_vertices = 0;      ///< over all processes
};

/// Numbers the vertices of a level: the owned ones (vertex_owner == comm.rank()) in rank order
/// and local index order, the others asked of their owners by `keys`, which every process
/// computes alike for a vertex (the level-p index, or the global numbers of the two parents on
/// the level above) and which are unique within a level. Collective; throws InvalidInput when an
/// owner does not hold a vertex it owns.
VertexNumbers number_vertices(const std::vector<int>& vertex_owner,
                              const std::vector<std::pair<std::int64_t, std::int64_t>>& keys,
                              const Communicator& comm);

/// Runs write() on every process; if it threw on any, rethrows there and throws a
/// std::runtime_error "<what>: another process failed" elsewhere. Collective.
void on_every_process(const Communicator& comm, const char* what,
                      const std::function<void()>& write);

/// The values of `fields` on the entities `entities` (indices into each field's entities), in
/// that order: what a piece of a parallel file holds.
std::vector<Field> subset(const std::vector<Field>& fields, const std::vector<int>& entities);

} // namespace detail

} // namespace mlc::mesh
