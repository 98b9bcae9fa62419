// SPDX-License-Identifier: MIT
// The diagonal block of a process's rows and the block-Jacobi-across-processes preconditioner.
#include "solvers/process_block.hpp"

#include "core/check.hpp"

#include <vector>

namespace mlc::solvers {

SparseMatrix diagonal_block(const DistributedRows& rows) {
    const int n = rows.n_rows();
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(rows.cols.size());
    for (int i = 0; i < n; ++i)
        for (int k = rows.row_ptr[static_cast<size_t>(i)];
             k < rows.row_ptr[static_cast<size_t>(i) + 1]; ++k) {
            const std::int64_t c = rows.cols[static_cast<size_t>(k)];
            MLC_CHECK(c >= 0, "diagonal_block: column " << c << " in row " << i);
            if (c >= rows.first_row && c < rows.first_row + n)
                trip.emplace_back(i, static_cast<int>(c - rows.first_row),
                                  rows.values[static_cast<size_t>(k)]);
        }
    SparseMatrix B(n, n);
    B.setFromTriplets(trip.begin(), trip.end());
    return B;
}

ProcessBlockPreconditioner::ProcessBlockPreconditioner(std::unique_ptr<Preconditioner> local)
    : local_(std::move(local)) {
    MLC_CHECK(local_ != nullptr, "ProcessBlockPreconditioner: no local preconditioner");
}

void ProcessBlockPreconditioner::setup_rows(const DistributedRows& rows) {
    block_ = diagonal_block(rows);
    local_->setup(block_);
}

void ProcessBlockPreconditioner::setup(const SparseMatrix& block) {
    block_ = block;
    local_->setup(block_);
}

void ProcessBlockPreconditioner::apply(const Vector& r, Vector& z) const {
    local_->apply(r, z);
}

std::string ProcessBlockPreconditioner::name() const {
    return "process-block(" + local_->name() + ")";
}

} // namespace mlc::solvers
