// SPDX-License-Identifier: MIT
/// @file The strict parser of Gmsh .msh files (ASCII 2.2 and 4.1) that read_gmsh (triangles,
/// mesh/io/gmsh.hpp) and read_gmsh_tet (tetrahedra, mesh/io/gmsh_tet.hpp) share: nodes,
/// elements and physical groups as in the file, before any selection.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mlc::mesh::gmsh_io {

/// What the readers need to know about a Gmsh element type.
struct ElementType {
    int dim = -1;
    int n_nodes = 0;
    const char* name = "";
};

/// Everything read from the file, before selection. Elements are stored flat: element e has
/// nodes node_ids[node_begin[e] .. node_begin[e+1]) and physical tags
/// phys[phys_begin[e] .. phys_begin[e+1]).
struct MshData {
    std::vector<std::int64_t> node_id;
    std::vector<Eigen::Vector3d> node_x;
    std::vector<int> node_line;
    std::vector<int> elem_type, elem_line;
    std::vector<std::size_t> node_begin{0}, phys_begin{0};
    std::vector<std::int64_t> node_ids;
    std::vector<int> phys;
    std::map<std::pair<int, int>, std::string> names;            // (dim, physical tag) -> name
    std::map<std::pair<int, int>, std::vector<int>> entity_phys; // 4.1: (dim, entity) -> tags

    std::size_t n_elements() const { return elem_type.size(); }
};

/// Gmsh element type `type` (gmsh.info, "MSH file format"); dim -1 for an unknown type.
ElementType msh_element_type(int type);

/// The whole text of a .msh file; InvalidInput if it cannot be opened or is not a regular file.
std::string read_msh_file(const std::filesystem::path& file);

/// Parses the text of a .msh file; InvalidInput "read_gmsh: <file>:<line>: ..." for every
/// defect of the format (see read_gmsh).
MshData parse_msh(const std::filesystem::path& file, std::string text);

} // namespace mlc::mesh::gmsh_io
