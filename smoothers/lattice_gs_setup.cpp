// SPDX-License-Identifier: MIT
// The lattice smoother's setup (LatticeGS::derive), in phases: the blocks, the visit order and
// its parts, the deep and semi-deep points of each macro, the visit codes, the items of each part
// and the rows of the row-swept blocks.
#include "core/check.hpp"
#include "core/parallel.hpp"
#include "smoothers/lattice_gs.hpp"
#include "smoothers/lattice_gs_layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace mlc::smoothers {

using namespace lattice;

/// What the phases of derive hand on: the blocks, the visit order, the parts and, per block, its
/// kind (deep, semi-deep or row-swept).
struct lattice::Layout {
    std::vector<Index> starts;      // first row of each block, then n
    Index nb = 0;                   // blocks
    std::vector<int> block_of_row;  // per row: its block
    std::vector<int> order;         // the visit: blocks in order
    std::vector<int> part_of_block; // per block: its part
    std::vector<int> cut;           // parts' first visit entries, then nb
    std::vector<int> deep_len;      // per block: its lattice row's length if deep, 0 semi-deep
    std::vector<int> deep_mac;      // per block: its macro if (semi-)deep
    std::vector<int> semi_of_block; // per block: its index among the semi-deep points, or -1
};

namespace {

/// The points one macro contributes, gathered over the macros in macro order.
struct MacroPoints {
    std::vector<int> rows, lens;          // deep points: first row, lattice row's length
    std::vector<std::uint8_t> slots;      // deep points: 7 slots each
    std::vector<int> semi_nbr;            // semi-deep points: 7 neighbour rows each
    std::vector<std::uint8_t> semi_slots; // semi-deep points: 7 slots each
};

/// The macro's stencil S from the seven 2x2 blocks v of a deep point (det: of the centre block):
/// the blocks, omega D^{-1}, G_east and G_west, then the ten blocks packed.
void set_stencil(const std::array<double, 28>& v, double det, double omega, double* S) {
    std::copy(v.begin(), v.end(), S);
    const double f = omega / det;
    S[28] = f * v[3];
    S[29] = -f * v[1];
    S[30] = -f * v[2];
    S[31] = f * v[0];
    for (int g = 0; g < 2; ++g) { // G_east (slot 1) at 32, G_west (slot 2) at 36
        const double* B = S + 4 + 4 * g;
        double* G = S + 32 + 4 * g;
        G[0] = S[28] * B[0] + S[29] * B[2];
        G[1] = S[28] * B[1] + S[29] * B[3];
        G[2] = S[30] * B[0] + S[31] * B[2];
        G[3] = S[30] * B[1] + S[31] * B[3];
    }
    for (int q = 0; q < 10; ++q) {
        const double* B = S + 4 * q;
        double* Q = S + kPacked + 4 * q;
        Q[0] = B[0];
        Q[1] = B[3];
        Q[2] = B[1];
        Q[3] = B[2];
    }
}

/// Macro m's deep points: interior points at least two points from its edges, all of whose
/// neighbours lie in their part, whose rows are seven plain 2x2 blocks equal (within tol) to the
/// first such point's, which sets the macro's stencil S. False if the macro has none.
bool macro_deep_points(const SparseMatrix& A, Layout& lay, const LatticeRows& lat,
                       const LatticeGSParams& prm, long m, double* S, double& tol,
                       MacroPoints& out) {
    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    const double* av = A.valuePtr();
    const int N = lat.n;
    const long np = LatticeRows::interior_points(N);
    const Index* fr = lat.first_row.data() + m * np;
    const auto& block_of_row = lay.block_of_row;
    const auto& part_of_block = lay.part_of_block;
    bool have = false;
    for (int j = 2; j <= N - 4; ++j)
        for (int i = 2; i + j <= N - 2; ++i) {
            std::array<Index, kSlots> nbr{};
            for (int s = 0; s < kSlots; ++s)
                nbr[static_cast<size_t>(s)] =
                    fr[LatticeRows::point_index(N, i + kDi[s], j + kDj[s])];
            const Index r = nbr[0];
            const int part =
                part_of_block[static_cast<size_t>(block_of_row[static_cast<size_t>(r)])];
            bool same_part = true;
            for (int s = 1; s < kSlots; ++s)
                same_part =
                    same_part &&
                    part_of_block[static_cast<size_t>(
                        block_of_row[static_cast<size_t>(nbr[static_cast<size_t>(s)])])] == part;
            if (!same_part) continue;
            if (ao[r + 1] - ao[r] != 2 * kSlots || ao[r + 2] - ao[r + 1] != 2 * kSlots) continue;
            std::array<double, 28> v{};
            std::array<std::uint8_t, kSlots> slots{};
            bool fits = true;
            for (int q = 0; q < kSlots && fits; ++q) {
                const int c0 = ai[ao[r] + 2 * q], c1 = ai[ao[r] + 2 * q + 1];
                const int d0 = ai[ao[r + 1] + 2 * q], d1 = ai[ao[r + 1] + 2 * q + 1];
                int s = 0;
                while (s < kSlots && nbr[static_cast<size_t>(s)] != c0)
                    ++s;
                fits = s < kSlots && c1 == c0 + 1 && d0 == c0 && d1 == c1;
                if (!fits) break;
                slots[static_cast<size_t>(q)] = static_cast<std::uint8_t>(s);
                v[static_cast<size_t>(4 * s)] = av[ao[r] + 2 * q];
                v[static_cast<size_t>(4 * s + 1)] = av[ao[r] + 2 * q + 1];
                v[static_cast<size_t>(4 * s + 2)] = av[ao[r + 1] + 2 * q];
                v[static_cast<size_t>(4 * s + 3)] = av[ao[r + 1] + 2 * q + 1];
            }
            if (!fits) continue;
            if (!have) {
                // The macro's stencil: this point's rows, with omega D^{-1} of the centre.
                const double det = v[0] * v[3] - v[1] * v[2];
                const double dscale = std::abs(v[0] * v[3]) + std::abs(v[1] * v[2]);
                if (!(dscale > 0.0 && std::abs(det) > prm.singular_tol * dscale)) continue;
                have = true;
                set_stencil(v, det, prm.omega, S);
                double mx = 0.0;
                for (double x : v)
                    mx = std::max(mx, std::abs(x));
                tol = prm.stencil_tol * mx;
            } else {
                bool match = true;
                for (int e = 0; e < 28 && match; ++e)
                    match = std::abs(v[static_cast<size_t>(e)] - S[e]) <= tol;
                if (!match) continue;
            }
            const int b = block_of_row[static_cast<size_t>(r)];
            lay.deep_len[static_cast<size_t>(b)] = N - 1 - j;
            lay.deep_mac[static_cast<size_t>(b)] = static_cast<int>(m);
            out.rows.push_back(static_cast<int>(r));
            out.lens.push_back(N - 1 - j);
            out.slots.insert(out.slots.end(), slots.begin(), slots.end());
        }
    return have;
}

/// Macro m's semi-deep points: every other interior point whose seven column pairs are plain 2x2
/// blocks of its part, matched to the slots: the interior neighbours by their rows, the others
/// (on the macro's edges) by their values among the slots left.
void macro_semi_points(const SparseMatrix& A, Layout& lay, const LatticeRows& lat, long m,
                       const double* S, double tol, MacroPoints& out) {
    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    const double* av = A.valuePtr();
    const int N = lat.n;
    const long np = LatticeRows::interior_points(N);
    const Index* fr = lat.first_row.data() + m * np;
    const auto& starts = lay.starts;
    const auto& block_of_row = lay.block_of_row;
    const auto& part_of_block = lay.part_of_block;
    for (int j = 1; j <= N - 2; ++j)
        for (int i = 1; i + j <= N - 1; ++i) {
            const Index r = fr[LatticeRows::point_index(N, i, j)];
            const int b = block_of_row[static_cast<size_t>(r)];
            if (lay.deep_len[static_cast<size_t>(b)] >= 0) continue;
            if (ao[r + 1] - ao[r] != 2 * kSlots || ao[r + 2] - ao[r + 1] != 2 * kSlots) continue;
            const int part = part_of_block[static_cast<size_t>(b)];
            std::array<Index, kSlots> known{};
            for (int t = 0; t < kSlots; ++t) {
                const int ii = i + kDi[t], jj = j + kDj[t];
                known[static_cast<size_t>(t)] = ii >= 1 && jj >= 1 && ii + jj <= N - 1
                                                    ? fr[LatticeRows::point_index(N, ii, jj)]
                                                    : -1;
            }
            std::array<std::uint8_t, kSlots> slots{};
            std::array<int, kSlots> nbr{};
            unsigned used = 0;
            bool fits = true;
            for (int q = 0; q < kSlots && fits; ++q) {
                const int c0 = ai[ao[r] + 2 * q], c1 = ai[ao[r] + 2 * q + 1];
                const int d0 = ai[ao[r + 1] + 2 * q], d1 = ai[ao[r + 1] + 2 * q + 1];
                const int cb = block_of_row[static_cast<size_t>(c0)];
                fits = c1 == c0 + 1 && d0 == c0 && d1 == c1 && starts[cb] == c0 &&
                       starts[cb + 1] == c0 + 2 && part_of_block[static_cast<size_t>(cb)] == part;
                if (!fits) break;
                const double w[4] = {av[ao[r] + 2 * q], av[ao[r] + 2 * q + 1],
                                     av[ao[r + 1] + 2 * q], av[ao[r + 1] + 2 * q + 1]};
                auto matches = [&](int t) {
                    for (int e = 0; e < 4; ++e)
                        if (!(std::abs(w[e] - S[4 * t + e]) <= tol)) return false;
                    return true;
                };
                int t = 0;
                while (t < kSlots && known[static_cast<size_t>(t)] != c0)
                    ++t;
                if (t == kSlots) { // on an edge: the first free edge slot with its values
                    t = 0;
                    while (t < kSlots &&
                           (known[static_cast<size_t>(t)] >= 0 || (used >> t & 1u) || !matches(t)))
                        ++t;
                }
                fits = t < kSlots && !(used >> t & 1u) && matches(t);
                if (!fits) break;
                used |= 1u << t;
                slots[static_cast<size_t>(q)] = static_cast<std::uint8_t>(t);
                nbr[static_cast<size_t>(t)] = c0;
            }
            if (!fits || used != (1u << kSlots) - 1) continue;
            lay.deep_len[static_cast<size_t>(b)] = 0; // semi-deep
            lay.deep_mac[static_cast<size_t>(b)] = static_cast<int>(m);
            out.semi_nbr.insert(out.semi_nbr.end(), nbr.begin(), nbr.end());
            out.semi_slots.insert(out.semi_slots.end(), slots.begin(), slots.end());
        }
}

} // namespace

