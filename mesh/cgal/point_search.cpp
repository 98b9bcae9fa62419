// SPDX-License-Identifier: MIT
// PointSearch with CGAL's Kd-tree (built only with MLC_WITH_CGAL; see point_search_linear.cpp).
#include "mesh/cgal/point_search.hpp"

#include "core/check.hpp"

#include <CGAL/Fuzzy_sphere.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_2.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>
#include <boost/tuple/tuple.hpp>

#include <iterator>

namespace mlc::mesh {

struct PointSearch::Impl {
    using K = CGAL::Simple_cartesian<double>;
    using Point = K::Point_2;
    using PointAndIndex = boost::tuple<Point, int>;
    using Traits = CGAL::Search_traits_adapter<
        PointAndIndex, CGAL::Nth_of_tuple_property_map<0, PointAndIndex>, CGAL::Search_traits_2<K>>;
    using KNN = CGAL::Orthogonal_k_neighbor_search<Traits>;
    using Tree = KNN::Tree;
    Tree tree;
    int n = 0;
};

PointSearch::PointSearch(const std::vector<Vec2>& pts) : impl_(std::make_unique<Impl>()) {
    std::vector<Impl::PointAndIndex> data;
    data.reserve(pts.size());
    for (size_t i = 0; i < pts.size(); ++i)
        data.emplace_back(Impl::Point(pts[i].x(), pts[i].y()), static_cast<int>(i));
    impl_->tree.insert(data.begin(), data.end());
    impl_->tree.build();
    impl_->n = static_cast<int>(pts.size());
}

PointSearch::~PointSearch() = default;
PointSearch::PointSearch(PointSearch&&) noexcept = default;
PointSearch& PointSearch::operator=(PointSearch&&) noexcept = default;

int PointSearch::size() const {
    return impl_->n;
}

int PointSearch::nearest(const Vec2& x) const {
    MLC_CHECK(impl_->n > 0, "PointSearch::nearest: no point to search");
    Impl::KNN search(impl_->tree, Impl::Point(x.x(), x.y()), 1);
    return boost::get<1>(search.begin()->first);
}

std::vector<int> PointSearch::within(const Vec2& x, double radius) const {
    std::vector<Impl::PointAndIndex> found;
    CGAL::Fuzzy_sphere<Impl::Traits> sphere(Impl::Point(x.x(), x.y()), radius, 0.0);
    impl_->tree.search(std::back_inserter(found), sphere);
    std::vector<int> out;
    out.reserve(found.size());
    for (const auto& p : found)
        out.push_back(boost::get<1>(p));
    return out;
}

} // namespace mlc::mesh
