// SPDX-License-Identifier: MIT
// Gmsh .msh reader: a strict line-by-line parser of the ASCII formats 2.2 and 4.1 that collects
// nodes and elements, then selects triangles and boundary lines.
#include "mesh/io/gmsh.hpp"
#include "mesh/io/gmsh_parse.hpp"
#include "mesh/topology.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace mlc::mesh {

namespace {

using gmsh_io::ElementType;

/// Gmsh element types (gmsh.info, "MSH file format"); dim -1 for an unknown type.
ElementType element_type(int type) {
    switch (type) {
    case 1:
        return {1, 2, "2-node line"};
    case 2:
        return {2, 3, "3-node triangle"};
    case 3:
        return {2, 4, "4-node quadrangle"};
    case 4:
        return {3, 4, "4-node tetrahedron"};
    case 5:
        return {3, 8, "8-node hexahedron"};
    case 6:
        return {3, 6, "6-node prism"};
    case 7:
        return {3, 5, "5-node pyramid"};
    case 8:
        return {1, 3, "3-node line"};
    case 9:
        return {2, 6, "6-node triangle"};
    case 10:
        return {2, 9, "9-node quadrangle"};
    case 11:
        return {3, 10, "10-node tetrahedron"};
    case 12:
        return {3, 27, "27-node hexahedron"};
    case 13:
        return {3, 18, "18-node prism"};
    case 14:
        return {3, 14, "14-node pyramid"};
    case 15:
        return {0, 1, "point"};
    case 16:
        return {2, 8, "8-node quadrangle"};
    case 17:
        return {3, 20, "20-node hexahedron"};
    case 18:
        return {3, 15, "15-node prism"};
    case 19:
        return {3, 13, "13-node pyramid"};
    case 20:
        return {2, 9, "9-node triangle"};
    case 21:
        return {2, 10, "10-node triangle"};
    case 22:
        return {2, 12, "12-node triangle"};
    case 23:
        return {2, 15, "15-node triangle"};
    case 24:
        return {2, 15, "15-node incomplete triangle"};
    case 25:
        return {2, 21, "21-node triangle"};
    case 26:
        return {1, 4, "4-node line"};
    case 27:
        return {1, 5, "5-node line"};
    case 28:
        return {1, 6, "6-node line"};
    case 29:
        return {3, 20, "20-node tetrahedron"};
    case 30:
        return {3, 35, "35-node tetrahedron"};
    case 31:
        return {3, 56, "56-node tetrahedron"};
    case 92:
        return {3, 64, "64-node hexahedron"};
    case 93:
        return {3, 125, "125-node hexahedron"};
    default:
        return {};
    }
}

using gmsh_io::MshData;

/// Line-by-line reader that knows where it is, for error messages.
class Reader {
public:
    Reader(const std::filesystem::path& file, std::string text)
        : file_(file.string()), text_(std::move(text)) {}

    /// Next line (without the line break), or false at the end of the file.
    bool next(std::string_view& line) {
        if (pos_ >= text_.size()) return false;
        std::size_t end = text_.find('\n', pos_);
        if (end == std::string::npos) end = text_.size();
        line = std::string_view(text_).substr(pos_, end - pos_);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos_ = end + 1;
        ++line_no_;
        return true;
    }

    /// Next line that is not blank; fails with "unexpected end of file <where>".
    std::string_view need(const char* where) {
        std::string_view line;
        do {
            if (!next(line)) fail(std::string("unexpected end of file ") + where);
        } while (line.find_first_not_of(" \t") == std::string_view::npos);
        return line;
    }

    /// Splits the next non-blank line into whitespace-separated tokens.
    const std::vector<std::string_view>& tokens(const char* where) {
        const std::string_view line = need(where);
        tokens_.clear();
        std::size_t i = 0;
        while (true) {
            i = line.find_first_not_of(" \t", i);
            if (i == std::string_view::npos) break;
            std::size_t j = line.find_first_of(" \t", i);
            if (j == std::string_view::npos) j = line.size();
            tokens_.push_back(line.substr(i, j - i));
            i = j;
        }
        return tokens_;
    }

