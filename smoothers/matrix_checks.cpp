// SPDX-License-Identifier: MIT
// Entry checks shared by the smoothers and preconditioners.
#include "smoothers/matrix_checks.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mlc::smoothers {

void check_setup_matrix(const SparseMatrix& A, std::string_view who) {
    MLC_CHECK(A.rows() == A.cols() && A.rows() > 0,
              who << ": expected a non-empty square matrix, found " << A.rows() << " x "
                  << A.cols());
    MLC_CHECK(A.isCompressed(),
              who << ": expected a compressed CSR matrix; call A.makeCompressed() first");
    // The values over the threads (a Newton Jacobian is checked at every refresh: at level 6 of
    // the square 29 million values); each chunk finds its first non-finite entry, and the
    // lowest chunk's is reported, the entry a serial scan would name.
    const double* v = A.valuePtr();
    const int* outer = A.outerIndexPtr();
    const parallel::RowChunks rc =
        parallel::row_chunks(static_cast<size_t>(A.rows()), static_cast<size_t>(kMinRowsPerThread));
    std::vector<int> first_bad(rc.count, -1);
    parallel::for_chunks(rc.count, [&](size_t c) {
        const int p0 = outer[rc.begin(c)], p1 = outer[rc.end(c)];
        bool finite = true;
        for (int p = p0; p < p1; ++p)
            finite &= std::isfinite(v[p]);
        if (finite) return;
        for (int p = p0; p < p1; ++p)
            if (!std::isfinite(v[p])) {
                first_bad[c] = p;
                return;
            }
    });
    for (const int p : first_bad) {
        if (p < 0) continue;
        const Index row = std::upper_bound(outer, outer + A.rows() + 1, p) - outer - 1;
        MLC_CHECK(false, who << ": non-finite entry " << v[p] << " at (" << row << ", "
                             << A.innerIndexPtr()[p] << "); fix the assembly");
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
