// SPDX-License-Identifier: MIT
// PointSearch without CGAL (built only with MLC_WITH_CGAL=OFF): linear scans, O(n) per query.
#include "mesh/cgal/point_search.hpp"

#include "core/check.hpp"

namespace mlc::mesh {

struct PointSearch::Impl {
    std::vector<Vec2> pts;
};

PointSearch::PointSearch(const std::vector<Vec2>& pts) : impl_(std::make_unique<Impl>()) {
    impl_->pts = pts;
}

PointSearch::~PointSearch() = default;
PointSearch::PointSearch(PointSearch&&) noexcept = default;
PointSearch& PointSearch::operator=(PointSearch&&) noexcept = default;

int PointSearch::size() const {
    return static_cast<int>(impl_->pts.size());
}

int PointSearch::nearest(const Vec2& x) const {
    const auto& pts = impl_->pts;
    MLC_CHECK(!pts.empty(), "PointSearch::nearest: no point to search");
    int best = 0;
    for (size_t i = 1; i < pts.size(); ++i)
        if ((pts[i] - x).squaredNorm() < (pts[static_cast<size_t>(best)] - x).squaredNorm())
            best = static_cast<int>(i);
    return best;
}

std::vector<int> PointSearch::within(const Vec2& x, double radius) const {
    const auto& pts = impl_->pts;
    std::vector<int> out;
    for (size_t i = 0; i < pts.size(); ++i)
        if ((pts[i] - x).norm() <= radius) out.push_back(static_cast<int>(i));
    return out;
}

} // namespace mlc::mesh