    /// Consumes the line "$End<section>".
    void end(const std::string& section) {
        const std::string_view line = trim(need(("in $" + section).c_str()));
        if (line != "$End" + section)
            fail("expected $End" + section + " but found '" + std::string(line.substr(0, 60)) +
                 "' (the section holds more entries than its count says)");
    }

    template <class Int> Int to_int(std::string_view s, const char* what) const {
        Int v{};
        const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        if (r.ec != std::errc() || r.ptr != s.data() + s.size())
            fail(std::string("expected an integer (") + what + ") but found '" + std::string(s) +
                 "'");
        return v;
    }

    double to_double(std::string_view s, const char* what) const {
        double v = 0;
        const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v))
            fail(std::string("expected a finite number (") + what + ") but found '" +
                 std::string(s) + "'");
        return v;
    }

    /// A count that must be non-negative and not absurdly large for the file.
    std::size_t to_count(std::string_view s, const char* what) const {
        const auto v = to_int<std::int64_t>(s, what);
        if (v < 0 || static_cast<std::uint64_t>(v) > text_.size())
            fail(std::string("invalid count ") + std::string(s) + " (" + what + ")");
        return static_cast<std::size_t>(v);
    }

    void need_tokens(const std::vector<std::string_view>& t, std::size_t n, const char* what) {
        if (t.size() < n)
            fail(std::string("expected ") + std::to_string(n) + " entries (" + what +
                 ") but found " + std::to_string(t.size()) +
                 (t.size() == 1 && t[0].front() == '$' ? " (the section ends early)" : ""));
    }

    [[noreturn]] void fail(const std::string& msg) const { fail_at(line_no_, msg); }
    [[noreturn]] void fail_at(int line, const std::string& msg) const {
        throw InvalidInput("read_gmsh: " + file_ + ":" + std::to_string(line) + ": " + msg);
    }

    int line_no() const { return line_no_; }

    static std::string_view trim(std::string_view s) {
        const std::size_t a = s.find_first_not_of(" \t");
        if (a == std::string_view::npos) return {};
        const std::size_t b = s.find_last_not_of(" \t");
        return s.substr(a, b - a + 1);
    }

private:
    std::string file_;
    std::string text_;
    std::size_t pos_ = 0;
    int line_no_ = 0;
    std::vector<std::string_view> tokens_;
};

void read_physical_names(Reader& in, MshData& d) {
    const std::size_t n = in.to_count(in.tokens("in $PhysicalNames")[0], "number of names");
    for (std::size_t i = 0; i < n; ++i) {
        const std::string_view line = Reader::trim(in.need("in $PhysicalNames"));
        // dim tag "name with spaces"
        const std::size_t q0 = line.find('"'), q1 = line.rfind('"');
        if (q0 == std::string_view::npos || q1 == q0)
            in.fail("expected 'dim tag \"name\"' in $PhysicalNames but found '" +
                    std::string(line) + "'");
        std::istringstream head{std::string(line.substr(0, q0))};
        std::string dim_s, tag_s, rest;
        head >> dim_s >> tag_s >> rest;
        if (tag_s.empty() || !rest.empty())
            in.fail("expected 'dim tag \"name\"' in $PhysicalNames but found '" +
                    std::string(line) + "'");
        const int dim = in.to_int<int>(dim_s, "physical dimension");
        const int tag = in.to_int<int>(tag_s, "physical tag");
        d.names[{dim, tag}] = std::string(line.substr(q0 + 1, q1 - q0 - 1));
    }
    in.end("PhysicalNames");
}

void read_entities_41(Reader& in, MshData& d) {
    const auto& head = in.tokens("in $Entities");
    in.need_tokens(head, 4, "numPoints numCurves numSurfaces numVolumes");
    std::size_t count[4];
    for (int k = 0; k < 4; ++k)
        count[k] = in.to_count(head[k], "number of entities");
    for (int dim = 0; dim < 4; ++dim)
        for (std::size_t i = 0; i < count[dim]; ++i) {
            const auto& t = in.tokens("in $Entities");
            // point: tag x y z nphys ...; others: tag minx miny minz maxx maxy maxz nphys ...
            const std::size_t at = dim == 0 ? 4 : 7;
            in.need_tokens(t, at + 1, "entity tag, bounding box, number of physical tags");
            const int tag = in.to_int<int>(t[0], "entity tag");
            const std::size_t n_phys = in.to_count(t[at], "number of physical tags");
            in.need_tokens(t, at + 1 + n_phys, "physical tags");
            auto& tags = d.entity_phys[{dim, tag}];
            for (std::size_t k = 0; k < n_phys; ++k)
                tags.push_back(in.to_int<int>(t[at + 1 + k], "physical tag"));
        }
    in.end("Entities");
}

