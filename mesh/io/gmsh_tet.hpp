// SPDX-License-Identifier: MIT
/// @file Reader for Gmsh .msh tetrahedral meshes (ASCII formats 2.2 and 4.1).
#pragma once

#include "mesh/tet_mesh.hpp"

#include <filesystem>
#include <string>

namespace mlc::mesh {

/// Reads a P1 tetrahedral mesh from a Gmsh .msh file, ASCII format 2.2 or 4.1 (the parser of
/// read_gmsh, mesh/io/gmsh.hpp, with its messages for broken files).
///
/// - Tetrahedra: every 4-node tetrahedron (element type 4) of the selection, in the file's node
///   order. The selection is the physical volume named `volume` (or, for an unnamed physical
///   volume with tag N, `volume` = "tag<N>"), or all 3D elements when `volume` is empty.
///   Gmsh lists tetrahedra with positive volume; one with negative volume is inverted and
///   refused.
/// - Vertices: only those used by the selected tetrahedra, renumbered 0.. in the file's node
///   order.
/// - Bodies: TetMesh::attribute is the (first) physical volume tag of each tetrahedron, or empty
///   when the tetrahedra carry no physical volume. Either every selected tetrahedron is in a
///   physical volume or none is: a file with both is refused, naming the first tetrahedron in
///   none.
/// - Boundary: every 3-node triangle (type 2) in a physical surface that is a boundary face of
///   the selected tetrahedra becomes a BoundaryFace tagged with the physical name ("tag<N>" if
///   unnamed), turned so that its normal points out of the body. Triangles that are faces of
///   two selected tetrahedra (interfaces) or of none are ignored; a face in several physical
///   surfaces keeps the first.
///
/// Throws InvalidInput with the file name and line number for the defects read_gmsh names, and
/// for: no tetrahedra, selected 3D elements that are not 4-node tetrahedra (naming the type),
/// an unknown `volume` (listing the physical volumes present), an inverted tetrahedron; then
/// calls check_quality (flat, duplicated and folded elements, faces of over two tetrahedra,
/// non-manifold boundaries), each tetrahedron named by its line and node ids. Lengths are in
/// the file's units.
TetMesh read_gmsh_tet(const std::filesystem::path& file, const std::string& volume = "");

/// As read_gmsh_tet, from the text of a .msh file; `file` names it in messages only.
TetMesh read_gmsh_tet_text(const std::string& text, const std::filesystem::path& file,
                           const std::string& volume = "");

} // namespace mlc::mesh
