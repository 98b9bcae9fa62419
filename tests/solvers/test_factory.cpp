// SPDX-License-Identifier: MIT
// make_preconditioner: valid specs build the right objects, invalid ones are rejected.
#include "core/check.hpp"
#include "solvers/factory.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

using namespace mlc;
using namespace mlc::solvers;

TEST(Factory, BuildsEveryRegisteredName) {
    const SparseMatrix A = testmat::laplace_2d(5);
    const std::vector<std::pair<std::string, std::string>> specs = {
        {"none", "none"},
        {"diag", "diag"},
        {"ilu", "ilu(0)"},
        {"ilu:2", "ilu(2)"},
        {"ilu:k=1", "ilu(1)"},
        {" ILU : 3 ", "ilu(3)"},
        {"sor", "sor(omega=1)"},
        {"sor:omega=1.25", "sor(omega=1.25)"},
        {"ssor:omega=0.8,sweeps=2", "ssor(omega=0.8,sweeps=2)"},
        {"ssor:block=5", "ssor(omega=1,block=5)"},
        {"lu", "lu"}};
    const Vector r = testmat::pseudo_random(A.rows());
    for (const auto& [spec, name] : specs) {
        auto M = make_preconditioner(spec);
        ASSERT_TRUE(M) << spec;
        EXPECT_EQ(M->name(), name) << spec;
        M->setup(A);
        Vector z;
        M->apply(r, z);
        EXPECT_TRUE(z.allFinite()) << spec;
        EXPECT_GT(z.dot(r), 0.0) << spec; // all are positive definite on this SPD matrix
    }
}

TEST(Factory, ParsesOptions) {
    const PreconditionerSpec s = parse_preconditioner_spec("sor:omega=1.5, sweeps=3");
    EXPECT_EQ(s.name, "sor");
    ASSERT_EQ(s.options.size(), 2u);
    EXPECT_EQ(s.options.at("omega"), "1.5");
    EXPECT_EQ(s.options.at("sweeps"), "3");
    EXPECT_EQ(parse_preconditioner_spec("ilu:4").options.at("k"), "4");
    EXPECT_TRUE(parse_preconditioner_spec("lu").options.empty());
}

TEST(Factory, RejectsInvalidSpecs) {
    for (const char* bad :
         {"", "foo", "ilu:x", "ilu:-1", "ilu:1.5", "ilu:1,k=2", "sor:omega=2.5",
          "sor:omega=", "sor:omega=abc", "sor:bogus=1", "sor:1.2", "ssor:sweeps=0", "lu:1",
          "lu:pivot=1", "none:x=1", "ilu:", "diag:omega=1"}) {
        EXPECT_THROW(make_preconditioner(bad), InvalidInput) << "'" << bad << "'";
    }
    try {
        make_preconditioner("amgx");
        FAIL() << "expected InvalidInput";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        for (const char* name : {"none", "diag", "ilu", "sor", "ssor", "lu"})
            EXPECT_NE(msg.find(name), std::string::npos) << msg;
    }
    try {
        make_preconditioner("ssor:omega=1.1,bogus=2");
        FAIL() << "expected InvalidInput";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("bogus"), std::string::npos) << msg;
        EXPECT_NE(msg.find("omega, sweeps, block"), std::string::npos) << msg;
    }
}
