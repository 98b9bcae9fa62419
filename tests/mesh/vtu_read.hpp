// SPDX-License-Identifier: MIT
/// @file Reading back the binary VTU files the writers make: the appended, zlib-compressed arrays.
#pragma once

#include "tests/common/files.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace mlc::testutil {

/// The decoded bytes of an appended, zlib-compressed array (header_type UInt64) of a binary VTU,
/// found by the `marker` in its DataArray tag; empty (and a test failure) if anything is off.
inline std::vector<unsigned char> appended_array(const std::string& xml,
                                                 const std::string& marker) {
    std::size_t at = xml.find(marker);
    EXPECT_NE(at, std::string::npos) << marker;
    if (at == std::string::npos) return {};
    if (marker.back() == '>') at = xml.find("<DataArray", at);
    EXPECT_EQ(testutil::xml_attribute(xml, "format", at), "appended");
    const std::size_t offset = std::stoull(testutil::xml_attribute(xml, "offset", at));
    const std::size_t data = xml.find('_', xml.find("<AppendedData encoding=\"raw\">")) + 1;
    const auto* p = reinterpret_cast<const unsigned char*>(xml.data()) + data + offset;
    std::uint64_t head[3];
    std::memcpy(head, p, sizeof head);
    const std::uint64_t n_blocks = head[0], block = head[1], last = head[2];
    std::vector<std::uint64_t> sizes(n_blocks);
    std::memcpy(sizes.data(), p + sizeof head, n_blocks * 8);
    const unsigned char* blocks = p + sizeof head + n_blocks * 8;
    std::vector<unsigned char> out;
    for (std::uint64_t b = 0; b < n_blocks; ++b) {
        uLongf n = (b + 1 == n_blocks && last != 0) ? last : block;
        std::vector<unsigned char> chunk(n);
        EXPECT_EQ(uncompress(chunk.data(), &n, blocks, sizes[b]), Z_OK);
        chunk.resize(n);
        out.insert(out.end(), chunk.begin(), chunk.end());
        blocks += sizes[b];
    }
    return out;
}

template <class T> std::vector<T> as(const std::vector<unsigned char>& bytes) {
    std::vector<T> v(bytes.size() / sizeof(T));
    std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
    return v;
}

} // namespace mlc::testutil
