#include "csgrt/core/angle_range.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {

AngleRange::AngleRange(double min, double max, std::string_view what, std::string_view min_name,
                       std::string_view max_name)
    : min_(min), max_(max) {
    require(min >= 0.0 && min < kTwoPi, what, min_name, "in [0, 2 pi)", min);
    require(max > min && max <= min + kTwoPi, what, max_name,
            std::string("in (") + std::string(min_name) + ", " + std::string(min_name) + " + 2 pi]",
            max);
    extent_ = max - min;
    // The same expression as the check above, so min + 2 pi passed in is the full circle.
    full_ = max == min + kTwoPi;
}

double AngleRange::fraction(double angle) const {
    const double offset = offset_from_min(angle);
    if (offset <= extent_) return offset / extent_;
    return offset - extent_ < kTwoPi - offset ? 1.0 : 0.0;
}

void AngleRange::sine_cosine_bounds(double& sin_lo, double& sin_hi, double& cos_lo,
                                    double& cos_hi) const {
    sin_lo = std::min(std::sin(min_), std::sin(max_));
    sin_hi = std::max(std::sin(min_), std::sin(max_));
    cos_lo = std::min(std::cos(min_), std::cos(max_));
    cos_hi = std::max(std::cos(min_), std::cos(max_));
    // The extremes of sin and cos are at the quarter turns; max <= min + 2 pi < 4 pi.
    constexpr double kQuarterSin[4] = {0, 1, 0, -1};
    constexpr double kQuarterCos[4] = {1, 0, -1, 0};
    for (int quarter = 0; quarter <= 8; ++quarter) {
        const double angle = quarter * (kPi / 2);
        if (angle < min_ || angle > max_) continue;
        sin_lo = std::min(sin_lo, kQuarterSin[quarter % 4]);
        sin_hi = std::max(sin_hi, kQuarterSin[quarter % 4]);
        cos_lo = std::min(cos_lo, kQuarterCos[quarter % 4]);
        cos_hi = std::max(cos_hi, kQuarterCos[quarter % 4]);
    }
}

}  // namespace csgrt
