// SPDX-License-Identifier: MIT
// Hand-written VTK XML writers: everything is validated first, then streamed through a large
// buffer with std::to_chars into a temporary file that is renamed into place.
#include "mesh/io/vtu.hpp"

#include "mesh/io/vtu_grid.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/stop.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <set>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <zlib.h>

namespace mlc::mesh {

namespace {

/// Output through a 1 MiB buffer; numbers are formatted with std::to_chars (shortest form that
/// round-trips). Errors are remembered and reported by close().
class BufferedFile {
public:
    explicit BufferedFile(const std::filesystem::path& path)
        : file_(std::fopen(path.c_str(), "wb")), buf_(1 << 20) {}
    BufferedFile(const BufferedFile&) = delete;
    BufferedFile& operator=(const BufferedFile&) = delete;
    ~BufferedFile() {
        if (file_) std::fclose(file_);
    }

    bool is_open() const { return file_ != nullptr; }

    void put(std::string_view s) {
        if (buf_.size() - n_ < s.size()) flush();
        if (s.size() > buf_.size()) {
            failed_ |= std::fwrite(s.data(), 1, s.size(), file_) != s.size();
            return;
        }
        s.copy(buf_.data() + n_, s.size());
        n_ += s.size();
    }
    void put(char c) {
        if (n_ == buf_.size()) flush();
        buf_[n_++] = c;
    }
    template <class Number> void put_number(Number v) {
        if (buf_.size() - n_ < 32) flush();
        const auto r = std::to_chars(buf_.data() + n_, buf_.data() + buf_.size(), v);
        n_ = static_cast<std::size_t>(r.ptr - buf_.data());
    }

    /// Closes without writing what is buffered.
    void abandon() {
        n_ = 0;
        if (file_) std::fclose(file_);
        file_ = nullptr;
    }

    /// Flushes and closes; false if any write failed.
    bool close() {
        flush();
        const bool closed = std::fclose(file_) == 0;
        file_ = nullptr;
        return closed && !failed_;
    }

private:
    void flush() {
        // A stop requested while writes are stoppable (core/stop.hpp) abandons the file here,
        // within one buffer.
        if (write_stop_requested()) throw Interrupted("stopped while writing a VTU file");
        if (n_ > 0) failed_ |= std::fwrite(buf_.data(), 1, n_, file_) != n_;
        n_ = 0;
    }

    std::FILE* file_;
    std::vector<char> buf_;
    std::size_t n_ = 0;
    bool failed_ = false;
};

std::string xml_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&':
            out += "&amp;";
            break;
        case '<':
            out += "&lt;";
            break;
        case '>':
            out += "&gt;";
            break;
        case '"':
            out += "&quot;";
            break;
        case '\'':
            out += "&apos;";
            break;
        default:
            out += c;
        }
    }
    return out;
}

void check_fields(const std::vector<Field>& fields, const char* kind, const char* entity,
                  std::size_t n_entities) {
    std::set<std::string> names;
    for (const Field& f : fields) {
        MLC_CHECK(!f.name.empty(), "write_vtu: a " << kind << " field has an empty name");
        MLC_CHECK(names.insert(f.name).second,
                  "write_vtu: two " << kind << " fields are named '" << f.name << "'");
        MLC_CHECK(f.n_components >= 1, "write_vtu: " << kind << " field '" << f.name << "' has "
                                                     << f.n_components
                                                     << " components; expected >= 1");
        const std::size_t nc = static_cast<std::size_t>(f.n_components);
        MLC_CHECK(f.values.size() == n_entities * nc,
                  "write_vtu: " << kind << " field '" << f.name << "' has " << f.values.size()
                                << " values; expected " << n_entities << " " << entity << "s x "
                                << nc << " components = " << n_entities * nc);
        for (std::size_t i = 0; i < f.values.size(); ++i)
            MLC_CHECK(std::isfinite(f.values[i]),
                      "write_vtu: " << kind << " field '" << f.name << "' has the non-finite value "
                                    << f.values[i] << " at " << entity << " " << i / nc
                                    << ", component " << i % nc << "; nothing was written");
    }
}

