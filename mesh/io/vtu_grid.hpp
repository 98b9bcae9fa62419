// SPDX-License-Identifier: MIT
/// @file What the VTU writers of 2D and tetrahedral meshes share (mesh/io/vtu.cpp): the cells of
/// an unstructured grid as VTK stores them, and the binary writer of such a grid with its fields.
#pragma once

#include "mesh/io/vtu.hpp"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace mlc::mesh::detail {

/// VTK cell types.
inline constexpr std::uint8_t kVtkTriangle = 5;
inline constexpr std::uint8_t kVtkTetra = 10;

/// An unstructured grid as VTK stores it.
struct VtuGrid {
    std::vector<double> xyz;                ///< 3 coordinates per point
    std::vector<std::int32_t> connectivity; ///< the points of every cell, cell after cell
    std::vector<std::int64_t> offsets;      ///< end of each cell in connectivity
    std::vector<std::uint8_t> types;        ///< VTK cell type of each cell
};

/// Checks fields against n_entities (write_vtu's messages, `kind` "point" or "cell", `entity`
/// e.g. "vertex" or "tetrahedron"); throws InvalidInput.
void check_vtu_fields(const std::vector<Field>& fields, const char* kind, const char* entity,
                      std::size_t n_entities);

/// Writes the grid and fields (already checked) as write_vtu's binary format does: appended raw
/// data, zlib-compressed, arrays in the order point fields, cell fields, points, connectivity,
/// offsets, types; atomically (a temporary renamed).
void write_vtu_grid(const std::filesystem::path& file, VtuGrid grid,
                    const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields);

} // namespace mlc::mesh::detail
