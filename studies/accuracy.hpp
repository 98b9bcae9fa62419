// SPDX-License-Identifier: MIT
/// @file `mlcontact study accuracy`: errors of the closed-form quantities of the benchmark scenes
/// (hertz, mindlin, patch) per level, with the observed convergence orders between levels.
#pragma once

#include "levels/problem.hpp"
#include "levels/solve.hpp"
#include "levels/solve3.hpp"

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// Options of the accuracy study.
struct AccuracyOptions {
    int levels = 3;            ///< levels 0..levels are solved (each coarse-to-fine from level 0)
    std::filesystem::path out; ///< output folder (default out/<scene>/accuracy)
    bool plot = true;          ///< draw accuracy.png with scripts/plot_accuracy.py
    /// For scenes with node-on-facet pairs, also solve each level with the other
    /// contact::FacetIntegration variants (nodal, segment, dual) and list their errors with the
    /// suffix "_nodal", "_segment" or "_dual", so that the variants can be read side by side.
    bool compare_integration = true;
};

/// One measured quantity of a converged state against its closed form.
struct AccuracyValue {
    std::string name;       ///< e.g. "half_width", "c_over_a"
    double value = 0.0;     ///< measured
    double reference = 0.0; ///< closed form (equal to value for information-only rows)
    /// Relative error (value - reference) / reference, or a quantity that is itself an error
    /// (an rms relative to a peak); NaN for information-only rows (P, Q, Q / (mu P)).
    double error = 0.0;
    std::string note; ///< what the error is relative to
};

/// Mindlin partial slip (benchmarks.md `mindlin`), measured on the finest level of a run:
/// P = -sum lambda_n, Q = |sum lambda_t| (per unit thickness); a, c the half-widths of the
/// contact and stick zones (each end midway between the last node inside and the first outside,
/// from the final statuses); nodal tractions p = -lambda_n / l, q = |lambda_t| / l with l the
/// tributary length along x. Closed form: a = sqrt(4 P R / (pi E*)), E* = E / (2 (1 - nu^2)),
/// p(x) = p0 sqrt(1 - x^2 / a^2), p0 = 2 P / (pi a), c / a = sqrt(1 - Q / (mu P)),
/// q(x) = mu p0 / a (sqrt(a^2 - x^2) - [|x| < c] sqrt(c^2 - x^2)).
struct MindlinMeasures {
    double P = 0.0, Q = 0.0;
    double a = 0.0, a_closed = 0.0;
    double c = 0.0;
    double c_over_a = 0.0, c_over_a_closed = 0.0;
    /// rms over the slip-zone nodes of (q - mu p_closed(x)) / (mu p0).
    double slip_traction_rms = 0.0;
    /// rms over the nodes with |x| < 0.9 a of (q - q_closed(x)) / (mu p0).
    double q_profile_rms = 0.0;
    /// rms over the nodes with |x| < 0.9 a of (p - p_closed(x)) / p0.
    double pressure_rms = 0.0;
    /// After load step 1: max |lambda_t| / (mu max |lambda_n|) (0 in the half-space theory).
    double step1_tangential = 0.0;
    /// After load step 1: tangential tractions q = |lambda_t| / l against mu p0_1, p0_1 the
    /// closed-form peak pressure of step 1's own measured normal force P_1: the rms over the
    /// nodes in contact after step 1, and the maximum over all nodes.
    double step1_traction_rms = 0.0, step1_traction_max = 0.0;
    int n_stick = 0, n_slip = 0, n_closed = 0;
};

/// One level of an accuracy study: its size, time and measured quantities.
struct AccuracyRow {
    int level = 0;
    Index unknowns = 0;
    int contacts = 0;
    double seconds = 0.0;
    std::vector<AccuracyValue> values;
};

/// Prints the last row of `rows` as a table (quantity, value, closed form, error, and the
/// observed order against the row before).
void print_accuracy_level(const std::vector<AccuracyRow>& rows, std::ostream& os);

/// accuracy.csv (long format) and accuracy.json of an accuracy study into `dir`, and
/// accuracy.png (scripts/plot_accuracy.py) when `plot`.
void write_accuracy_files(const std::string& scene, const std::vector<AccuracyRow>& rows,
                          const std::filesystem::path& dir, bool plot, std::ostream& os);