void add_node(Reader& in, MshData& d, std::int64_t id, const std::vector<std::string_view>& t,
              std::size_t first) {
    d.node_id.push_back(id);
    d.node_x.emplace_back(in.to_double(t[first], "x"), in.to_double(t[first + 1], "y"),
                          in.to_double(t[first + 2], "z"));
    d.node_line.push_back(in.line_no());
}

void read_nodes_22(Reader& in, MshData& d) {
    const std::size_t n = in.to_count(in.tokens("in $Nodes")[0], "number of nodes");
    for (std::size_t i = 0; i < n; ++i) {
        const auto& t = in.tokens("in $Nodes");
        in.need_tokens(t, 4, "node id x y z");
        add_node(in, d, in.to_int<std::int64_t>(t[0], "node id"), t, 1);
    }
    in.end("Nodes");
}

void read_nodes_41(Reader& in, MshData& d) {
    const auto& head = in.tokens("in $Nodes");
    in.need_tokens(head, 4, "numEntityBlocks numNodes minNodeTag maxNodeTag");
    const std::size_t n_blocks = in.to_count(head[0], "number of entity blocks");
    const std::size_t n_nodes = in.to_count(head[1], "number of nodes");
    std::size_t total = 0;
    std::vector<std::int64_t> ids;
    for (std::size_t b = 0; b < n_blocks; ++b) {
        const auto& bt = in.tokens("in $Nodes");
        in.need_tokens(bt, 4, "entityDim entityTag parametric numNodesInBlock");
        const std::size_t n = in.to_count(bt[3], "number of nodes in block");
        ids.clear();
        for (std::size_t i = 0; i < n; ++i) {
            const auto& t = in.tokens("in $Nodes");
            if (t.size() != 1) in.fail("expected one node tag per line in a $Nodes block");
            ids.push_back(in.to_int<std::int64_t>(t[0], "node tag"));
        }
        for (std::size_t i = 0; i < n; ++i) {
            const auto& t = in.tokens("in $Nodes");
            in.need_tokens(t, 3, "x y z");
            add_node(in, d, ids[i], t, 0);
        }
        total += n;
    }
    if (total != n_nodes)
        in.fail("the $Nodes header announces " + std::to_string(n_nodes) + " nodes but its " +
                "blocks hold " + std::to_string(total));
    in.end("Nodes");
}

/// Appends one element; `t` holds its node ids from position `first`.
void add_element(Reader& in, MshData& d, int type, const std::vector<std::string_view>& t,
                 std::size_t first, const std::vector<int>& phys) {
    const ElementType et = element_type(type);
    if (et.dim < 0) in.fail("unknown element type " + std::to_string(type));
    if (t.size() != first + static_cast<std::size_t>(et.n_nodes))
        in.fail("element type " + std::to_string(type) + " (" + et.name + ") needs " +
                std::to_string(et.n_nodes) + " node ids but the line has " +
                std::to_string(static_cast<long>(t.size()) - static_cast<long>(first)));
    d.elem_type.push_back(type);
    d.elem_line.push_back(in.line_no());
    for (std::size_t k = first; k < t.size(); ++k)
        d.node_ids.push_back(in.to_int<std::int64_t>(t[k], "node id"));
    d.node_begin.push_back(d.node_ids.size());
    d.phys.insert(d.phys.end(), phys.begin(), phys.end());
    d.phys_begin.push_back(d.phys.size());
}

