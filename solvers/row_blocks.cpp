// SPDX-License-Identifier: MIT
// The conversion of RowBlocks to DistributedRows (solvers/hypre/par_matrix.hpp). Plain Eigen, so
// it is built with or without hypre (the sanitizer tree has MLC_WITH_HYPRE=OFF).
#include "solvers/hypre/par_matrix.hpp"

namespace mlc::solvers {

DistributedRows distributed_rows(const RowBlocks& b) {
    DistributedRows rows;
    rows.first_row = b.first_row;
    rows.row_ptr.assign(1, 0);
    rows.cols.reserve(static_cast<size_t>(b.diag.nonZeros() + b.offd.nonZeros()));
    rows.values.reserve(rows.cols.capacity());
    for (Index i = 0; i < b.diag.rows(); ++i) {
        for (SparseMatrix::InnerIterator it(b.diag, i); it; ++it) {
            rows.cols.push_back(b.first_col + it.col());
            rows.values.push_back(it.value());
        }
        for (SparseMatrix::InnerIterator it(b.offd, i); it; ++it) {
            rows.cols.push_back(b.col_map[static_cast<size_t>(it.col())]);
            rows.values.push_back(it.value());
        }
        rows.row_ptr.push_back(static_cast<int>(rows.cols.size()));
    }
    return rows;
}

} // namespace mlc::solvers
