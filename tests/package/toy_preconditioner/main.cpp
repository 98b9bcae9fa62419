// SPDX-License-Identifier: MIT
// Registers a preconditioner the library does not know ("toy": ILU(K) that counts its
// applications) from user code, plans a solve with it through levels::plan_solver and solves
// the square with it. Checks: its usage line and canonical text come from its declared key; the
// plan takes it with CGS; a plan on two processes is refused (it declares no distributed form);
// the solve applies it and gives bit for bit the answer of the built-in ILU(K) it wraps.
#include <mlcontact/core/check.hpp>
#include <mlcontact/levels/resources.hpp>
#include <mlcontact/levels/solve.hpp>
#include <mlcontact/scene/scene.hpp>
#include <mlcontact/solvers/factory.hpp>

#include <cstdio>
#include <exception>
#include <memory>
#include <string>

namespace {

long applications = 0;

// ILU(K) of the library, counting what the Krylov method asks of it.
class Toy final : public mlc::Preconditioner {
public:
    explicit Toy(int k) : inner_(mlc::solvers::make_preconditioner("ilu:" + std::to_string(k))) {}
    void setup(const mlc::SparseMatrix& A) override { inner_->setup(A); }
    void apply(const mlc::Vector& r, mlc::Vector& z) const override {
        ++applications;
        inner_->apply(r, z);
    }
    std::string name() const override { return "toy(" + inner_->name() + ")"; }

private:
    std::unique_ptr<mlc::Preconditioner> inner_;
};

#define REQUIRE(cond)                                                                              \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            std::fprintf(stderr, "toy: failed: %s (line %d)\n", #cond, __LINE__);                  \
            return 1;                                                                              \
        }                                                                                          \
    } while (0)

} // namespace

int main() {
    using namespace mlc;
    try {
        solvers::register_preconditioner({
            .name = "toy",
            .summary = "ILU(K) counting its applications, registered from user code",
            .defaults = solvers::UserOptions{{{"fill", 0.0}}},
            .fields =
                [](solvers::PcOptions& o, solvers::PcFields& f) {
                    f.real("fill", std::get<solvers::UserOptions>(o).values["fill"], "K");
                },
            .build = [](const solvers::PcOptions& o,
                        const solvers::LevelData*) -> std::unique_ptr<Preconditioner> {
                return std::make_unique<Toy>(
                    static_cast<int>(std::get<solvers::UserOptions>(o).values.at("fill")));
            },
        });
        const solvers::PcSpec spec = solvers::parse_pc("toy:fill=1");
        REQUIRE(spec.text() == "toy:fill=1");
        REQUIRE(solvers::parse_pc(spec.text()) == spec);
        REQUIRE(solvers::parse_pc("toy").text() == "toy");
        REQUIRE(solvers::preconditioner_entry("toy")->usage().find("fill=K") != std::string::npos);

        levels::Problem p = scene::load_scene("square");
        p.levels = 1;
        const levels::SolverPlan plan = levels::plan_solver(p, {.pc = spec});
        REQUIRE(plan.spec.method == solvers::Method::krylov);
        REQUIRE(plan.spec.krylov == solvers::Krylov::cgs);
        REQUIRE(plan.spec.pc == spec);
        bool refused = false;
        try {
            (void)levels::plan_solver(p, {.pc = spec}, 2);
        } catch (const InvalidInput& e) {
            refused =
                std::string(e.what()).find("'toy' has no distributed form") != std::string::npos;
        }
        REQUIRE(refused);

        levels::SolveOptions so;
        so.linear = plan.spec;
        const levels::RunResult toy = levels::solve(p, so);
        REQUIRE(toy.converged);
        REQUIRE(applications > 0);
        so.linear.pc = solvers::parse_pc("ilu:1");
        const levels::RunResult ilu = levels::solve(p, so);
        REQUIRE(ilu.converged);
        REQUIRE(toy.x.size() == ilu.x.size() && toy.x == ilu.x);
        std::printf("toy: registered, planned and solved the square (%ld applications), equal "
                    "to ilu:1\n",
                    applications);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "toy: error: %s\n", e.what());
        return 1;
    }
}
