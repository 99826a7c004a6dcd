#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

namespace csgrt::bench {

/// The median, 99th percentile and maximum of a sample (all zero for an empty one).
struct Quantiles {
    double median = 0.0;
    double p99 = 0.0;
    double max = 0.0;
};

/// The q-quantile (q in [0, 1]) of `sorted` by the nearest-rank rule: the smallest value with
/// at least a fraction q of the sample at or below it. 0 for an empty sample.
inline double nearest_rank(std::span<const double> sorted, double q) {
    if (sorted.empty()) return 0.0;
    const auto n = static_cast<double>(sorted.size());
    const auto rank = static_cast<std::size_t>(std::ceil(q * n));
    return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

/// Median, 99th percentile and maximum of `values` (nearest rank; NaNs count as largest).
inline Quantiles quantiles(std::vector<double> values) {
    std::sort(values.begin(), values.end(), [](double a, double b) {
        // NaN sorts last so a bad value shows up in the maximum instead of breaking the sort.
        if (std::isnan(a)) return false;
        return std::isnan(b) || a < b;
    });
    Quantiles result;
    result.median = nearest_rank(values, 0.5);
    result.p99 = nearest_rank(values, 0.99);
    result.max = values.empty() ? 0.0 : values.back();
    return result;
}

/// time = coefficient * n^exponent fitted by least squares on (log n, log time), and the
/// fraction of the variance of log time the fit explains.
struct PowerFit {
    double exponent = 0.0;
    double coefficient = 0.0;
    double r_squared = 0.0;
    bool valid = false;
};

/// Fits a power law to the pairs (n[i], time[i]); pairs with a non-positive or non-finite
/// member are skipped. Needs two distinct n, otherwise the fit is not valid.
inline PowerFit fit_power_law(std::span<const double> n, std::span<const double> time) {
    std::vector<double> x, y;
    for (std::size_t i = 0; i < std::min(n.size(), time.size()); ++i) {
        if (n[i] > 0.0 && time[i] > 0.0 && std::isfinite(n[i]) && std::isfinite(time[i])) {
            x.push_back(std::log(n[i]));
            y.push_back(std::log(time[i]));
        }
    }
    PowerFit fit;
    if (x.size() < 2) return fit;
    const auto count = static_cast<double>(x.size());
    double mean_x = 0.0, mean_y = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        mean_x += x[i] / count;
        mean_y += y[i] / count;
    }
    // Centred sums, so large logs do not cancel.
    double sxx = 0.0, sxy = 0.0, syy = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sxx += (x[i] - mean_x) * (x[i] - mean_x);
        sxy += (x[i] - mean_x) * (y[i] - mean_y);
        syy += (y[i] - mean_y) * (y[i] - mean_y);
    }
    if (sxx == 0.0) return fit;
    fit.exponent = sxy / sxx;
    fit.coefficient = std::exp(mean_y - fit.exponent * mean_x);
    fit.r_squared = syy == 0.0 ? 1.0 : (sxy * sxy) / (sxx * syy);
    fit.valid = true;
    return fit;
}

/// A variant's cost and error, both to be minimised.
struct CostError {
    double time = 0.0;
    double error = 0.0;
};

/// Which points are on the Pareto front: no other point is at least as fast and at least as
/// accurate, and strictly better in one of the two. Equal points are all on the front.
inline std::vector<bool> pareto_front(std::span<const CostError> points) {
    std::vector<bool> on_front(points.size(), true);
    for (std::size_t i = 0; i < points.size(); ++i) {
        for (std::size_t j = 0; j < points.size() && on_front[i]; ++j) {
            const bool no_worse =
                points[j].time <= points[i].time && points[j].error <= points[i].error;
            const bool better =
                points[j].time < points[i].time || points[j].error < points[i].error;
            if (j != i && no_worse && better) on_front[i] = false;
        }
    }
    return on_front;
}

}  // namespace csgrt::bench
