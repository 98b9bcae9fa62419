// SPDX-License-Identifier: MIT
// The Alart–Curnier projection as one template for dim = 2 and 3: the 3D derivative M against
// central differences, the Coulomb disc, the 2D law recovered from 3D along a tangent axis and
// bit for bit from the template, and mu = 0.
#include "contact/law.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

using namespace mlc;
using contact::Status;

namespace {

using Tangent2 = Eigen::Matrix<double, 2, 1>;
using Tangent1 = Eigen::Matrix<double, 1, 1>;

/// The 2D law as it was written before the template: the reference for bitwise equality.
contact::Projection law3_reference_2d(double sigma_t, double sigma_n, double mu) {
    contact::Projection p;
    if (sigma_n > 0) return p;
    const double bound = -mu * sigma_n;
    if (std::abs(sigma_t) <= bound) {
        p.status = Status::stick;
        p.phi = {sigma_t, sigma_n};
        p.M.setIdentity();
        return p;
    }
    const double eps = sigma_t > 0 ? 1.0 : -1.0;
    p.status = eps > 0 ? Status::slip_forward : Status::slip_backward;
    p.phi = {eps * bound, sigma_n};
    p.M << 0.0, -eps * mu, 0.0, 1.0;
    return p;
}

/// Same bits (so +0 and -0 differ, and a NaN equals the same NaN).
template <class A, class B> bool law3_same_bits(const A& a, const B& b) {
    static_assert(sizeof(a) == sizeof(b));
    return std::memcmp(a.data(), b.data(), sizeof(a)) == 0;
}

enum class Region { gap, stick, slip };

/// A random sigma = (sigma_t, sigma_n) in `region`, with |sigma| of order `scale`, away from
/// the region's boundaries: |sigma_n| >= 0.05 scale, and |sigma_t| off the stick-slip boundary
/// mu |sigma_n| by at least a tenth of it.
std::pair<Tangent2, double> law3_random_sigma(std::mt19937& rng, Region region, double mu,
                                              double scale) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int tries = 0; tries < 1000000; ++tries) {
        const Tangent2 st(scale * u(rng), scale * u(rng));
        const double sn = scale * u(rng);
        const double bound = -mu * sn, nt = st.norm();
        if (std::abs(sn) < 0.05 * scale) continue;
        if (region == Region::gap && sn > 0) return {st, sn};
        if (sn > 0) continue;
        if (region == Region::stick && nt < 0.9 * bound) return {st, sn};
        if (region == Region::slip && nt > 1.1 * bound && nt > 0.05 * scale) return {st, sn};
    }
    throw std::logic_error("law3_random_sigma: no point found in the region");
}

/// Central differences of Phi at sigma with step h in each of the three components.
Eigen::Matrix3d law3_central_differences(const Tangent2& st, double sn, double mu, double h) {
    Eigen::Matrix3d fd;
    for (int j = 0; j < 3; ++j) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d[j] = h;
        const auto plus = contact::project<3>(st + d.head<2>(), sn + d[2], mu);
        const auto minus = contact::project<3>(st - d.head<2>(), sn - d[2], mu);
        fd.col(j) = (plus.phi - minus.phi) / (2 * h);
    }
    return fd;
}

} // namespace

TEST(Law3, DerivativeMatchesCentralDifferencesInEachRegion) {
    std::mt19937 rng(20240);
    int checked = 0;
    for (double mu : {0.1, 0.5, 1.0, 2.3})
        for (double scale : {1e-3, 1.0, 1e4})
            for (Region region : {Region::gap, Region::stick, Region::slip})
                for (int k = 0; k < 20; ++k) {
                    const auto [st, sn] = law3_random_sigma(rng, region, mu, scale);
                    const auto p = contact::project<3>(st, sn, mu);
                    const Status expected = region == Region::gap     ? Status::gap
                                            : region == Region::stick ? Status::stick
                                                                      : Status::slip;
                    ASSERT_EQ(p.status, expected);
                    const Eigen::Matrix3d fd = law3_central_differences(st, sn, mu, 1e-6 * scale);
                    EXPECT_LE((fd - p.M).norm(), 1e-6 * std::max(1.0, p.M.norm()))
                        << "mu " << mu << " sigma_t " << st.transpose() << " sigma_n " << sn
                        << "\nM\n"
                        << p.M << "\nfinite differences\n"
                        << fd;
                    ++checked;
                }
    EXPECT_EQ(checked, 4 * 3 * 3 * 20);
}

TEST(Law3, SlipDerivativeIsTheDiscProjectionsWithRhoBelowOne) {
    // sigma_t = (3, 4), sigma_n = -2, mu = 1: |sigma_t| = 5, s = (0.6, 0.8), rho = 2 / 5.
    const auto p = contact::project<3>(Tangent2(3.0, 4.0), -2.0, 1.0);
    ASSERT_EQ(p.status, Status::slip);
    EXPECT_EQ(p.slip_direction, Tangent2(0.6, 0.8));
    EXPECT_NEAR(p.phi[0], 1.2, 1e-15);
    EXPECT_NEAR(p.phi[1], 1.6, 1e-15);
    EXPECT_EQ(p.phi[2], -2.0);
    Eigen::Matrix3d M;
    M << 0.4 * 0.64, -0.4 * 0.48, -0.6, //
        -0.4 * 0.48, 0.4 * 0.36, -0.8,  //
        0.0, 0.0, 1.0;
    EXPECT_LE((p.M - M).norm(), 1e-15);
}