void LatticeGS::derive(const SparseMatrix& A) {
    A_ = &A;
    n_ = A.rows();
    Layout lay;
    derive_blocks(lay);
    derive_parts(A, lay);
    derive_points(A, lay);
    number_visits(lay);
    group_items();
    derive_swept_rows(A, lay);
    outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + n_ + 1);
    nnz_ = A.nonZeros();
}

void LatticeGS::derive_blocks(Layout& lay) const {
    lay.starts = block_starts_in_.empty() ? uniform_block_starts(n_, 2) : block_starts_in_;
    auto& starts = lay.starts;
    if (starts.back() != n_) starts.push_back(n_);
    MLC_CHECK(starts.front() == 0, "lattice smoother: the blocks must start at row 0");
    const Index nb = lay.nb = static_cast<Index>(starts.size()) - 1;
    lay.block_of_row.resize(static_cast<size_t>(n_));
    for (Index b = 0; b < nb; ++b) {
        MLC_CHECK(starts[b] < starts[b + 1], "lattice smoother: block starts must increase");
        for (Index r = starts[b]; r < starts[b + 1]; ++r)
            lay.block_of_row[static_cast<size_t>(r)] = static_cast<int>(b);
    }
}

void LatticeGS::derive_parts(const SparseMatrix& A, Layout& lay) const {
    const int* ao = A.outerIndexPtr();
    const auto& starts = lay.starts;
    const auto& block_of_row = lay.block_of_row;
    const Index nb = lay.nb;
    // The visit order and its parts: runs of about equal nonzeros (BlockSOR's cut).
    auto& order = lay.order;
    order.resize(static_cast<size_t>(nb));
    if (lattice_.visit.empty()) {
        for (Index b = 0; b < nb; ++b)
            order[static_cast<size_t>(b)] = static_cast<int>(b);
    } else {
        MLC_CHECK(static_cast<Index>(lattice_.visit.size()) == nb,
                  "lattice smoother: the visit lists " << lattice_.visit.size() << " blocks of "
                                                       << nb);
        std::vector<char> seen(static_cast<size_t>(nb), 0);
        for (size_t i = 0; i < lattice_.visit.size(); ++i) {
            const Index r = lattice_.visit[i];
            MLC_CHECK(r >= 0 && r < n_ && starts[block_of_row[static_cast<size_t>(r)]] == r &&
                          !seen[static_cast<size_t>(block_of_row[static_cast<size_t>(r)])],
                      "lattice smoother: visit entry " << i << " (row " << r
                                                       << ") is not a block's first row, or "
                                                          "repeats one");
            order[i] = block_of_row[static_cast<size_t>(r)];
            seen[static_cast<size_t>(order[i])] = 1;
        }
    }
    const Index P = hybrid_part_count(params_.parts, n_, nb);
    lay.part_of_block.assign(static_cast<size_t>(nb), 0);
    auto& cut = lay.cut;
    cut.assign(1, 0);
    const double per_part = static_cast<double>(A.nonZeros()) / static_cast<double>(P);
    double cum = 0.0;
    int p = 0;
    for (Index i = 0; i < nb; ++i) {
        const int b = order[static_cast<size_t>(i)];
        lay.part_of_block[static_cast<size_t>(b)] = p;
        cum += static_cast<double>(ao[starts[b + 1]] - ao[starts[b]]);
        if (p + 1 < P && cum >= per_part * (p + 1)) {
            cut.push_back(static_cast<int>(i + 1));
            ++p;
        }
    }
    while (static_cast<Index>(cut.size()) < P + 1)
        cut.push_back(static_cast<int>(nb));
    cut.back() = static_cast<int>(nb);
}

