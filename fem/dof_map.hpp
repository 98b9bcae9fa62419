// SPDX-License-Identifier: MIT
/// @file Numbering of the unknowns: free displacement components interleaved by vertex, with each
/// vertex's extra unknowns (contact multipliers) right after its displacements.
#pragma once

#include "core/types.hpp"

#include <array>
#include <vector>

namespace mlc::fem {

/// Unknown numbering of one level, in `dim` dimensions (2 or 3).
///
/// Vertices are visited in a given order (default: index order); vertex v contributes, in this
/// order: its free displacement components (x, y (, z); a component
/// fixed by a Dirichlet condition is not an unknown, `u_dof` is -1 there), then `n_extra(v)`
/// extra unknowns (the contact multipliers (lambda_t, lambda_n), or lambda_n alone). Keeping a
/// contact node's multipliers next to its displacements gives ILU nonzero pivots and lets block
/// smoothers see vertex+multiplier blocks.
template <int dim> class BasicDofMap {
public:
    static_assert(dim == 2 || dim == 3, "BasicDofMap: dim is 2 or 3");
    /// Displacement components per vertex.
    static constexpr int kDim = dim;

    BasicDofMap() = default;
    /// @param fixed  fixed[v][c] true when component c of vertex v is prescribed
    /// @param n_extra number of extra unknowns per vertex (0 .. dim: in 2D 0, 1 or 2)
    /// @param order  the order in which vertices are numbered (a permutation of the vertices,
    ///               e.g. mesh::hilbert_order); empty: vertex index order
    BasicDofMap(const std::vector<std::array<bool, dim>>& fixed, const std::vector<int>& n_extra,
                const std::vector<int>& order = {});

    Index n_dofs() const { return n_dofs_; }
    int n_vertices() const { return static_cast<int>(u_dof_.size()); }
    /// Unknown index of component c of vertex v, or -1 if prescribed.
    int u_dof(int v, int c) const { return u_dof_[static_cast<size_t>(v)][static_cast<size_t>(c)]; }
    /// First extra unknown of vertex v, or -1 when it has none.
    int extra_dof(int v) const { return extra_[static_cast<size_t>(v)]; }
    /// Number of free displacement unknowns.
    Index n_displacement_dofs() const { return n_u_; }
    /// true when the unknown is a displacement component (false: a multiplier).
    bool is_displacement(Index dof) const { return is_u_[static_cast<size_t>(dof)]; }
    /// Vertex owning an unknown.
    int vertex_of(Index dof) const { return owner_[static_cast<size_t>(dof)]; }

    /// Full nodal displacement vector (dim per vertex, interleaved) from the unknowns x and the
    /// prescribed values `u_fixed` (dim per vertex; read only where fixed).
    void expand(const Vector& x, const Vector& u_fixed, Vector& u_full) const;

private:
    std::vector<std::array<int, dim>> u_dof_;
    std::vector<int> extra_;
    std::vector<char> is_u_;
    std::vector<int> owner_;
    Index n_dofs_ = 0;
    Index n_u_ = 0;
};

extern template class BasicDofMap<2>;
extern template class BasicDofMap<3>;

/// The 2D numbering (2 components per vertex), as every 2D level uses it.
using DofMap = BasicDofMap<2>;
/// The 3D numbering (3 components per vertex, interleaved x, y, z).
using DofMap3 = BasicDofMap<3>;

} // namespace mlc::fem
