// SPDX-License-Identifier: MIT
// The V-cycle (solvers/vcycle.hpp) on a two-level toy: A_1 = diag(2, 4) smoothed by Jacobi
// damped by 1/2 (S = (2 D)^-1),
// T = [1; 1], R = T^T, and the exact coarse solve of R A_1 T = 6, against the cycle worked by
// hand.
#include "solvers/vcycle.hpp"

#include <gtest/gtest.h>

using namespace mlc;

namespace {

class Toy final : public solvers::VCycle,
                  solvers::CycleOperator,
                  solvers::CycleSmoother,
                  solvers::CycleTransfer {
public:
    Toy(int pre, int post) : pre_(pre), post_(post) {}
    Vector run(const Vector& r) const {
        Vector z;
        cycle(1, r, z);
        return z;
    }
    mutable int from_zero_calls = 0, coarse_calls = 0;

private:
    void residual(const Vector& r, const Vector& z, Vector& out) const override {
        out = r - d_.cwiseProduct(z);
    }
    void forward_from_zero(const Vector& r, Vector& z, Vector& out) const override {
        ++from_zero_calls;
        z = r.cwiseQuotient(2.0 * d_);
        residual(r, z, out);
    }
    void smooth(const Vector& r, Vector& z, smoothers::Sweep, int count) const override {
        for (int s = 0; s < count; ++s)
            z += (r - d_.cwiseProduct(z)).cwiseQuotient(2.0 * d_);
    }
    void restrict_residual(const Vector& x, Vector& y) const override {
        y = Vector::Constant(1, x.sum());
    }
    void prolongate(const Vector& e, Vector& z, bool add) const override {
        if (!add) z = Vector::Zero(2);
        z.array() += e[0];
    }
    solvers::CycleLevel cycle_level(int k) const override {
        EXPECT_EQ(k, 1);
        return {*this, *this, *this, pre_, post_, res_, rc_, ec_};
    }
    void coarse_solve(const Vector& r, Vector& z) const override {
        ++coarse_calls;
        z = r / 6.0;
    }

    int pre_, post_;
    Vector d_ = Vector{{2.0, 4.0}};
    mutable Vector res_, rc_, ec_;
};

} // namespace

TEST(VCycle, WithoutPreSmoothingRestrictsTheRightHandSideAndPostSmooths) {
    // r = (1, 1): rc = 2, ec = 1/3, z = (1/3, 1/3); one sweep: z + (r - A z) / (2 d) =
    // (1/3 + 1/12, 1/3 - 1/24) = (5/12, 7/24).
    const Toy toy(0, 1);
    const Vector z = toy.run(Vector{{1.0, 1.0}});
    EXPECT_DOUBLE_EQ(z[0], 5.0 / 12.0);
    EXPECT_DOUBLE_EQ(z[1], 7.0 / 24.0);
    EXPECT_EQ(toy.from_zero_calls, 0);
    EXPECT_EQ(toy.coarse_calls, 1);
}

TEST(VCycle, PreSmoothingThenTheCoarseCorrectionOfItsResidual) {
    // One pre-sweep on r = (1, 1): z = (1/4, 1/8), res = (1/2, 1/2), rc = 1, ec = 1/6:
    // z = (5/12, 7/24).
    const Toy one(1, 0);
    Vector z = one.run(Vector{{1.0, 1.0}});
    EXPECT_DOUBLE_EQ(z[0], 5.0 / 12.0);
    EXPECT_DOUBLE_EQ(z[1], 7.0 / 24.0);
    EXPECT_EQ(one.from_zero_calls, 1);
    // Two: z = (3/8, 3/16), res = (1/4, 1/4) (the operator's residual), ec = 1/12:
    // z = (11/24, 13/48).
    const Toy two(2, 0);
    z = two.run(Vector{{1.0, 1.0}});
    EXPECT_DOUBLE_EQ(z[0], 11.0 / 24.0);
    EXPECT_DOUBLE_EQ(z[1], 13.0 / 48.0);
    EXPECT_EQ(two.from_zero_calls, 1);
    EXPECT_EQ(two.coarse_calls, 1);
}