void LatticeGS::derive_points(const SparseMatrix& A, Layout& lay) {
    // Macros numbered as a lattice: every interior point a plain 2x2 block at row0 + 2p.
    const long np = LatticeRows::interior_points(lattice_.n);
    const long n_macros = lattice_.macros();
    const Index nb = lay.nb;
    // Deep points, macro by macro over the threads (each writes its own stencil and lists).
    lay.deep_len.assign(static_cast<size_t>(nb), -1);
    lay.deep_mac.assign(static_cast<size_t>(nb), -1);
    stencils_.assign(static_cast<size_t>(n_macros) * kStencil, 0.0);
    // Semi-deep points: interior points whose rows hold the macro's stencil but some of whose
    // neighbours lie on the macro's edges (no fixed offset): their neighbours' rows by slot.
    std::vector<MacroPoints> macro(static_cast<size_t>(n_macros));
    parallel::for_chunks(static_cast<size_t>(n_macros), [&](size_t m) {
        const Index row0 = lattice_.lattice_base(static_cast<long>(m));
        if (row0 < 0 || row0 + 2 * np > n_) return;
        for (long q = 0; q < np; ++q) {
            const Index r = row0 + 2 * q;
            const int b = lay.block_of_row[static_cast<size_t>(r)];
            if (lay.starts[b] != r || lay.starts[b + 1] != r + 2) return;
        }
        double* S = stencils_.data() + m * kStencil;
        double tol = 0.0;
        const long ml = static_cast<long>(m);
        if (!macro_deep_points(A, lay, lattice_, params_, ml, S, tol, macro[m])) return;
        macro_semi_points(A, lay, lattice_, ml, S, tol, macro[m]);
    });
    deep_row_.clear();
    deep_len_.clear();
    deep_macro_.clear();
    deep_slots_.clear();
    for (long m = 0; m < n_macros; ++m) {
        const MacroPoints& mp = macro[static_cast<size_t>(m)];
        deep_row_.insert(deep_row_.end(), mp.rows.begin(), mp.rows.end());
        deep_len_.insert(deep_len_.end(), mp.lens.begin(), mp.lens.end());
        deep_macro_.insert(deep_macro_.end(), mp.rows.size(), static_cast<int>(m));
        deep_slots_.insert(deep_slots_.end(), mp.slots.begin(), mp.slots.end());
    }
    n_deep_ = static_cast<Index>(deep_row_.size());
    semi_nbr_.clear();
    semi_slots_.clear();
    semi_macro_.clear();
    lay.semi_of_block.assign(static_cast<size_t>(nb), -1);
    for (long m = 0; m < n_macros; ++m) {
        const MacroPoints& mp = macro[static_cast<size_t>(m)];
        const auto& nbr = mp.semi_nbr;
        for (size_t k = 0; k < nbr.size(); k += kSlots) {
            lay.semi_of_block[static_cast<size_t>(lay.block_of_row[static_cast<size_t>(nbr[k])])] =
                static_cast<int>(semi_macro_.size());
            semi_macro_.push_back(static_cast<int>(m));
        }
        semi_nbr_.insert(semi_nbr_.end(), nbr.begin(), nbr.end());
        semi_slots_.insert(semi_slots_.end(), mp.semi_slots.begin(), mp.semi_slots.end());
    }
    MLC_CHECK(semi_macro_.size() < (size_t{1} << 29) && nb < (Index{1} << 29),
              "lattice smoother: too many blocks (" << nb << ")");
}