TEST(Law3, SlipPutsPhiTOnTheCoulombDiscAlongSigmaT) {
    std::mt19937 rng(77);
    for (double mu : {0.05, 0.3, 1.0, 4.0})
        for (int k = 0; k < 200; ++k) {
            const auto [st, sn] = law3_random_sigma(rng, Region::slip, mu, 10.0);
            const auto p = contact::project<3>(st, sn, mu);
            ASSERT_EQ(p.status, Status::slip);
            const Tangent2 phi_t = p.phi.head<2>();
            EXPECT_NEAR(phi_t.norm(), mu * std::abs(sn), 1e-14 * mu * std::abs(sn));
            EXPECT_NEAR(p.slip_direction.norm(), 1.0, 1e-15);
            EXPECT_LE((p.slip_direction - st / st.norm()).norm(), 1e-15);
            EXPECT_LE((phi_t - mu * std::abs(sn) * p.slip_direction).norm(), 1e-14 * phi_t.norm());
            EXPECT_EQ(p.phi[2], sn);
            // rho (I - s s^T) has s in its null space and the tangent across s as eigenvector
            // with eigenvalue rho = mu |sigma_n| / |sigma_t| < 1.
            const Eigen::Matrix2d block = p.M.topLeftCorner<2, 2>();
            const Tangent2 across(-p.slip_direction[1], p.slip_direction[0]);
            const double rho = mu * std::abs(sn) / st.norm();
            EXPECT_LT(rho, 1.0);
            EXPECT_LE((block * p.slip_direction).norm(), 1e-15);
            EXPECT_LE((block * across - rho * across).norm(), 1e-15);
        }
}

TEST(Law3, StickAndGapAreIdentityAndZero) {
    // |sigma_t| = 0.625 = bound exactly (3-4-5 in eighths): the boundary belongs to stick.
    auto p = contact::project<3>(Tangent2(0.375, -0.5), -1.0, 0.625);
    EXPECT_EQ(p.status, Status::stick);
    EXPECT_EQ(p.phi, Eigen::Vector3d(0.375, -0.5, -1.0));
    EXPECT_EQ(p.M, Eigen::Matrix3d::Identity());
    EXPECT_EQ(p.slip_direction, Tangent2::Zero());
    p = contact::project<3>(Tangent2(0.375, -0.5), 0.0, 0.625); // sigma_n = 0: slip with Phi = 0
    EXPECT_EQ(p.status, Status::slip);
    EXPECT_EQ(p.phi.norm(), 0.0);
    p = contact::project<3>(Tangent2(0.0, 0.0), 0.0, 0.5); // the apex belongs to stick
    EXPECT_EQ(p.status, Status::stick);
    EXPECT_EQ(p.M, Eigen::Matrix3d::Identity());
    p = contact::project<3>(Tangent2(5.0, 1.0), 1e-300, 0.5);
    EXPECT_EQ(p.status, Status::gap);
    EXPECT_EQ(p.phi, Eigen::Vector3d::Zero());
    EXPECT_EQ(p.M, Eigen::Matrix3d::Zero());
}

TEST(Law3, SigmaTAlongOneTangentAxisGivesThe2DValues) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    int slips = 0, sticks = 0, gaps = 0;
    for (int k = 0; k < 2000; ++k) {
        const double a = u(rng), sn = u(rng), mu = 0.5 * (u(rng) + 2.0);
        const auto p2 = contact::project(a, sn, mu);
        for (int axis : {0, 1}) {
            Tangent2 st = Tangent2::Zero();
            st[axis] = a;
            const auto p3 = contact::project<3>(st, sn, mu);
            const Status want =
                p2.status == Status::slip_forward || p2.status == Status::slip_backward
                    ? Status::slip
                    : p2.status;
            ASSERT_EQ(p3.status, want) << a << " " << sn << " " << mu;
            const int other = 1 - axis;
            EXPECT_EQ(p3.phi[axis], p2.phi[0]);
            EXPECT_EQ(p3.phi[other], 0.0);
            EXPECT_EQ(p3.phi[2], p2.phi[1]);
            EXPECT_EQ(p3.M(axis, axis), p2.M(0, 0));
            EXPECT_EQ(p3.M(axis, 2), p2.M(0, 1));
            EXPECT_EQ(p3.M(2, axis), p2.M(1, 0));
            EXPECT_EQ(p3.M(2, 2), p2.M(1, 1));
            EXPECT_EQ(p3.M(axis, other), 0.0);
            EXPECT_EQ(p3.M(other, 2), 0.0);
            if (want == Status::slip) {
                EXPECT_EQ(p3.slip_direction[axis], p2.status == Status::slip_forward ? 1.0 : -1.0);
                EXPECT_EQ(p3.slip_direction[other], 0.0);
                // Across the slip the disc projection scales by rho (the 2D law has no such
                // direction): M(other, other) = mu |sigma_n| / |sigma_t|.
                EXPECT_DOUBLE_EQ(p3.M(other, other), mu * std::abs(sn) / std::abs(a));
            }
        }
        slips += p2.status == Status::slip_forward || p2.status == Status::slip_backward;
        sticks += p2.status == Status::stick;
        gaps += p2.status == Status::gap;
    }
    EXPECT_GT(slips, 100);
    EXPECT_GT(sticks, 100);
    EXPECT_GT(gaps, 100);
}

