// SPDX-License-Identifier: MIT
// Entry checks shared by the smoothers and preconditioners.
#include "smoothers/matrix_checks.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/first_touch.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace mlc::smoothers {

void check_setup_matrix(const SparseMatrix& A, std::string_view who) {
    MLC_CHECK(A.rows() == A.cols() && A.rows() > 0,
              who << ": expected a non-empty square matrix, found " << A.rows() << " x "
                  << A.cols());
    MLC_CHECK(A.isCompressed(),
              who << ": expected a compressed CSR matrix; call A.makeCompressed() first");
    // The values over the threads (a Newton Jacobian is checked at every refresh: at level 6 of
    // the square 29 million values); the first non-finite entry is named.
    const double* v = A.valuePtr();
    const auto nnz = static_cast<size_t>(A.nonZeros());
    const size_t bad =
        parallel::first_flagged(nnz, parallel::kTouchRowsPerChunk, [&](size_t b, size_t e) {
            bool finite = true;
            for (size_t k = b; k < e; ++k)
                finite &= std::isfinite(v[k]);
            if (finite) return e;
            return static_cast<size_t>(
                std::find_if(v + b, v + e, [](double x) { return !std::isfinite(x); }) - v);
        });
    MLC_CHECK(bad == nnz, who << ": non-finite entry " << v[bad] << " at ("
                              << row_of_entry(A, static_cast<Index>(bad)) << ", "
                              << A.innerIndexPtr()[bad] << "); fix the assembly");
}

void check_size(const Vector& v, Index n, std::string_view who, std::string_view what) {
    MLC_CHECK(v.size() == n, who << ": " << what << " has size " << v.size() << ", expected " << n
                                 << " (the size of the matrix given to setup)");
}

double row_max_abs(const SparseMatrix& A, Index i) {
    double m = 0.0;
    for (int p = A.outerIndexPtr()[i]; p < A.outerIndexPtr()[i + 1]; ++p)
        m = std::max(m, std::abs(A.valuePtr()[p]));
    return m;
}

} // namespace mlc::smoothers