void LatticeGS::number_visits(const Layout& lay) {
    // The visit entries and the row-swept blocks, in visit order.
    const Index nb = lay.nb;
    part_visit_ = lay.cut;
    visit_row_.resize(static_cast<size_t>(nb));
    visit_code_.resize(static_cast<size_t>(nb));
    cb_row_.clear();
    cb_size_.clear();
    cb_block_.clear();
    for (Index i = 0; i < nb; ++i) {
        const int b = lay.order[static_cast<size_t>(i)];
        const int len = lay.deep_len[static_cast<size_t>(b)];
        visit_row_[static_cast<size_t>(i)] = static_cast<int>(lay.starts[b]);
        if (len > 0) {
            visit_code_[static_cast<size_t>(i)] =
                lay.deep_mac[static_cast<size_t>(b)] * kLenCodes + len;
        } else if (len == 0) {
            visit_code_[static_cast<size_t>(i)] = kSemi + lay.semi_of_block[static_cast<size_t>(b)];
        } else {
            visit_code_[static_cast<size_t>(i)] = -1 - static_cast<int>(cb_row_.size());
            cb_row_.push_back(static_cast<int>(lay.starts[b]));
            cb_size_.push_back(static_cast<int>(lay.starts[b + 1] - lay.starts[b]));
            cb_block_.push_back(b);
        }
    }
}

