// SPDX-License-Identifier: MIT
/// @file The description of a contact problem independent of any mesh level: bodies and
/// materials, loads, supports, contact pairs, load stepping and solver settings. A scene file is
/// parsed into this (apps/), and every level is built from it and a mesh.
#pragma once

#include "contact/obstacle.hpp"
#include "core/types.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"

#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::levels {

/// Axis-aligned box used to select vertices.
struct Box {
    Vec2 lo = Vec2::Constant(-1e300);
    Vec2 hi = Vec2::Constant(1e300);
    bool contains(const Vec2& p) const {
        return p.x() >= lo.x() && p.x() <= hi.x() && p.y() >= lo.y() && p.y() <= hi.y();
    }
};

/// A body: one material region of the merged mesh (triangle attribute = body index).
struct Body {
    std::string name;
    fem::Material material;
    Vec2 body_force = Vec2::Zero(); ///< force per unit area
};

/// Uniform surface load on the boundary edges with a tag (at the full load factor 1).
struct Load {
    std::string tag;
    double pressure = 0.0;        ///< normal pressure, positive pushes into the body
    Vec2 traction = Vec2::Zero(); ///< vector traction per unit length
};

/// Prescribed displacement components on a tagged boundary or at a point (full load factor 1).
struct Support {
    std::string tag;           ///< boundary tag, or empty when `point` is given
    std::optional<Vec2> point; ///< a vertex position (must coincide with a level-0 vertex)
    std::optional<double> ux;  ///< prescribed x displacement, if any
    std::optional<double> uy;  ///< prescribed y displacement, if any
};

/// One contact pair: contactor nodes on a tagged boundary (optionally inside a box) against a
/// rigid obstacle. (Two-body pairs name a target boundary instead; see node_on_facet.)
struct ContactPair {
    std::string name;
    std::string contactor;                     ///< boundary tag of the contactor nodes
    std::optional<Box> region;                 ///< keep only contactor vertices inside this box
    std::optional<contact::Obstacle> obstacle; ///< rigid target
    double mu = 0.0;                           ///< Coulomb friction coefficient >= 0
    double r = 0.0; ///< augmentation parameter > 0 (force/length^2 units x length)
};

/// Generalized Newton settings.
struct NewtonParams {
    /// Converged when the statuses did not change and ||R|| <= rel_tol * scale, with scale the
    /// largest of the load norm and the internal/contact force norms (no absolute tolerance).
    double rel_tol = 1e-10;
    /// Iterations per load step before the step is declared not converged. The papers converge
    /// in 3-10; 50 leaves room for cycling detection to act.
    int max_iter = 50;
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const NewtonParams& p);

/// Everything needed to build a level and solve.
struct Problem {
    std::string name;
    std::string description;
    std::string units; ///< free text, e.g. "N, mm, N/mm^2"
    mesh::Mesh mesh0;  ///< level-0 mesh (all bodies; attribute = body index)
    std::vector<Body> bodies;
    std::vector<Load> loads;
    std::vector<Support> supports;
    std::vector<ContactPair> contacts;
    int load_steps = 1; ///< proportional loading in equal increments
    int levels = 0;     ///< number of 1->4 refinements of mesh0
    NewtonParams newton;

    /// Checks materials, pairs (mu >= 0, r > 0), load_steps >= 1, levels >= 0, and the mesh.
    /// Throws InvalidInput naming the offending entry.
    void validate() const;
    /// Characteristic Young's modulus (the largest), for defaults such as r = 0.1 E.
    double max_young_modulus() const;
};

} // namespace mlc::levels
