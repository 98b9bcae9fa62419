// SPDX-License-Identifier: MIT
/// @file Reader for Gmsh .msh triangle meshes (ASCII formats 2.2 and 4.1).
#pragma once

#include "mesh/mesh.hpp"

#include <filesystem>
#include <ostream>
#include <string>

namespace mlc::mesh {

/// Reads a planar P1 triangle mesh from a Gmsh .msh file, ASCII format 2.2 or 4.1.
///
/// - Triangles: every 3-node triangle (element type 2) of the selection; clockwise ones are
///   re-oriented counter-clockwise. The selection is the physical surface named `surface` (or,
///   for an unnamed physical surface with tag N, `surface` = "tag<N>"), or all 2D elements when
///   `surface` is empty, which is how one body is taken out of a file holding several.
/// - Vertices: only those used by the selected triangles, renumbered 0.. in the file's node order.
///   Their z coordinate must be 0 (to 1e-10 of the mesh size).
/// - Boundary: every 2-node line (type 1) in a physical curve that is a boundary edge of the
///   selected triangles becomes a BoundaryEdge tagged with the physical name ("tag<N>" if
///   unnamed), oriented counter-clockwise around the body; `curve` = -1. A line in a physical
///   curve that is an interior edge of the selection (an edge of two selected triangles) becomes
///   a tagged interior line (Mesh::lines) with that name. Lines elsewhere (on other bodies, or
///   not edges of the selection) are ignored; an edge in several physical curves keeps the first.
///   Boundary edges in no physical curve are not listed.
/// - Mesh::attribute: the (first) physical surface tag of each triangle, or empty when the
///   triangles carry no physical surface.
///
/// Throws InvalidInput with the file name and line number for: binary files, versions other than
/// 2.x and 4.1, truncated sections or files, counts that disagree with the data, unknown node
/// ids, duplicate node ids, degenerate triangles, unknown element types; and, naming the type,
/// for selected elements that are not 3-node triangles (quadratic triangles, quadrangles, 3D
/// elements). An unknown `surface` throws listing the physical surfaces present. Calls
/// check_quality on the result. Lengths are in the file's units.
Mesh read_gmsh(const std::filesystem::path& file, const std::string& surface = "");

/// As read_gmsh, from the text of a .msh file (a mesh embedded in the program); `file` names it in
/// messages only.
Mesh read_gmsh_text(const std::string& text, const std::filesystem::path& file,
                    const std::string& surface = "");

/// Writes `m` as an ASCII Gmsh 2.2 file that read_gmsh reads back to the same mesh: its vertices
/// (z = 0) and triangles, and its tagged boundary edges and interior lines as 2-node lines in
/// physical curves named after their tags (physical tag = tag id + 1). Triangles carry physical
/// surface 1 + their attribute (named "body<attribute>") when the mesh has attributes, none
/// otherwise. Circles (curved-boundary data) and refinement parents are not written: the file
/// is a level-0 mesh. Used to export a refined level as a fine mesh with no levels.
void write_gmsh(const Mesh& m, std::ostream& os);

} // namespace mlc::mesh