void read_elements_22(Reader& in, MshData& d) {
    const std::size_t n = in.to_count(in.tokens("in $Elements")[0], "number of elements");
    std::vector<int> phys;
    for (std::size_t i = 0; i < n; ++i) {
        const auto& t = in.tokens("in $Elements");
        in.need_tokens(t, 3, "id type ntags");
        const int type = in.to_int<int>(t[1], "element type");
        const std::size_t n_tags = in.to_count(t[2], "number of tags");
        in.need_tokens(t, 3 + n_tags, "element tags");
        phys.clear();
        // The first tag is the physical group (0: none), the second the elementary entity.
        if (n_tags >= 1) {
            const int p = in.to_int<int>(t[3], "physical tag");
            if (p != 0) phys.push_back(p);
        }
        add_element(in, d, type, t, 3 + n_tags, phys);
    }
    in.end("Elements");
}

void read_elements_41(Reader& in, MshData& d) {
    const auto& head = in.tokens("in $Elements");
    in.need_tokens(head, 4, "numEntityBlocks numElements minElementTag maxElementTag");
    const std::size_t n_blocks = in.to_count(head[0], "number of entity blocks");
    const std::size_t n_elements = in.to_count(head[1], "number of elements");
    std::size_t total = 0;
    for (std::size_t b = 0; b < n_blocks; ++b) {
        const auto& bt = in.tokens("in $Elements");
        in.need_tokens(bt, 4, "entityDim entityTag elementType numElementsInBlock");
        const int dim = in.to_int<int>(bt[0], "entity dimension");
        const int entity = in.to_int<int>(bt[1], "entity tag");
        const int type = in.to_int<int>(bt[2], "element type");
        const std::size_t n = in.to_count(bt[3], "number of elements in block");
        const auto it = d.entity_phys.find({dim, entity});
        const std::vector<int> phys = it == d.entity_phys.end() ? std::vector<int>{} : it->second;
        for (std::size_t i = 0; i < n; ++i)
            add_element(in, d, type, in.tokens("in $Elements"), 1, phys);
        total += n;
    }
    if (total != n_elements)
        in.fail("the $Elements header announces " + std::to_string(n_elements) +
                " elements but its blocks hold " + std::to_string(total));
    in.end("Elements");
}

std::string read_file(const std::filesystem::path& file) {
    std::ifstream stream(file, std::ios::binary);
    MLC_CHECK(stream.good(), "read_gmsh: cannot open '" << file.string() << "'");
    // The whole file is read into memory: a device (/dev/zero) or a pipe would never end.
    MLC_CHECK(std::filesystem::is_regular_file(file),
              "read_gmsh: '" << file.string() << "' is not a regular file");
    std::stringstream buffer;
    buffer << stream.rdbuf();
    return buffer.str();
}

MshData parse(const std::filesystem::path& file, std::string text) {
    Reader in(file, std::move(text));

    MshData d;
    int version = 0; // 2 or 41
    bool have_nodes = false, have_elements = false;
    std::string_view line;
    while (in.next(line)) {
        line = Reader::trim(line);
        if (line.empty()) continue;
        if (line.front() != '$')
            in.fail("expected a section such as $Nodes but found '" +
                    std::string(line.substr(0, 60)) + "'");
        const std::string section(line.substr(1));
        if (section.rfind("End", 0) == 0) in.fail("unexpected '" + std::string(line) + "'");
        if (section == "MeshFormat") {
            const auto& t = in.tokens("in $MeshFormat");
            in.need_tokens(t, 3, "version file-type data-size");
            const std::string v(t[0]);
            if (t[1] != "0")
                in.fail("binary .msh files are not supported; save the mesh as ASCII (Gmsh "
                        "option Mesh.Binary = 0)");
            if (v == "4.1")
                version = 41;
            else if (v == "2" || v.rfind("2.", 0) == 0)
                version = 2;
            else
                in.fail("unsupported .msh version " + v +
                        "; save the mesh in format 2.2 or 4.1 (Gmsh option Mesh.MshFileVersion)");
            in.end("MeshFormat");
            continue;
        }
        if (version == 0) in.fail("the file does not start with $MeshFormat; is it a .msh file?");
        if (section == "PhysicalNames") {
            read_physical_names(in, d);
        } else if (section == "Entities" && version == 41) {
            read_entities_41(in, d);
        } else if (section == "PartitionedEntities") {
            in.fail("partitioned meshes are not supported; save the mesh unpartitioned");
        } else if (section == "Nodes") {
            if (have_nodes) in.fail("a second $Nodes section");
            version == 41 ? read_nodes_41(in, d) : read_nodes_22(in, d);
            have_nodes = true;
        } else if (section == "Elements") {
            if (have_elements) in.fail("a second $Elements section");
            version == 41 ? read_elements_41(in, d) : read_elements_22(in, d);
            have_elements = true;
        } else {
            // Sections we do not need ($Periodic, $NodeData, $Comments, ...): skip to their end.
            const int start = in.line_no();
            std::string_view skip;
            while (true) {
                if (!in.next(skip))
                    in.fail_at(start, "section $" + section + " is not closed by $End" + section);
                if (Reader::trim(skip) == "$End" + section) break;
            }
        }
    }
    if (version == 0) in.fail("empty file or no $MeshFormat section");
    if (!have_nodes) in.fail("the file has no $Nodes section");
    if (!have_elements) in.fail("the file has no $Elements section");
    return d;
}