void put_fields(BufferedFile& out, const std::vector<Field>& fields, const char* section) {
    out.put("      <");
    out.put(section);
    out.put(">\n");
    for (const Field& f : fields) {
        const int nc = f.n_components == 2 ? 3 : f.n_components;
        out.put("        <DataArray type=\"Float64\" Name=\"");
        out.put(xml_escape(f.name));
        out.put("\" NumberOfComponents=\"");
        out.put_number(nc);
        out.put("\" format=\"ascii\">\n");
        const std::size_t n = f.values.size() / static_cast<std::size_t>(f.n_components);
        for (std::size_t i = 0; i < n; ++i) {
            for (int c = 0; c < f.n_components; ++c) {
                if (c > 0) out.put(' ');
                out.put_number(f.values[i * static_cast<std::size_t>(f.n_components) +
                                        static_cast<std::size_t>(c)]);
            }
            if (f.n_components == 2) out.put(" 0");
            out.put('\n');
        }
        out.put("        </DataArray>\n");
    }
    out.put("      </");
    out.put(section);
    out.put(">\n");
}

/// Runs `write` on a temporary file next to `file` and renames it into place; on any failure
/// the temporary is removed and nothing is left at `file`'s path by us.
template <class Write>
void write_atomically(const std::filesystem::path& file, const char* who, Write&& write) {
    if (write_stop_requested())
        throw Interrupted(std::string(who) + ": stopped before writing '" + file.string() + "'");
    const std::filesystem::path tmp = temporary_path(file);
    RegisteredTemporary registered(tmp);
    BufferedFile out(tmp);
    MLC_CHECK(out.is_open(), who << ": cannot open '" << tmp.string()
                                 << "' for writing; does the directory exist and is it writable?");
    try {
        write(out);
        if (!out.close())
            throw std::runtime_error(std::string(who) + ": writing '" + tmp.string() +
                                     "' failed (disk full?)");
        std::error_code ec;
        std::filesystem::rename(tmp, file, ec);
        if (ec)
            throw std::runtime_error(std::string(who) + ": cannot rename '" + tmp.string() +
                                     "' to '" + file.string() + "': " + ec.message());
        registered.release();
    } catch (const Interrupted&) {
        out.abandon();
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw Interrupted(std::string(who) + ": stopped while writing '" + file.string() +
                          "' (the file was left as it was)");
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
    }
}

/// One array of the appended section: its opening DataArray attributes and its encoded bytes
/// (the UInt64 compression header followed by the zlib blocks).
struct AppendedArray {
    std::string attributes; ///< type, Name, NumberOfComponents (without format/offset)
    std::vector<unsigned char> encoded;
};

/// One zlib stream of `size` bytes at `in` (level 0: stored, a copy) into `out` (resized).
bool deflate_block(const unsigned char* in, std::size_t size, int level, int strategy,
                   std::vector<unsigned char>& out) {
    z_stream z{};
    if (deflateInit2(&z, level, Z_DEFLATED, 15, 8, strategy) != Z_OK) return false;
    out.resize(deflateBound(&z, static_cast<uLong>(size)));
    z.next_in = const_cast<unsigned char*>(in);
    z.avail_in = static_cast<uInt>(size);
    z.next_out = out.data();
    z.avail_out = static_cast<uInt>(out.size());
    const bool done = deflate(&z, Z_FINISH) == Z_STREAM_END;
    out.resize(z.total_out);
    deflateEnd(&z);
    return done;
}

/// An array of the appended section before compression.
struct RawArray {
    std::vector<unsigned char> bytes;
    /// Doubles of a solution field: compressed with Z_RLE (runs of zero bytes and repeated
    /// values; twice as fast as the default match search on these arrays for a few percent of
    /// size); geometry and integers with the default strategy (long repeated patterns).
    bool field = false;
};

