// SPDX-License-Identifier: MIT
// Closed-form contact references.
#include "run/closed_form.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mlc::apps {

double Hertz::half_width() const {
    return std::sqrt(4.0 * P * R / (std::numbers::pi * E_star));
}
double Hertz::peak_pressure() const {
    return E_star * half_width() / (2.0 * R);
}
double Hertz::pressure(double x) const {
    const double a = half_width();
    return std::abs(x) >= a ? 0.0 : 2.0 * P / (std::numbers::pi * a * a) * std::sqrt(a * a - x * x);
}

PressureProfile pressure_profile(std::vector<levels::ContactNodeState> nodes) {
    MLC_CHECK(nodes.size() >= 2, "a pressure profile needs at least two contact nodes");
    std::sort(nodes.begin(), nodes.end(),
              [](const auto& a, const auto& b) { return a.x.x() < b.x.x(); });
    PressureProfile prof;
    const size_t n = nodes.size();
    int last = -1;
    for (size_t i = 0; i < n; ++i) {
        const double left = i > 0 ? 0.5 * (nodes[i].x.x() - nodes[i - 1].x.x()) : 0.0;
        const double right = i + 1 < n ? 0.5 * (nodes[i + 1].x.x() - nodes[i].x.x()) : 0.0;
        prof.x.push_back(nodes[i].x.x());
        prof.p.push_back(-nodes[i].lambda_n / (left + right));
        if (nodes[i].status != contact::Status::gap) last = static_cast<int>(i);
    }
    MLC_CHECK(last >= 0, "no node is in contact");
    MLC_CHECK(last + 1 < static_cast<int>(n),
              "the contact zone reaches the last candidate node: widen the contact region");
    prof.half_width =
        0.5 * (prof.x[static_cast<size_t>(last)] + prof.x[static_cast<size_t>(last) + 1]);
    prof.edge_spacing = prof.x[static_cast<size_t>(last) + 1] - prof.x[static_cast<size_t>(last)];
    return prof;
}

HertzErrors compare(const PressureProfile& prof, const Hertz& h) {
    HertzErrors e;
    const double a = h.half_width(), p0 = h.peak_pressure();
    e.half_width = (prof.half_width - a) / a;
    e.peak = (prof.p.front() - p0) / p0;
    double s = 0.0;
    int k = 0;
    for (size_t i = 0; i < prof.x.size(); ++i)
        if (std::abs(prof.x[i]) < 0.9 * a) {
            s += std::pow(prof.p[i] - h.pressure(prof.x[i]), 2);
            ++k;
        }
    e.profile_rms = k > 0 ? std::sqrt(s / k) / p0 : 0.0;
    return e;
}

} // namespace mlc::apps