void LatticeGS::group_items() {
    // Items of each part: runs of deep points along one lattice row (the same macro and row,
    // consecutive visits two rows apart, all in one direction), and runs of row-swept blocks.
    item_begin_.clear();
    part_item_.assign(1, 0);
    for (size_t p = 0; p + 1 < part_visit_.size(); ++p) {
        const int e = part_visit_[p + 1];
        for (int i = part_visit_[p]; i < e;) {
            item_begin_.push_back(i);
            const int code = visit_code_[static_cast<size_t>(i)];
            int j = i + 1;
            if (code < 0) { // a run of semi-deep points, or of row-swept blocks
                const bool semi = code <= kSemiMax;
                while (j < e && visit_code_[static_cast<size_t>(j)] < 0 &&
                       (visit_code_[static_cast<size_t>(j)] <= kSemiMax) == semi)
                    ++j;
            } else if (j < e && visit_code_[static_cast<size_t>(j)] == code) {
                const int step =
                    visit_row_[static_cast<size_t>(j)] - visit_row_[static_cast<size_t>(i)];
                if (step == 2 || step == -2)
                    while (j < e && visit_code_[static_cast<size_t>(j)] == code &&
                           visit_row_[static_cast<size_t>(j)] -
                                   visit_row_[static_cast<size_t>(j) - 1] ==
                               step)
                        ++j;
            }
            i = j;
        }
        part_item_.push_back(static_cast<int>(item_begin_.size()));
    }
    item_begin_.push_back(part_visit_.back());
}

