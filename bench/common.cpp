// SPDX-License-Identifier: MIT
// What the benches share.
#include "bench/common.hpp"

#include "contact/element.hpp"
#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/memory.hpp"
#include "core/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <set>

namespace mlc::apps {

double peak_rss_mib() {
    return peak_rss_bytes() / (1024.0 * 1024.0);
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

// The JSON a bench writes: `given`, or out/bench/<prefix><scene>_L<levels>.json.
std::filesystem::path bench_json_path(const std::string& given, const std::string& prefix,
                                      const std::string& scene, int levels) {
    if (!given.empty()) return given;
    return "out/bench/" + prefix + scene + "_L" + std::to_string(levels) + ".json";
}

AtomicOfstream open_json(const std::filesystem::path& file) {
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    AtomicOfstream f(file);
    MLC_CHECK(f.good(), "cannot write " << file.string());
    f << std::setprecision(6);
    return f;
}

// Nonzeros of the Jacobian pattern of a level: K plus the contact tangent entries outside it.
long jacobian_nonzeros(const levels::Level& L) {
    const SparseMatrix& K = L.elastic.K;
    std::set<std::pair<int, int>> extra;
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    for (size_t e = 0; e < L.contacts.size(); ++e)
        contact::for_each_tangent_entry(
            L.contacts[e], I, L.dofs, L.lambda_dof[e], [&](int row, int col, double) {
                const int* b = K.innerIndexPtr() + K.outerIndexPtr()[row];
                const int* en = K.innerIndexPtr() + K.outerIndexPtr()[row + 1];
                if (!std::binary_search(b, en, col)) extra.emplace(row, col);
            });
    return static_cast<long>(K.nonZeros()) + static_cast<long>(extra.size());
}

double time_matvec(const SparseMatrix& A, int min_calls, double min_seconds) {
    const Vector x = Vector::Ones(A.cols());
    Vector y(A.rows());
    csr_multiply(A, x, y);
    std::vector<double> t;
    const double start = wall_seconds();
    while (static_cast<int>(t.size()) < min_calls || wall_seconds() - start < min_seconds) {
        const double t0 = wall_seconds();
        csr_multiply(A, x, y);
        t.push_back(wall_seconds() - t0);
        if (t.size() >= 1000) break;
    }
    return median(t);
}

long long whole(double v) {
    return static_cast<long long>(std::llround(v));
}

double gbs(double bytes, double seconds) {
    return seconds > 0 ? bytes / seconds * 1e-9 : 0.0;
}

double matrix_bytes(const traffic::Account& a) {
    return a.b(traffic::Kind::matvec) + a.b(traffic::Kind::smoother) + a.b(traffic::Kind::transfer);
}

double matrix_seconds(const traffic::Account& a) {
    return a.s(traffic::Kind::matvec) + a.s(traffic::Kind::smoother) + a.s(traffic::Kind::transfer);
}

} // namespace mlc::apps
