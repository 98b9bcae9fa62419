// SPDX-License-Identifier: MIT
/// @file VTU output of tetrahedral meshes: the tetrahedra with point and cell fields, and the
/// tagged boundary faces as a file of their own. Series of steps: write_pvd (mesh/io/vtu.hpp).
#pragma once

#include "mesh/io/vtu.hpp"
#include "mesh/tet_mesh.hpp"

#include <filesystem>
#include <vector>

namespace mlc::mesh {

/// Writes a tetrahedral mesh and fields as a binary VTK XML UnstructuredGrid (the format and
/// guarantees of write_vtu for 2D meshes, mesh/io/vtu.hpp: appended zlib-compressed arrays,
/// doubles bit for bit, checks before the file is touched, written atomically).
///
/// Points are the vertices (x, y, z); cells the tetrahedra as VTK_TETRA (type 10) in the mesh's
/// vertex order (either orientation: VTK takes the volume's absolute value). Point fields have
/// n_vertices * n_components values (a displacement: 3 components interleaved per vertex; 2
/// components are written as 3 with z = 0); cell fields n_tetrahedra * n_components. The cell
/// field "body" (TetMesh::attribute, 0 for a mesh without attributes) is written first; a cell
/// field of that name in `cell_fields` is refused. Throws InvalidInput naming the defect (a
/// non-finite coordinate, a vertex index out of range, a field of the wrong size or with a
/// non-finite value) before creating any file.
void write_vtu(const std::filesystem::path& file, const TetMesh& m,
               const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields);

/// Writes the tagged boundary faces (TetMesh::boundary) of a tetrahedral mesh as a binary VTU:
/// all the mesh's vertices as points (so the same point fields apply, e.g. a displacement for
/// "Warp By Vector"), the faces as VTK_TRIANGLE (type 5) oriented outwards, with the cell
/// fields "tag" (the tag id; names in TetMesh::tag_names) and "surface" (index into
/// TetMesh::surfaces, -1 for a flat face), then `cell_fields` (n_faces * n_components values;
/// the names "tag" and "surface" are refused). Same checks and guarantees as write_vtu.
void write_boundary_vtu(const std::filesystem::path& file, const TetMesh& m,
                        const std::vector<Field>& point_fields,
                        const std::vector<Field>& cell_fields = {});

} // namespace mlc::mesh
