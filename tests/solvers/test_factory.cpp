// SPDX-License-Identifier: MIT
// make_preconditioner: valid specs build the right objects, invalid ones are rejected.
#include "core/check.hpp"
#include "solvers/factory.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <algorithm>

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

TEST(Factory, ParsesOptionsIntoTheirStruct) {
    const PcSpec s = parse_pc("sor:omega=1.5, sweeps=3");
    EXPECT_EQ(s.name(), "sor");
    EXPECT_EQ(s.get<SorOptions>().omega, 1.5);
    EXPECT_EQ(s.get<SorOptions>().sweeps, 3);
    EXPECT_EQ(s.get<SorOptions>().block, 1);
    EXPECT_EQ(parse_pc("ilu:4").get<IluOptions>().k, 4);
    EXPECT_EQ(parse_pc("ilu:k=4"), parse_pc("ilu:4"));
    EXPECT_EQ(parse_pc(" MG : post=2 , pre=0 ").text(), "mg:pre=0,post=2");
    const PcSpec mg = parse_pc("mg:omega=0.8,pre=0,post=2,smoother=lattice");
    const MgOptions& m = mg.get<MgOptions>();
    EXPECT_EQ(m.omega, 0.8);
    EXPECT_EQ(m.pre, 0);
    EXPECT_EQ(m.post, 2);
    EXPECT_EQ(m.coarse, MgCoarse::automatic);
    EXPECT_EQ(m.smoother, MultigridParams::Smoother::lattice);
    EXPECT_EQ(parse_pc("mg:coarse=galerkin").get<MgOptions>().coarse, MgCoarse::galerkin);
    EXPECT_EQ(parse_pc("mgr:frelax=gs").get<MgrOptions>().f_relax, 3);
    EXPECT_EQ(parse_pc("cf:inner=cgs,tol=1e-8").get<CfOptions>().params.inner_tol, 1e-8);
    EXPECT_TRUE(parse_pc("sorcf:block=1").get<SorcfOptions>().params.block);
    EXPECT_NE(parse_pc("mg"), parse_pc("mg:pre=2"));
    EXPECT_NE(parse_pc("sor"), parse_pc("ssor"));
}

// The driver's own specs print exactly as they always have (reports, summary.json and
// iterations.csv carry this text).
TEST(Factory, CanonicalTextKeepsTheDriversSpellings) {
    for (const char* t :
         {"mg:pre=0,post=2", "mg:omega=0.8,pre=0,post=2", "mg:pre=0,post=2,smoother=lattice",
          "mg:omega=0.8,pre=0,post=2,smoother=lattice", "ilu:1", "ebe", "cf", "mg", "ilu",
          "cf:inner=cgs,tol=1e-8", "sor:omega=1.25", "ssor:omega=0.8,sweeps=2", "mg:post=2",
          "mg:coarse=galerkin", "mg:precision=single", "sorcf:omega=1.2,block=1"})
        EXPECT_EQ(parse_pc(t).text(), t);
    // Defaults given explicitly print nothing; the key order is the entry's.
    EXPECT_EQ(parse_pc("ilu:0").text(), "ilu");
    EXPECT_EQ(parse_pc("mg:post=2,omega=1,pre=0").text(), "mg:pre=0,post=2");
    EXPECT_EQ(parse_pc("mg:smoother=lattice,omega=0.80,pre=0,post=2").text(),
              "mg:omega=0.8,pre=0,post=2,smoother=lattice");
}

// Every entry's default and every option it declares, set to a value other than its default,
// read back from its canonical text to the same spec; the usage line names every key.
TEST(Factory, EveryRegistryEntryRoundTripsThroughItsText) {
    for (const PreconditionerEntry& e : preconditioner_registry()) {
        ASSERT_TRUE(e.fields) << e.name << " has no parser (fields)";
        ASSERT_TRUE(e.build) << e.name << " has no builder";
        ASSERT_FALSE(e.summary.empty()) << e.name << " has no usage text";
        const std::string usage = e.usage();
        EXPECT_EQ(usage.rfind(e.name, 0), 0u) << usage;
        const PcSpec def = parse_pc(e.name);
        EXPECT_EQ(def.entry, &e);
        EXPECT_EQ(def.text(), e.name);
        EXPECT_EQ(parse_pc(def.text()), def) << e.name;
        const std::vector<PcKey> keys = e.keys();
        if (!e.positional_key.empty()) {
            EXPECT_TRUE(std::any_of(keys.begin(), keys.end(), [&](const PcKey& k) {
                return k.name == e.positional_key;
            })) << e.name;
        }
        for (const PcKey& k : keys) {
            EXPECT_NE(usage.find(k.name + "=" + k.placeholder), std::string::npos)
                << usage << " lacks " << k.name;
            ASSERT_NE(k.other, k.value) << e.name << ":" << k.name;
            const PcSpec s = parse_pc(e.name + ":" + k.name + "=" + k.other);
            EXPECT_NE(s, def) << e.name << ":" << k.name << "=" << k.other;
            const std::string text = s.text();
            EXPECT_NE(text.find(k.other), std::string::npos) << text;
            EXPECT_EQ(parse_pc(text), s) << text;
            EXPECT_EQ(parse_pc(text).text(), text);
        }
        // Every key at once, in reverse order: the text puts them back in the entry's order.
        if (keys.size() > 1) {
            std::string all = e.name + ":";
            for (size_t i = keys.size(); i-- > 0;)
                all += keys[i].name + "=" + keys[i].other + (i ? "," : "");
            const PcSpec s = parse_pc(all);
            EXPECT_EQ(parse_pc(s.text()), s) << all << " -> " << s.text();
            std::string ordered = e.name + ":";
            for (size_t i = 0; i < keys.size(); ++i)
                ordered += (keys[i].name == e.positional_key ? "" : keys[i].name + "=") +
                           keys[i].other + (i + 1 < keys.size() ? "," : "");
            EXPECT_EQ(s.text(), ordered);
        }
    }
}

