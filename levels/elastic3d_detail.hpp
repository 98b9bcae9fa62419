// SPDX-License-Identifier: MIT
/// @file What levels/elastic3d_levels.cpp shares with levels/elastic3d_sizes.cpp (the level-0
/// edges and the edges of line supports) and with levels/distributed3.cpp (the contact nodes of a
/// level or of a process's part of it, their pinned components, and the loading path). Internal
/// to mlc_levels.
#pragma once

#include "contact/search3.hpp"
#include "levels/elastic3d_levels.hpp"

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace mlc::levels::detail {

/// The edges of m (mesh::tet_edges, smaller vertex first), sorted.
std::vector<std::array<int, 2>> sorted_edges(const mesh::TetMesh& m);

/// The level-0 edges of a line support (pairs of vertices, smaller first), after checking that
/// its ends are level-0 vertices and its segment runs along level-0 edges (`edges`: those of
/// sorted_edges(m0)). Throws InvalidInput otherwise.
std::vector<std::pair<int, int>> line_edges0(const mesh::TetMesh& m0,
                                             const std::vector<std::array<int, 2>>& edges,
                                             const std::array<Vec3, 2>& line);

/// The two-body elements of pair k of p for the contactor vertices `nodes` of level mesh m
/// (contact::node_on_facet_search3 with the level-0 target faces as the reference, which decides
/// whether a vertex is a contact node the same on every level, so that the contact nodes nest;
/// or contact::node_on_node_search3). `is_part`: m is a process's part of the level, which may
/// hold no target face; its nodes then lie beyond the search's reach of the target (the ghost
/// layer holds every target face within it) and are all not found.
contact::SearchResult3 two_body_search3(const ElasticProblem3& p, const mesh::TetMesh& m, size_t k,
                                        const std::vector<int>& nodes, bool is_part = false);

/// The contact elements of every pair of p on level L (Level3::contacts in pair order,
/// contact_of_vertex, not_found) and the multipliers of each vertex (n_extra, sized to the
/// vertices); L.fixed must be set. Contactor nodes, pair by pair: the vertices of the faces with
/// the contactor tag, inside the region, not fully fixed, not claimed by an earlier pair (a
/// two-body node that finds no target is released for the later pairs). Throws InvalidInput for
/// a pair with no node, or (two-body) no node that found a target. `owned` (null: the whole
/// level): L is a process's part, and only the vertices with owned[v] != 0 become contact nodes;
/// a pair may then have none here (the caller checks the pairs over all parts).
void find_contact_nodes3(const ElasticProblem3& p, Level3& L, std::vector<int>& n_extra,
                         const std::vector<char>* owned = nullptr);

/// Sets ContactElement3::pinned of every element of L.contacts and L.ghost_contacts from the
/// fixed components of its vertices (contact::held_components, and a frictional two-body element
/// whose contactor alone pins its first tangent pins it: a symmetry plane through two-body
/// contact nodes), turning the frame of an element whose first tangent alone is pinned onto the
/// held axis. Throws InvalidInput, naming the pair, vertex, held components, frame and fixes, for
/// an element of L.contacts whose supports hold a direction its frame meets only in part; such a
/// ghost element is left unpinned (its owner refuses it).
void pin_held_components3(const ElasticProblem3& p, Level3& L);

/// The message of a two-body pair none of whose `n_nodes` contactor vertices found a target.
std::string no_target_message(const ContactPair3& pair, std::size_t n_nodes);

/// The loading path of a level whose supports (`vs`, their values those of the last path point),
/// fixed components, numbering and assembled system at the last path point are set, with
/// K = p.n_path_points() > 1: Level3::path_u_fixed, path_f and path_f_nodal at every path point
/// (the last entries are u_fixed, elastic.f and elastic.f_nodal_full). `nodal_loads_at(k)` gives
/// the nodal loads of path point k; `share(u)` (may be empty) completes the prescribed values of
/// a point where `vs` does not reach (a process's ghost vertices: their owners' values).
void set_load_path3(const ElasticProblem3& p, Level3& L, std::vector<fem::VertexSupport3> vs,
                    const std::function<Vector(int)>& nodal_loads_at,
                    const std::function<void(Vector&)>& share = {});

} // namespace mlc::levels::detail
