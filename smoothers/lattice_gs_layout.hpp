// SPDX-License-Identifier: MIT
/// @file The lattice smoother's stencil layout and visit codes, shared by its setup
/// (lattice_gs_setup.cpp) and its sweeps (lattice_gs.cpp). Internal to mlc_smoothers.
#pragma once

namespace mlc::smoothers::lattice {

constexpr int kSlots = 7; // centre, then (1,0), (-1,0), (0,1), (0,-1), (1,-1), (-1,1)
// 7 slots x 4 entries (row-major 2x2), then omega D^{-1} of the centre, then G_east = omega D^{-1}
// S_(1,0) and G_west = omega D^{-1} S_(-1,0) (deep_run); then the same ten 2x2 blocks packed for
// two-lane arithmetic, each as its diagonal (B00, B11) and its off-diagonal (B01, B10).
constexpr int kStencil = 80;
constexpr int kPacked = 40;
constexpr int kDi[kSlots] = {0, 1, -1, 0, 0, 1, -1};
constexpr int kDj[kSlots] = {0, 0, 0, 1, -1, -1, 1};
constexpr int kLenCodes = 4096; // visit code = macro * kLenCodes + row length
// Visit codes of semi-deep points: kSemi + their index (row-swept blocks: -1 - their index).
constexpr int kSemi = -(1 << 30);
constexpr int kSemiMax = kSemi + (1 << 29);

} // namespace mlc::smoothers::lattice
