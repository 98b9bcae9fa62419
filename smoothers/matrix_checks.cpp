// SPDX-License-Identifier: MIT
// Entry checks shared by the smoothers and preconditioners.
#include "smoothers/matrix_checks.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>

namespace mlc::smoothers {

void check_setup_matrix(const SparseMatrix& A, std::string_view who) {
    MLC_CHECK(A.rows() == A.cols() && A.rows() > 0,
              who << ": expected a non-empty square matrix, found " << A.rows() << " x "
                  << A.cols());
    MLC_CHECK(A.isCompressed(),
              who << ": expected a compressed CSR matrix; call A.makeCompressed() first");
    const double* v = A.valuePtr();
    for (Index row = 0; row < A.rows(); ++row) {
        for (int p = A.outerIndexPtr()[row]; p < A.outerIndexPtr()[row + 1]; ++p) {
            MLC_CHECK(std::isfinite(v[p]), who << ": non-finite entry " << v[p] << " at (" << row
                                               << ", " << A.innerIndexPtr()[p]
                                               << "); fix the assembly");
        }
    }
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