std::uint64_t edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

/// The file's nodes by id, with the messages' prefix `where`.
class NodeLookup {
public:
    NodeLookup(const MshData& d, const std::string& where) : d_(d), where_(where) {
        index_.reserve(d.node_id.size());
        for (std::size_t i = 0; i < d.node_id.size(); ++i)
            MLC_CHECK(index_.emplace(d.node_id[i], static_cast<int>(i)).second,
                      where << ":" << d.node_line[i] << ": node id " << d.node_id[i]
                            << " appears twice");
    }
    /// The file's index of node k of element e.
    int operator()(std::size_t e, std::size_t k) const {
        const std::int64_t id = d_.node_ids[d_.node_begin[e] + k];
        auto it = index_.find(id);
        MLC_CHECK(it != index_.end(), where_ << ":" << d_.elem_line[e]
                                             << ": element refers to node id " << id
                                             << ", which is not in $Nodes");
        return it->second;
    }

private:
    const MshData& d_;
    const std::string& where_;
    std::unordered_map<std::int64_t, int> index_;
};

/// The physical surface named `surface` (or "tagN" for an unnamed surface N); 0 for all.
int wanted_surface(const MshData& d, const std::string& surface, const std::string& where) {
    if (surface.empty()) return 0;
    int wanted = 0;
    std::set<int> surfaces;
    for (std::size_t e = 0; e < d.n_elements(); ++e)
        if (element_type(d.elem_type[e]).dim == 2)
            for (std::size_t k = d.phys_begin[e]; k < d.phys_begin[e + 1]; ++k)
                surfaces.insert(d.phys[k]);
    bool found = false;
    for (const auto& [key, name] : d.names)
        if (key.first == 2 && name == surface) {
            wanted = key.second;
            found = true;
        }
    for (int s : surfaces)
        if (!found && surface == "tag" + std::to_string(s) && !d.names.count({2, s})) {
            wanted = s;
            found = true;
        }
    if (!found) {
        std::ostringstream known;
        for (int s : surfaces) {
            auto it = d.names.find({2, s});
            known << " '" << (it == d.names.end() ? "tag" + std::to_string(s) : it->second) << "'";
        }
        MLC_CHECK(false, where << ": no physical surface '" << surface << "'; the file has:"
                               << (surfaces.empty() ? " none" : "") << known.str());
    }
    return wanted;
}

/// The selected triangles (in node indices of the file) and the candidate boundary lines.
struct Selection {
    std::vector<std::array<int, 3>> tris;
    std::vector<int> tri_phys;
    std::vector<std::size_t> tri_element, lines;
};