/// Compresses each array the way vtkZLibDataCompressor does with header_type="UInt64": a
/// header [number of blocks, block size, size of the last block (0: full), compressed size of
/// each block] followed by the blocks (1 MiB each), each a zlib stream of its own. The blocks of
/// all arrays are compressed in parallel at level 1. A block whose first 16 KiB do not shrink
/// to half at level 1 is stored (level 0, a copy): the doubles of displacements, stresses and
/// von Mises have noisy mantissas and shrink little, at the cost of most of the compression
/// time, while the geometry, connectivity, offsets and the mostly-zero contact arrays shrink
/// many times. The file is a third of the ASCII one's size and written faster.
std::vector<std::vector<unsigned char>> zlib_encode(const std::vector<RawArray>& raws) {
    constexpr std::size_t block = 1 << 20, sample = 1 << 14;
    std::vector<std::pair<std::size_t, std::size_t>> tasks; // (array, first byte)
    for (std::size_t a = 0; a < raws.size(); ++a)
        for (std::size_t begin = 0; begin < raws[a].bytes.size(); begin += block)
            tasks.emplace_back(a, begin);
    std::vector<std::vector<unsigned char>> packed(tasks.size());
    bool ok = true;
#pragma omp parallel for schedule(dynamic) reduction(&& : ok)
    for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(tasks.size()); ++k) {
        const auto [a, begin] = tasks[static_cast<std::size_t>(k)];
        const unsigned char* in = raws[a].bytes.data() + begin;
        const std::size_t size = std::min(block, raws[a].bytes.size() - begin);
        const int strategy = raws[a].field ? Z_RLE : Z_DEFAULT_STRATEGY;
        auto& out = packed[static_cast<std::size_t>(k)];
        const std::size_t probe = std::min(sample, size);
        ok = ok && deflate_block(in, probe, 1, strategy, out);
        const int level =
            static_cast<double>(out.size()) > 0.5 * static_cast<double>(probe) ? 0 : 1;
        ok = ok && deflate_block(in, size, level, strategy, out);
    }
    if (!ok) throw std::runtime_error("write_vtu: zlib compression failed");
    std::vector<std::vector<unsigned char>> encoded(raws.size());
    std::size_t k = 0;
    for (std::size_t a = 0; a < raws.size(); ++a) {
        const std::size_t n = raws[a].bytes.size();
        const std::size_t n_blocks = (n + block - 1) / block;
        std::vector<std::uint64_t> header{n_blocks, block, n % block};
        for (std::size_t b = 0; b < n_blocks; ++b)
            header.push_back(packed[k + b].size());
        auto& out = encoded[a];
        out.resize(header.size() * sizeof(std::uint64_t));
        std::memcpy(out.data(), header.data(), out.size()); // little endian (checked)
        for (std::size_t b = 0; b < n_blocks; ++b, ++k) {
            out.insert(out.end(), packed[k].begin(), packed[k].end());
            std::vector<unsigned char>().swap(packed[k]);
        }
    }
    return encoded;
}

template <class T> std::vector<unsigned char> raw_bytes(const std::vector<T>& v) {
    std::vector<unsigned char> out(v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
    return out;
}

/// A field's DataArray attributes and its bytes as Float64, 2-component fields padded to 3
/// (z = 0).
std::pair<std::string, std::vector<unsigned char>> field_bytes(const Field& f) {
    const std::size_t nc = static_cast<std::size_t>(f.n_components);
    const std::size_t n = f.values.size() / nc;
    std::string attributes = "type=\"Float64\" Name=\"" + xml_escape(f.name) +
                             "\" NumberOfComponents=\"" + std::to_string(nc == 2 ? 3 : nc) + "\"";
    if (nc != 2) return {attributes, raw_bytes(f.values)};
    std::vector<double> padded(3 * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        padded[3 * i] = f.values[2 * i];
        padded[3 * i + 1] = f.values[2 * i + 1];
    }
    return {attributes, raw_bytes(padded)};
}

void put_appended_refs(BufferedFile& out, const std::vector<AppendedArray>& arrays,
                       std::size_t first, std::size_t count, std::uint64_t& offset) {
    for (std::size_t i = first; i < first + count; ++i) {
        out.put("        <DataArray ");
        out.put(arrays[i].attributes);
        out.put(" format=\"appended\" offset=\"");
        out.put_number(offset);
        out.put("\"/>\n");
        offset += arrays[i].encoded.size();
    }
}

} // namespace

