// SPDX-License-Identifier: MIT
// The distributed multigrid's parameters from a 2D run's linear-solver spec.
#include "core/check.hpp"
#include "levels/distributed_multigrid.hpp"
#include "solvers/factory.hpp"

namespace mlc::levels {

solvers::MultigridParams distributed_mg_params(const LinearSolverSpec& spec) {
    MLC_CHECK(spec.method == solvers::Method::krylov,
              "on several processes the Newton systems are solved by a Krylov method with mg "
              "(--linear krylov --pc mg); '"
                  << spec.method
                  << "' has no distributed form (schur, lu, cf and sorcf need the "
                     "whole level on one process)");
    const solvers::PcSpec& pc = spec.pc;
    const std::string why = pc.distributed();
    MLC_CHECK(why.empty(), why);
    if (pc.name() != "mg") {
        // A preconditioner of the matrix alone (or ebe) runs on each process's diagonal block;
        // its options checked here, on every process (ebe: on no elements, not set up).
        static const std::vector<smoothers::ElementMatrix> none;
        solvers::LevelData d;
        d.elements = [] { return &none; };
        solvers::make_preconditioner(pc, pc.entry->level_aware ? &d : nullptr);
        return {};
    }
    // Per process on its diagonal block, as one process smooths its level (block or lattice
    // sweeps, double or single precision).
    const solvers::MultigridParams p = pc.get<solvers::MgOptions>().cycle();
    p.validate();
    return p;
}

LinearSolverSpec serial_levels_spec(const LinearSolverSpec& spec, int partition_level) {
    LinearSolverSpec s = spec;
    if (spec.method != solvers::Method::krylov || partition_level >= kMgDefaultLatticeLevel ||
        spec.pc.name() != "mg")
        return s;
    solvers::MgOptions m = spec.pc.get<solvers::MgOptions>();
    if (m.smoother != solvers::MultigridParams::Smoother::lattice) return s;
    m.smoother = solvers::MultigridParams::Smoother::block;
    s.pc.options = m;
    return s;
}

} // namespace mlc::levels
