// SPDX-License-Identifier: MIT
/// @file VTK XML UnstructuredGrid (.vtu) and ParaView collection (.pvd) writers, without VTK.
#pragma once

#include "mesh/mesh.hpp"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace mlc::mesh {

/// A named field on the points (vertices) or cells (triangles) of a mesh.
///
/// Values are interleaved by entity: values[i * n_components + c] is component c of entity i,
/// so values.size() must equal n_entities * n_components. A displacement vector (u_x, u_y) per
/// vertex, interleaved by node as the solvers store it, is a point field with n_components = 2.
struct Field {
    std::string name;           ///< shown in ParaView; non-empty, unique among point (cell) fields
    int n_components = 1;       ///< >= 1; 2 is written as a 3-vector (z = 0)
    std::vector<double> values; ///< n_entities * n_components entries, all finite
};

/// How write_vtu encodes the arrays.
enum class VtuFormat {
    /// Appended raw binary data, zlib-compressed in blocks (header_type="UInt64",
    /// compressor="vtkZLibDataCompressor"): what VTK's own writer produces by default. Doubles
    /// are stored bit for bit.
    binary,
    /// Every number as text inside its DataArray (format="ascii"); readable by eye.
    ascii
};

/// "binary" or "ascii".
const char* to_string(VtuFormat f);

/// Writes a mesh and fields as a VTK XML UnstructuredGrid file that ParaView opens.
///
/// Points are (x, y, 0); triangles are VTK_TRIANGLE (type 5) with the mesh's vertex order.
/// Two-component fields are written with three components (z = 0), so that ParaView's
/// "Warp By Vector" applies them directly. Both formats hold the same arrays with the same
/// values: binary stores every double bit for bit (Float64, connectivity Int32, offsets Int64,
/// types UInt8, each array compressed with zlib in blocks of 1 MiB, the blocks compressed in
/// parallel; a block that does not shrink to half is stored uncompressed, see vtu.cpp); ascii
/// writes numbers with std::to_chars in the shortest form that reads back to the same double, so
/// values round-trip exactly there too.
///
/// Everything is checked before the file is touched: field sizes against the mesh
/// (n_vertices * n_components for point fields, n_triangles * n_components for cell fields),
/// names, and that every value and coordinate is finite. A violation throws InvalidInput naming
/// the field, entity and component, and no file is created. The file is written to a temporary
/// next to it (core/atomic_file.hpp's temporary_path: unique to the process and the call) and
/// renamed at the end, so a reader never sees a half-written file; an I/O failure throws
/// std::runtime_error and removes the temporary. A stop requested while writes are stoppable
/// (core/stop.hpp) abandons the file within one 1 MiB buffer: mlc::Interrupted, the temporary
/// removed, the file left as it was.
void write_vtu(const std::filesystem::path& file, const Mesh& m,
               const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields,
               VtuFormat format = VtuFormat::binary);

/// Writes a ParaView collection (.pvd) listing a time series of .vtu files, e.g. load steps.
///
/// steps[i] = (time or load parameter, path of the .vtu file as ParaView should find it; a
/// relative path is relative to the directory of the .pvd file). Times must be finite and paths
/// non-empty; throws InvalidInput otherwise (before creating any file).
void write_pvd(const std::filesystem::path& file,
               const std::vector<std::pair<double, std::string>>& steps);

/// Writes a parallel UnstructuredGrid (.pvtu): one mesh made of the .vtu pieces `pieces` (paths
/// as ParaView should find them; a relative path is relative to the folder of the .pvtu), as
/// VTK's vtkXMLPUnstructuredGridReader and ParaView read it. The pieces are write_vtu files
/// written with fields of the names and component counts of `point_fields` and `cell_fields`
/// (only those two are read here: the values may be empty). Checks before touching the file:
/// at least one piece, non-empty piece names and field names, n_components >= 1; throws
/// InvalidInput otherwise. Written atomically, like write_vtu.
void write_pvtu(const std::filesystem::path& file, const std::vector<std::string>& pieces,
                const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields);

} // namespace mlc::mesh
