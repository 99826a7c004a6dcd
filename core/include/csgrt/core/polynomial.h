#pragma once

#include <algorithm>
#include <cmath>

#include "csgrt/core/math.h"

namespace csgrt {

/// Real roots of a x^2 + b x + c = 0, written to roots[] in increasing order; returns how many
/// (0, 1 or 2; a double root is reported twice). The discriminant is formed with one rounding
/// (difference_of_products) and the roots by the cancellation-free pair q = -(b + sign(b)
/// sqrt(disc)) / 2, x = q / a and x = c / q (Press et al., "Numerical Recipes", 5.6).
/// a == 0 falls back to the linear equation; a == b == 0 has no isolated roots (returns 0).
inline int solve_quadratic(double a, double b, double c, double roots[2]) {
    if (a == 0.0) {
        if (b == 0.0) return 0;
        roots[0] = -c / b;
        return 1;
    }
    const double discriminant = difference_of_products(b, b, 4.0 * a, c);
    if (!(discriminant >= 0.0)) return 0;  // also rejects NaN coefficients
    const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0.0) {
        // b == 0 and disc == 0, so c == 0: the double root 0.
        roots[0] = roots[1] = 0.0;
        return 2;
    }
    roots[0] = q / a;
    roots[1] = c / q;
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    return 2;
}

}  // namespace csgrt