/// Measures a Mindlin run. `r` must come from levels::solve with keep_step_states (step 1 is
/// read from r.step_nodes[0]) and at least two load steps. E and nu are the first body's, mu
/// the first pair's, R the radius of the circle the contactor boundary lies on.
/// Throws InvalidInput when these are missing or a zone is not resolved by the candidates.
MindlinMeasures measure_mindlin(const levels::Problem& p, const levels::RunResult& r);

/// Contact patch test (benchmarks.md `patch`): exact uniform pressure p = E |u_top| / H and
/// interface displacement u_top / 2 (H = 2 the height of the stack, u_top the prescribed platen
/// u_y, nu = 0). Pressures are -lambda_n / l at the contactor nodes, l the tributary length.
struct PatchMeasures {
    double p_exact = 0.0, uy_exact = 0.0;
    double pressure_max_error = 0.0;          ///< max |p - p_exact| / p_exact, every node
    double pressure_interior_max_error = 0.0; ///< the same without the two end nodes
    double uy_max_error = 0.0;                ///< max |u_y - uy_exact| / |uy_exact|
    double resultant_error = 0.0;             ///< |sum -lambda_n - p_exact width| / (p_exact width)
};

/// Measures a patch-test run (nu = 0 required; throws InvalidInput otherwise).
PatchMeasures measure_patch(const levels::Problem& p, const levels::RunResult& r);

/// The closed-form quantities of a converged run of a benchmark scene, chosen by the scene name:
/// `hertz` (half-width, peak pressure, profile rms; P from the contact resultant of the half
/// model), `mindlin` (MindlinMeasures), `patch` and `patch_matching` (PatchMeasures).
/// Throws InvalidInput for another scene (no closed form known).
std::vector<AccuracyValue> accuracy_values(const levels::Problem& p, const levels::RunResult& r);

/// Solves the scene on levels 0..opt.levels (each run coarse-to-fine from level 0), prints per
/// level the closed-form quantities, their errors and the observed orders
/// log2(|e_(l-1)| / |e_l|) (h halves per level), and writes accuracy.csv (one row per level and
/// quantity: level, unknowns, contact_nodes, seconds, quantity, value, reference, error, order),
/// accuracy.json and accuracy.png. Returns 0, or 2 if a level did not converge.
int study_accuracy(const levels::Problem& problem, const AccuracyOptions& opt, std::ostream& os);

/// The closed-form quantities of a converged 3D run: hertz3d and sphere_punch (P, the contact
/// radius a against (3 P R / (4 E*))^(1/3) with 1/E* = (1 - nu^2) / E, the pressure of the node
/// nearest the axis against p0 = 3 P / (2 pi a^2), the rms of p - p0 sqrt(1 - r^2 / a^2) over
/// r < 0.9 a relative to p0; pressures -lambda_n / int N_i dA), sphere_on_block (Hertz between
/// two equal bodies, 1/E* = 2 (1 - nu^2) / E, P and Q twice the half model's normal force and x
/// force; the same radius, peak pressure and rms, then, after the shift of the last step, c / a
/// against Cattaneo-Mindlin's (1 - Q / (mu P))^(1/3) with c and a the half-widths of the stick
/// and the closed nodes on the x axis (y = 0), each end midway to the next node, as in 2D; the
/// rms of the traction along x against the closed form over r < 0.9 a relative to mu p0; the
/// largest |lambda_t| / (mu |lambda_n|) after the first step), punch3d (the largest relative
/// error of the pressure against the load's, and of the resultant). Throws InvalidInput for
/// another scene.
std::vector<AccuracyValue> accuracy_values3(const levels::ElasticProblem3& p,
                                            const levels::RunResult3& r);

/// The accuracy study of a 3D scene: levels 0..opt.levels, each coarse-to-fine, the same table
/// and files as in 2D.
int study_accuracy3(const levels::ElasticProblem3& problem, const AccuracyOptions& opt,
                    std::ostream& os);

} // namespace mlc::apps