TEST(Law3, TwoDimensionalTemplateIsTheOld2DLawBitForBit) {
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<std::array<double, 3>> cases; // (sigma_t, sigma_n, mu)
    std::mt19937 rng(123);
    std::uniform_real_distribution<double> u(-1.0, 1.0), e(-12.0, 12.0);
    for (int k = 0; k < 20000; ++k) {
        const double st = u(rng) * std::pow(10.0, e(rng)), sn = u(rng) * std::pow(10.0, e(rng));
        const double mu = std::abs(u(rng)) * std::pow(10.0, e(rng) / 6.0);
        cases.push_back({st, sn, mu});
        cases.push_back({-mu * sn, sn, mu}); // |sigma_t| = bound exactly
        cases.push_back({mu * sn, sn, mu});
        cases.push_back({std::nextafter(-mu * sn, inf), sn, mu});
        cases.push_back({st, sn, 0.0});
        cases.push_back({st, 0.0, mu});
        cases.push_back({st, -0.0, mu});
    }
    for (double st : {0.0, -0.0, 1.0, -1.0, 0.5, -0.5, inf, -inf, nan})
        for (double sn : {0.0, -0.0, -1.0, 1.0, -inf, inf, nan})
            for (double mu : {0.0, 0.5, 1.0})
                cases.push_back({st, sn, mu});
    int slip = 0, stick = 0, gap = 0;
    for (const auto& [st, sn, mu] : cases) {
        const contact::Projection want = law3_reference_2d(st, sn, mu);
        const contact::Projection got = contact::project(st, sn, mu);
        const contact::LawProjection<2> tpl = contact::project<2>(Tangent1(st), sn, mu);
        ASSERT_EQ(got.status, want.status) << st << " " << sn << " " << mu;
        ASSERT_TRUE(law3_same_bits(got.phi, want.phi)) << st << " " << sn << " " << mu;
        ASSERT_TRUE(law3_same_bits(got.M, want.M)) << st << " " << sn << " " << mu;
        ASSERT_EQ(tpl.status, want.status);
        ASSERT_TRUE(law3_same_bits(tpl.phi, want.phi));
        ASSERT_TRUE(law3_same_bits(tpl.M, want.M));
        const double dir = want.status == Status::slip_forward    ? 1.0
                           : want.status == Status::slip_backward ? -1.0
                                                                  : 0.0;
        ASSERT_EQ(tpl.slip_direction[0], dir);
        slip += want.status == Status::slip_forward || want.status == Status::slip_backward;
        stick += want.status == Status::stick;
        gap += want.status == Status::gap;
    }
    EXPECT_GT(slip, 10000);
    EXPECT_GT(stick, 10000);
    EXPECT_GT(gap, 10000);
}

TEST(Law3, FrictionlessGivesZeroTangentialPhiAndBlock) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    for (int k = 0; k < 1000; ++k) {
        const Tangent2 st(u(rng), u(rng));
        const double sn = u(rng);
        const auto p = contact::project<3>(st, sn, 0.0);
        EXPECT_EQ(p.phi[0], 0.0);
        EXPECT_EQ(p.phi[1], 0.0);
        EXPECT_EQ(p.phi[2], std::min(sn, 0.0));
        EXPECT_EQ((p.M.topLeftCorner<2, 2>().norm()), 0.0);
        EXPECT_EQ((p.M.topRightCorner<2, 1>().norm()), 0.0);
        EXPECT_EQ(p.M(2, 2), sn > 0 ? 0.0 : 1.0);
        EXPECT_EQ(p.status, sn > 0 ? Status::gap : Status::slip);
        const auto p2 = contact::project(st[0], sn, 0.0);
        EXPECT_EQ(p2.phi[0], 0.0);
        EXPECT_EQ(p2.M(0, 0), 0.0);
        EXPECT_EQ(p2.M(0, 1), 0.0);
    }
}

TEST(Law3, StatusNamesAndValues) {
    EXPECT_EQ(contact::to_string(Status::slip), "slip");
    EXPECT_EQ(contact::to_string(Status::slip_backward), "slip_backward");
    EXPECT_EQ(static_cast<int>(Status::gap), 0);
    EXPECT_EQ(static_cast<int>(Status::stick), 1);
    EXPECT_EQ(static_cast<int>(Status::slip_forward), 2);
    EXPECT_EQ(static_cast<int>(Status::slip_backward), 3);
    EXPECT_EQ(static_cast<int>(Status::slip), 4);
}