TEST(Factory, CapabilitiesAreDeclaredOnTheEntry) {
    EXPECT_TRUE(parse_pc("mg").entry->single_level_too);
    EXPECT_TRUE(parse_pc("cf").entry->needs_level_below);
    EXPECT_FALSE(parse_pc("cf").entry->single_level_too);
    EXPECT_TRUE(parse_pc("ebe").entry->element_matrices);
    EXPECT_FALSE(parse_pc("ilu").entry->level_aware);
    EXPECT_TRUE(parse_pc("mg:smoother=lattice").lattice_numbering());
    EXPECT_FALSE(parse_pc("mg").lattice_numbering());
    EXPECT_FALSE(parse_pc("ilu").lattice_numbering());
    // On several processes: mg's rediscretized V-cycle with block or lattice sweeps in double or
    // single precision, the matrix-alone preconditioners and ebe; not the coarse/fine ones, mgr,
    // mg's algebraic hierarchy, or lattice sweeps in single precision.
    for (const char* ok :
         {"mg", "mg:omega=0.8,pre=0,post=2", "mg:coarse=rediscretize", "ilu:1", "diag", "sor",
          "ebe", "none", "mg:precision=single", "mg:smoother=lattice"})
        EXPECT_EQ(parse_pc(ok).distributed(), "") << ok;
    for (const char* no : {"cf", "sorcf", "mgr", "mg:coarse=galerkin", "mg:csize=100",
                           "mg:smoother=lattice,precision=single"})
        EXPECT_NE(parse_pc(no).distributed(), "") << no;
    EXPECT_NE(parse_pc("sorcf").distributed().find("'sorcf' has no distributed form"),
              std::string::npos);
    EXPECT_NE(parse_pc("mg:coarse=galerkin")
                  .distributed()
                  .find("mg:coarse=galerkin has no distributed form"),
              std::string::npos);
}

TEST(Factory, WhatIs2DOnlySaysSoThroughTheRegistry) {
    // Every built-in entry runs on a 2D level with its defaults and any options.
    for (const auto& e : preconditioner_registry())
        EXPECT_EQ(e.dimension_reason(e.defaults, 2), "") << e.name;
    for (const char* ok2 : {"mg:smoother=lattice", "amg:fn=2", "ebe"})
        EXPECT_EQ(parse_pc(ok2).dimension_reason(2), "") << ok2;
    // On a 3D level: mg's block sweep, the matrix-alone ones, the coarse/fine ones (they read
    // the transfers' coarse/fine splitting), amg with 3 (or 1) components per vertex; not the
    // lattice sweep of 2D macro triangles, ebe's triangle element matrices, amg:fn=2.
    for (const char* ok : {"mg", "mg:pre=2,post=2", "mg:coarse=aggregation", "ilu:1", "diag", "sor",
                           "none", "cf", "sorcf", "mgr", "amg:fn=3", "amg:fn=1"})
        EXPECT_EQ(parse_pc(ok).dimension_reason(3), "") << ok;
    const std::pair<const char*, const char*> no[] = {
        {"mg:smoother=lattice", "sweeps the lattices of 2D macro triangles (2D-only)"},
        {"ebe", "element matrices of triangles (2D-only)"},
        {"amg", "amg:fn=2 groups 2 interleaved components per vertex, but a level of 3 "
                "dimensions has 3: amg:fn=3"}};
    for (const auto& [text, why] : no)
        EXPECT_NE(parse_pc(text).dimension_reason(3).find(why), std::string::npos) << text;
    EXPECT_THROW(parse_pc("mg").dimension_reason(4), InvalidInput);
}

TEST(Factory, MethodNamesReadBack) {
    for (Method m : {Method::schur, Method::lu, Method::krylov})
        EXPECT_EQ(parse_method(to_string(m)), m);
    EXPECT_THROW(parse_method("cholesky"), InvalidInput);
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres})
        EXPECT_EQ(parse_krylov(to_string(k)), k);
}

TEST(Factory, RegisteringRefusesAnEntryWithoutParserOrUsage) {
    PreconditionerEntry e;
    e.name = "toy-without-fields";
    e.summary = "a toy";
    e.build = [](const PcOptions&, const LevelData*) -> std::unique_ptr<Preconditioner> {
        return std::make_unique<IdentityPreconditioner>();
    };
    EXPECT_THROW(register_preconditioner(e), InvalidInput); // no fields
    e.fields = [](PcOptions&, PcFields&) {};
    e.summary.clear();
    EXPECT_THROW(register_preconditioner(e), InvalidInput); // no usage text
    e.name = "mg";
    e.summary = "a toy";
    EXPECT_THROW(register_preconditioner(e), InvalidInput); // taken
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