namespace detail {

void check_vtu_fields(const std::vector<Field>& fields, const char* kind, const char* entity,
                      std::size_t n_entities) {
    check_fields(fields, kind, entity, n_entities);
}

void write_vtu_grid(const std::filesystem::path& file, VtuGrid grid,
                    const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields) {
    static_assert(sizeof(double) == 8);
    {
        const std::uint16_t one = 1;
        unsigned char first = 0;
        std::memcpy(&first, &one, 1);
        MLC_CHECK(first == 1, "write_vtu: binary output is written little endian only");
    }
    const std::size_t nv = grid.xyz.size() / 3, nt = grid.types.size();
    // Order in the file: point fields, cell fields, points, connectivity, offsets, types.
    std::vector<std::string> attributes;
    std::vector<RawArray> raws;
    for (const auto* fields : {&point_fields, &cell_fields})
        for (const Field& f : *fields) {
            auto [a, bytes] = field_bytes(f);
            attributes.push_back(std::move(a));
            raws.push_back({std::move(bytes), true});
        }
    attributes.emplace_back("type=\"Float64\" NumberOfComponents=\"3\"");
    raws.push_back({raw_bytes(grid.xyz)});
    attributes.emplace_back("type=\"Int32\" Name=\"connectivity\"");
    raws.push_back({raw_bytes(grid.connectivity)});
    attributes.emplace_back("type=\"Int64\" Name=\"offsets\"");
    raws.push_back({raw_bytes(grid.offsets)});
    attributes.emplace_back("type=\"UInt8\" Name=\"types\"");
    raws.push_back({raw_bytes(grid.types)});
    grid = VtuGrid{};
    std::vector<AppendedArray> arrays(raws.size());
    {
        auto encoded = zlib_encode(raws);
        std::vector<RawArray>().swap(raws);
        for (std::size_t a = 0; a < arrays.size(); ++a)
            arrays[a] = {std::move(attributes[a]), std::move(encoded[a])};
    }
    write_atomically(file, "write_vtu", [&](BufferedFile& out) {
        out.put("<?xml version=\"1.0\"?>\n"
                "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
                "byte_order=\"LittleEndian\" header_type=\"UInt64\" "
                "compressor=\"vtkZLibDataCompressor\">\n"
                "  <UnstructuredGrid>\n"
                "    <Piece NumberOfPoints=\"");
        out.put_number(nv);
        out.put("\" NumberOfCells=\"");
        out.put_number(nt);
        out.put("\">\n");
        std::uint64_t offset = 0;
        out.put("      <PointData>\n");
        put_appended_refs(out, arrays, 0, point_fields.size(), offset);
        out.put("      </PointData>\n      <CellData>\n");
        put_appended_refs(out, arrays, point_fields.size(), cell_fields.size(), offset);
        out.put("      </CellData>\n      <Points>\n");
        const std::size_t geometry = point_fields.size() + cell_fields.size();
        put_appended_refs(out, arrays, geometry, 1, offset);
        out.put("      </Points>\n      <Cells>\n");
        put_appended_refs(out, arrays, geometry + 1, 3, offset);
        out.put("      </Cells>\n"
                "    </Piece>\n"
                "  </UnstructuredGrid>\n"
                "  <AppendedData encoding=\"raw\">\n   _");
        for (const auto& a : arrays)
            out.put(std::string_view(reinterpret_cast<const char*>(a.encoded.data()),
                                     a.encoded.size()));
        out.put("\n  </AppendedData>\n"
                "</VTKFile>\n");
    });
}

} // namespace detail

namespace {

/// The triangles of a 2D mesh as a VtuGrid (points (x, y, 0), VTK_TRIANGLE).
void write_vtu_binary(const std::filesystem::path& file, const Mesh& m,
                      const std::vector<Field>& point_fields,
                      const std::vector<Field>& cell_fields) {
    const std::size_t nv = m.vertices.size(), nt = m.cells.size();
    detail::VtuGrid grid;
    grid.xyz.assign(3 * nv, 0.0);
    for (std::size_t v = 0; v < nv; ++v) {
        grid.xyz[3 * v] = m.vertices[v].x();
        grid.xyz[3 * v + 1] = m.vertices[v].y();
    }
    grid.connectivity.resize(3 * nt);
    grid.offsets.resize(nt);
    for (std::size_t t = 0; t < nt; ++t) {
        for (std::size_t k = 0; k < 3; ++k)
            grid.connectivity[3 * t + k] = m.cells[t][k];
        grid.offsets[t] = static_cast<std::int64_t>(3 * (t + 1));
    }
    grid.types.assign(nt, detail::kVtkTriangle);
    detail::write_vtu_grid(file, std::move(grid), point_fields, cell_fields);
}

} // namespace

const char* to_string(VtuFormat f) {
    return f == VtuFormat::binary ? "binary" : "ascii";
}