Selection select_elements(const MshData& d, const NodeLookup& node, const std::string& surface,
                          int wanted, const std::string& where) {
    auto has_phys = [&](std::size_t e, int p) {
        for (std::size_t k = d.phys_begin[e]; k < d.phys_begin[e + 1]; ++k)
            if (d.phys[k] == p) return true;
        return false;
    };
    Selection s;
    for (std::size_t e = 0; e < d.n_elements(); ++e) {
        const int type = d.elem_type[e];
        const ElementType et = element_type(type);
        for (std::size_t k = 0; k < static_cast<std::size_t>(et.n_nodes); ++k)
            node(e, k);
        // All elements of dimension >= 1 but 2-node lines, or the wanted surface's elements.
        const bool selected =
            surface.empty() ? et.dim >= 1 && type != 1 : et.dim == 2 && has_phys(e, wanted);
        if (type == 1 && d.phys_begin[e + 1] > d.phys_begin[e]) s.lines.push_back(e);
        if (!selected) continue;
        MLC_CHECK(type == 2, where << ":" << d.elem_line[e] << ": element type " << type << " ("
                                   << et.name
                                   << ") is not supported; only 3-node triangles (type 2) and "
                                      "2-node lines (type 1) are read (set Gmsh's "
                                      "Mesh.ElementOrder = 1 and do not recombine)");
        s.tris.push_back({node(e, 0), node(e, 1), node(e, 2)});
        s.tri_element.push_back(e);
        s.tri_phys.push_back(d.phys_begin[e + 1] > d.phys_begin[e] ? d.phys[d.phys_begin[e]] : 0);
    }
    MLC_CHECK(!s.tris.empty(),
              where << ": no 3-node triangles found"
                    << (surface.empty() ? "" : " in physical surface '" + surface + "'"));
    return s;
}

/// The used nodes, in file order (new_index: file index -> vertex, or -1), and the triangles
/// oriented counter-clockwise.
Mesh build_triangles(const MshData& d, const Selection& s, const std::string& where,
                     std::vector<int>& new_index) {
    Mesh m;
    new_index.assign(d.node_id.size(), -1);
    for (const auto& t : s.tris)
        for (int v : t)
            new_index[v] = 0;
    for (std::size_t i = 0; i < new_index.size(); ++i)
        if (new_index[i] == 0) {
            new_index[i] = m.n_vertices();
            m.vertices.emplace_back(d.node_x[i].x(), d.node_x[i].y());
        }
    const double diam = m.diameter();
    for (std::size_t i = 0; i < new_index.size(); ++i)
        MLC_CHECK(new_index[i] < 0 || std::abs(d.node_x[i].z()) <= 1e-10 * diam,
                  where << ":" << d.node_line[i] << ": node " << d.node_id[i] << " has z = "
                        << d.node_x[i].z() << "; only planar meshes in the plane z = 0 are read");
    for (std::size_t i = 0; i < s.tris.size(); ++i) {
        std::array<int, 3> t = {new_index[s.tris[i][0]], new_index[s.tris[i][1]],
                                new_index[s.tris[i][2]]};
        const Vec2 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
        const double area2 = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
        const std::size_t e = s.tri_element[i];
        MLC_CHECK(std::abs(area2) > 2e-14 * diam * diam,
                  where << ":" << d.elem_line[e] << ": degenerate triangle (nodes "
                        << d.node_ids[d.node_begin[e]] << ", " << d.node_ids[d.node_begin[e] + 1]
                        << ", " << d.node_ids[d.node_begin[e] + 2] << ")");
        if (area2 < 0) std::swap(t[1], t[2]);
        m.cells.push_back(t);
    }
    if (std::any_of(s.tri_phys.begin(), s.tri_phys.end(), [](int p) { return p != 0; }))
        m.attribute = s.tri_phys;
    return m;
}

/// The tagged line elements: boundary edges (on one triangle) and interior lines (on two). The
/// triangles of every vertex, in triangle order: a line element (a, b) lies on the triangles that
/// hold both, with the direction it has in the first of them.
void tag_lines(const MshData& d, const Selection& s, const NodeLookup& node,
               const std::vector<int>& new_index, Mesh& m) {
    const VertexTriangles vtri = vertex_triangles(m);
    std::set<std::uint64_t> tagged;
    for (std::size_t e : s.lines) {
        const int a = new_index[node(e, 0)], b = new_index[node(e, 1)];
        if (a < 0 || b < 0) continue;
        const auto on = vtri.on_edge(m, a, b); // its direction in the first triangle holding it
        const int count = on.count;
        std::array<int, 2> dir{};
        if (count > 0) {
            const auto& t = m.cells[static_cast<std::size_t>(on.first[0])];
            for (int i = 0; i < 3; ++i)
                if ((t[i] == a && t[(i + 1) % 3] == b) || (t[i] == b && t[(i + 1) % 3] == a))
                    dir = {t[i], t[(i + 1) % 3]};
        }
        const std::uint64_t key = edge_key(a, b);
        if (count == 0 || count > 2 || !tagged.insert(key).second) continue;
        const int p = d.phys[d.phys_begin[e]];
        auto name = d.names.find({1, p});
        BoundaryEdge be;
        be.v0 = dir[0];
        be.v1 = dir[1];
        be.tag = m.add_tag(name == d.names.end() ? "tag" + std::to_string(p) : name->second);
        // An edge of two selected triangles is a tagged interior line.
        (count == 1 ? m.boundary : m.lines).push_back(be);
    }
}

} // namespace

