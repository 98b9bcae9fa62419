// SPDX-License-Identifier: MIT
/// @file The vertex lists of a ghost exchange and its exchange of per-vertex records, for the 2D
/// and 3D parts of a distributed level (GhostExchange, GhostExchange3): the same over the
/// dimension, as a part of either kind numbers its vertices the same way (mesh/distributed.hpp).
#pragma once

#include "core/check.hpp"
#include "core/communicator.hpp"

#include <algorithm>
#include <cstdint>
#include <cstddef>
#include <vector>

namespace mlc::levels::detail {

/// Per process q: recv[q], this part's ghost vertices that q owns; send[q], this part's owned
/// vertices that q holds as ghosts (in the order q lists them). Collective. `who` names the
/// class in the messages.
template <class Part>
void ghost_lists(const Part& part, const Communicator& comm, const char* who,
                 std::vector<std::vector<int>>& recv, std::vector<std::vector<int>>& send) {
    const int np = comm.size();
    const int me = comm.rank();
    recv.assign(static_cast<size_t>(np), {});
    std::vector<std::vector<std::int64_t>> ask(static_cast<size_t>(np));
    for (int v = 0; v < part.mesh.n_vertices(); ++v) {
        const int o = part.vertex_owner[static_cast<size_t>(v)];
        if (o == me) continue;
        recv[static_cast<size_t>(o)].push_back(v);
        ask[static_cast<size_t>(o)].push_back(part.global_vertex[static_cast<size_t>(v)]);
    }
    const auto asked = comm.exchange(ask);
    send.assign(static_cast<size_t>(np), {});
    for (int q = 0; q < np; ++q)
        for (const std::int64_t g : asked[static_cast<size_t>(q)]) {
            const std::int64_t i = g - part.first_vertex;
            MLC_CHECK(i >= 0 && i < part.n_owned_vertices(),
                      who << ": process " << q << " asks for vertex " << g << ", which process "
                          << me << " does not own");
            send[static_cast<size_t>(q)].push_back(part.owned_vertices[static_cast<size_t>(i)]);
        }
}

/// Overwrites the `width` records of every ghost vertex in `rec` with its owner's. Collective.
inline void exchange_vertex_records(const Communicator& comm, const char* who,
                                    const std::vector<std::vector<int>>& recv,
                                    const std::vector<std::vector<int>>& send,
                                    std::vector<double>& rec, int width) {
    const auto w = static_cast<size_t>(width);
    std::vector<std::vector<double>> out(send.size());
    for (size_t q = 0; q < send.size(); ++q)
        for (const int v : send[q])
            out[q].insert(out[q].end(), rec.begin() + static_cast<std::ptrdiff_t>(v * w),
                          rec.begin() + static_cast<std::ptrdiff_t>((v + 1) * w));
    const auto in = comm.exchange(out);
    for (size_t q = 0; q < recv.size(); ++q) {
        MLC_CHECK(in[q].size() == recv[q].size() * w,
                  who << ": process " << q << " sent " << in[q].size() << " values for "
                      << recv[q].size() << " vertices");
        for (size_t i = 0; i < recv[q].size(); ++i)
            std::copy_n(in[q].begin() + static_cast<std::ptrdiff_t>(i * w), w,
                        rec.begin() + static_cast<std::ptrdiff_t>(recv[q][i] * w));
    }
}

} // namespace mlc::levels::detail