void write_vtu(const std::filesystem::path& file, const Mesh& m,
               const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields,
               VtuFormat format) {
    const std::size_t nv = m.vertices.size(), nt = m.cells.size();
    for (std::size_t v = 0; v < nv; ++v)
        MLC_CHECK(m.vertices[v].allFinite(),
                  "write_vtu: vertex " << v << " has a non-finite coordinate (" << m.vertices[v].x()
                                       << ", " << m.vertices[v].y() << "); nothing was written");
    for (std::size_t t = 0; t < nt; ++t)
        for (int k : m.cells[t])
            MLC_CHECK(k >= 0 && static_cast<std::size_t>(k) < nv,
                      "write_vtu: triangle " << t << " refers to vertex " << k
                                             << " but the mesh has " << nv << " vertices");
    check_fields(point_fields, "point", "vertex", nv);
    check_fields(cell_fields, "cell", "triangle", nt);
    if (format == VtuFormat::binary) {
        write_vtu_binary(file, m, point_fields, cell_fields);
        return;
    }

    write_atomically(file, "write_vtu", [&](BufferedFile& out) {
        out.put("<?xml version=\"1.0\"?>\n"
                "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
                "byte_order=\"LittleEndian\">\n"
                "  <UnstructuredGrid>\n"
                "    <Piece NumberOfPoints=\"");
        out.put_number(nv);
        out.put("\" NumberOfCells=\"");
        out.put_number(nt);
        out.put("\">\n");
        put_fields(out, point_fields, "PointData");
        put_fields(out, cell_fields, "CellData");
        out.put("      <Points>\n"
                "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
                "format=\"ascii\">\n");
        for (const Vec2& p : m.vertices) {
            out.put_number(p.x());
            out.put(' ');
            out.put_number(p.y());
            out.put(" 0\n");
        }
        out.put("        </DataArray>\n"
                "      </Points>\n"
                "      <Cells>\n"
                "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n");
        for (const auto& t : m.cells) {
            out.put_number(t[0]);
            out.put(' ');
            out.put_number(t[1]);
            out.put(' ');
            out.put_number(t[2]);
            out.put('\n');
        }
        out.put("        </DataArray>\n"
                "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
        for (std::size_t t = 0; t < nt; ++t) {
            out.put_number(3 * (t + 1));
            out.put((t % 16 == 15 || t + 1 == nt) ? '\n' : ' ');
        }
        out.put("        </DataArray>\n"
                "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
        for (std::size_t t = 0; t < nt; ++t)
            out.put((t % 32 == 31 || t + 1 == nt) ? "5\n" : "5 ");
        out.put("        </DataArray>\n"
                "      </Cells>\n"
                "    </Piece>\n"
                "  </UnstructuredGrid>\n"
                "</VTKFile>\n");
    });
}

void write_pvd(const std::filesystem::path& file,
               const std::vector<std::pair<double, std::string>>& steps) {
    for (std::size_t i = 0; i < steps.size(); ++i) {
        MLC_CHECK(std::isfinite(steps[i].first),
                  "write_pvd: step " << i << " has the non-finite time " << steps[i].first);
        MLC_CHECK(!steps[i].second.empty(), "write_pvd: step " << i << " has an empty file name");
    }
    write_atomically(file, "write_pvd", [&](BufferedFile& out) {
        out.put("<?xml version=\"1.0\"?>\n"
                "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                "  <Collection>\n");
        for (const auto& [time, name] : steps) {
            out.put("    <DataSet timestep=\"");
            out.put_number(time);
            out.put("\" group=\"\" part=\"0\" file=\"");
            out.put(xml_escape(name));
            out.put("\"/>\n");
        }
        out.put("  </Collection>\n"
                "</VTKFile>\n");
    });
}

void write_pvtu(const std::filesystem::path& file, const std::vector<std::string>& pieces,
                const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields) {
    MLC_CHECK(!pieces.empty(), "write_pvtu: no pieces for " << file);
    for (std::size_t i = 0; i < pieces.size(); ++i)
        MLC_CHECK(!pieces[i].empty(), "write_pvtu: piece " << i << " has an empty file name");
    for (const auto* fields : {&point_fields, &cell_fields})
        for (const Field& f : *fields) {
            MLC_CHECK(!f.name.empty(), "write_pvtu: a field has an empty name");
            MLC_CHECK(f.n_components >= 1, "write_pvtu: field '" << f.name << "' has "
                                                                 << f.n_components
                                                                 << " components");
        }
    // The arrays as write_vtu declares them: Float64, two components written as three.
    auto put_arrays = [](BufferedFile& out, const std::vector<Field>& fields, const char* tag) {
        out.put("    <");
        out.put(tag);
        out.put(">\n");
        for (const Field& f : fields) {
            out.put("      <PDataArray type=\"Float64\" Name=\"");
            out.put(xml_escape(f.name));
            out.put("\" NumberOfComponents=\"");
            out.put(std::to_string(f.n_components == 2 ? 3 : f.n_components));
            out.put("\"/>\n");
        }
        out.put("    </");
        out.put(tag);
        out.put(">\n");
    };
    write_atomically(file, "write_pvtu", [&](BufferedFile& out) {
        out.put("<?xml version=\"1.0\"?>\n"
                "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" "
                "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                "  <PUnstructuredGrid GhostLevel=\"0\">\n");
        put_arrays(out, point_fields, "PPointData");
        put_arrays(out, cell_fields, "PCellData");
        out.put("    <PPoints>\n"
                "      <PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n"
                "    </PPoints>\n");
        for (const auto& piece : pieces) {
            out.put("    <Piece Source=\"");
            out.put(xml_escape(piece));
            out.put("\"/>\n");
        }
        out.put("  </PUnstructuredGrid>\n"
                "</VTKFile>\n");
    });
}

} // namespace mlc::mesh
