// SPDX-License-Identifier: MIT
/// @file Reproducible random vectors for the tests.
#pragma once

#include "core/types.hpp"

#include <random>

namespace mlc::testutil {

/// n entries uniform in [-1, 1), from std::mt19937(seed).
inline Vector random_vector(Index n, unsigned seed) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    Vector x(n);
    for (Index i = 0; i < n; ++i)
        x[i] = U(gen);
    return x;
}

} // namespace mlc::testutil