namespace gmsh_io {

ElementType msh_element_type(int type) {
    return element_type(type);
}

std::string read_msh_file(const std::filesystem::path& file) {
    return read_file(file);
}

MshData parse_msh(const std::filesystem::path& file, std::string text) {
    return parse(file, std::move(text));
}

} // namespace gmsh_io

Mesh read_gmsh(const std::filesystem::path& file, const std::string& surface) {
    return read_gmsh_text(read_file(file), file, surface);
}

Mesh read_gmsh_text(const std::string& text, const std::filesystem::path& file,
                    const std::string& surface) {
    const MshData d = parse(file, text);
    const std::string where = "read_gmsh: " + file.string();
    const NodeLookup node(d, where);
    const int wanted = wanted_surface(d, surface, where);
    const Selection s = select_elements(d, node, surface, wanted, where);
    std::vector<int> new_index; // the file's node index -> vertex, or -1
    Mesh m = build_triangles(d, s, where, new_index);
    tag_lines(d, s, node, new_index, m);
    // Defects of the mesh name the file, and each triangle its element's line and node ids.
    try {
        check_quality(m, [&](int t) {
            const std::size_t e = s.tri_element[static_cast<std::size_t>(t)];
            return "triangle " + std::to_string(t) + " (the element on line " +
                   std::to_string(d.elem_line[e]) + ", nodes " +
                   std::to_string(d.node_ids[d.node_begin[e]]) + " " +
                   std::to_string(d.node_ids[d.node_begin[e] + 1]) + " " +
                   std::to_string(d.node_ids[d.node_begin[e] + 2]) + ")";
        });
    } catch (const InvalidInput& e) {
        throw InvalidInput(where + ": " + e.what());
    }
    return m;
}

void write_gmsh(const Mesh& m, std::ostream& os) {
    std::set<int> surfaces;
    for (int a : m.attribute)
        surfaces.insert(a);
    os << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n"
       << m.tag_names.size() + surfaces.size() << "\n";
    for (const auto& [name, tag] : m.tag_names)
        os << "1 " << tag + 1 << " \"" << name << "\"\n";
    for (int a : surfaces)
        os << "2 " << a + 1 << " \"body" << a << "\"\n";
    os << "$EndPhysicalNames\n$Nodes\n" << m.n_vertices() << "\n";
    os.precision(17);
    for (int v = 0; v < m.n_vertices(); ++v)
        os << v + 1 << " " << m.vertices[static_cast<size_t>(v)].x() << " "
           << m.vertices[static_cast<size_t>(v)].y() << " 0\n";
    os << "$EndNodes\n$Elements\n" << m.boundary.size() + m.lines.size() + m.cells.size() << "\n";
    int id = 1;
    for (const auto* edges : {&m.boundary, &m.lines})
        for (const BoundaryEdge& e : *edges)
            os << id++ << " 1 2 " << e.tag + 1 << " " << e.tag + 1 << " " << e.v0 + 1 << " "
               << e.v1 + 1 << "\n";
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        const int phys = m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)] + 1;
        os << id++ << " 2 2 " << phys << " " << std::max(phys, 1) << " " << tri[0] + 1 << " "
           << tri[1] + 1 << " " << tri[2] + 1 << "\n";
    }
    os << "$EndElements\n";
}

} // namespace mlc::mesh