void LatticeGS::derive_swept_rows(const SparseMatrix& A, const Layout& lay) {
    const int* ao = A.outerIndexPtr();
    const int* ai = A.innerIndexPtr();
    const auto& block_of_row = lay.block_of_row;
    const auto& part_of_block = lay.part_of_block;
    // Rows of the row-swept blocks: the own part's entries first (column order), then the
    // entries read across a cut; sizes first, then the rows over the threads.
    const size_t ncb = cb_row_.size();
    cb_crow_.assign(ncb, 0);
    cb_twin_.assign(ncb, 0);
    cb_inv_.assign(ncb + 1, 0);
    for (size_t c = 0; c < ncb; ++c) {
        cb_crow_[c] = c == 0 ? 0 : cb_crow_[c - 1] + cb_size_[c - 1];
        cb_inv_[c + 1] = cb_inv_[c] + static_cast<Index>(cb_size_[c]) * cb_size_[c];
    }
    const size_t n_crows = ncb == 0 ? 0 : static_cast<size_t>(cb_crow_.back() + cb_size_.back());
    crow_ptr_.assign(n_crows + 1, 0);
    for (size_t c = 0; c < ncb; ++c)
        for (int k = 0; k < cb_size_[c]; ++k) {
            const int row = cb_row_[c] + k;
            crow_ptr_[static_cast<size_t>(cb_crow_[c] + k) + 1] = ao[row + 1] - ao[row];
        }
    for (size_t r = 0; r < n_crows; ++r)
        crow_ptr_[r + 1] += crow_ptr_[r];
    ccol_.resize(static_cast<size_t>(crow_ptr_.back()));
    csrc_.resize(ccol_.size());
    crow_own_end_.assign(n_crows, 0);
    parallel::for_rows(ncb, 4096, [&](size_t c0, size_t c1) {
        for (size_t c = c0; c < c1; ++c) {
            const int part = part_of_block[static_cast<size_t>(cb_block_[c])];
            for (int k = 0; k < cb_size_[c]; ++k) {
                const int row = cb_row_[c] + k;
                const size_t cr = static_cast<size_t>(cb_crow_[c] + k);
                int e = crow_ptr_[cr];
                for (int pass = 0; pass < 2; ++pass) {
                    for (int q = ao[row]; q < ao[row + 1]; ++q) {
                        const bool own = part_of_block[static_cast<size_t>(
                                             block_of_row[static_cast<size_t>(ai[q])])] == part;
                        if (own != (pass == 0)) continue;
                        ccol_[static_cast<size_t>(e)] = ai[q];
                        csrc_[static_cast<size_t>(e)] = q;
                        ++e;
                    }
                    if (pass == 0) crow_own_end_[cr] = e;
                }
            }
            if (cb_size_[c] == 2) { // two rows with the same columns: swept together
                const int r0 = cb_crow_[c];
                const int a = crow_ptr_[static_cast<size_t>(r0)];
                const int m = crow_ptr_[static_cast<size_t>(r0) + 1];
                const int e = crow_ptr_[static_cast<size_t>(r0) + 2];
                cb_twin_[c] = m - a == e - m &&
                              crow_own_end_[static_cast<size_t>(r0)] - a ==
                                  crow_own_end_[static_cast<size_t>(r0) + 1] - m &&
                              std::equal(ccol_.begin() + a, ccol_.begin() + m, ccol_.begin() + m);
            }
        }
    });
    std::vector<char> across(static_cast<size_t>(n_), 0);
    for (size_t r = 0; r < n_crows; ++r)
        for (int e = crow_own_end_[r]; e < crow_ptr_[r + 1]; ++e)
            across[static_cast<size_t>(ccol_[static_cast<size_t>(e)])] = 1;
    interface_.clear();
    for (Index col = 0; col < n_; ++col)
        if (across[static_cast<size_t>(col)]) interface_.push_back(static_cast<int>(col));
    cval_.resize(ccol_.size());
    cinv_.resize(static_cast<size_t>(cb_inv_.back()));
    snap_.resize(n_); // read at the interface columns only, each written before a sweep reads it
}

} // namespace mlc::smoothers
