#pragma once

#include <string_view>

#include "csgrt/core/math.h"

namespace csgrt {

/// A closed interval of angles [min, max] (radians) that limits a part object: the azimuth of
/// a part sphere, cylinder, annulus or torus, or the tube angle of a part torus.
///
/// min lies in [0, 2 pi) and min < max <= min + 2 pi, so a range may run past 2 pi and then
/// wraps through 0: [3 pi / 2, 5 pi / 2] is the half facing +z. max == min + 2 pi is the full
/// circle. Both ends belong to the range, and the seam 0 = 2 pi is no boundary.
class AngleRange {
public:
    /// Throws InvalidParameter naming `what` and `min_name` or `max_name` unless the limits
    /// follow the rules above.
    AngleRange(double min, double max, std::string_view what, std::string_view min_name = "phi_min",
               std::string_view max_name = "phi_max");

    double min() const { return min_; }
    double max() const { return max_; }
    bool is_full() const { return full_; }

    /// Whether `angle` (any value in [0, 2 pi]) lies in the range.
    bool contains(double angle) const { return full_ || offset_from_min(angle) <= extent_; }

    /// Whether the angle atan2(x, z) of the point (x, z) lies in the range; the origin, where
    /// the angle is undefined (a point on the axis), belongs to every range.
    bool contains(double x, double z) const {
        if (full_ || (x == 0.0 && z == 0.0)) return true;
        return offset_from_min(azimuth(x, z)) <= extent_;
    }

    /// Where `angle` lies in the range: 0 at min, 1 at max; an angle just outside (by
    /// rounding) gives the nearer end. The u or v of a part object's parameterisation.
    double fraction(double angle) const;

    /// The ranges of sin and cos over the interval: their values at the ends and at every
    /// quarter turn inside. Part objects bound their arcs with these.
    void sine_cosine_bounds(double& sin_lo, double& sin_hi, double& cos_lo, double& cos_hi) const;

    /// atan2(x, z) wrapped to [0, 2 pi): the y-up azimuth convention. A tiny negative angle,
    /// which rounds up to 2 pi, is returned as 0.
    static double azimuth(double x, double z) {
        double angle = std::atan2(x, z);
        if (angle < 0.0) angle += kTwoPi;
        return angle < kTwoPi ? angle : 0.0;
    }

private:
    /// angle - min reduced into [0, 2 pi).
    double offset_from_min(double angle) const {
        double offset = angle - min_;
        if (offset < 0.0) offset += kTwoPi;
        if (offset >= kTwoPi) offset -= kTwoPi;
        return offset;
    }

    double min_;
    double max_;
    double extent_;
    bool full_;
};

}  // namespace csgrt
