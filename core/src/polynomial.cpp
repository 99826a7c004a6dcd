#include "csgrt/core/polynomial.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace csgrt {
namespace {

template <class Real>
constexpr Real rounding_bound(int n) {
    constexpr Real u = std::numeric_limits<Real>::epsilon() / 2;
    return n * u / (1 - n * u);
}

// sum_i |w_i| |x|^i. With w = c it is the scale of the rounding error of Horner's rule,
// |error| <= gamma(2 n) sum |c_i| |x|^i (Higham, "Accuracy and Stability of Numerical
// Algorithms", 2002, 5.1).
template <class Real, int Degree>
Real magnitude(const Real* w, Real x) {
    const Real ax = std::abs(x);
    Real sum = std::abs(w[Degree]);
    for (int i = Degree - 1; i >= 0; --i) sum = sum * ax + std::abs(w[i]);
    return sum;
}

// p(x) and p'(x) by Horner's rule (coefficients in ascending powers), with the bound
// gamma(2 n) sum |c_i| |x|^i on the rounding error of p(x).
template <class Real, int Degree>
void evaluate(const Real* c, Real x, Real& value, Real& slope, Real& error) {
    const Real ax = std::abs(x);
    value = c[Degree];
    slope = 0;
    Real scale = std::abs(c[Degree]);
    for (int i = Degree - 1; i >= 0; --i) {
        slope = slope * x + value;
        value = value * x + c[i];
        scale = scale * ax + std::abs(c[i]);
    }
    error = rounding_bound<Real>(2 * Degree) * scale;
}

template <class Real, int Degree>
void evaluate(const Real* c, Real x, Real& value, Real& slope) {
    Real error;
    evaluate<Real, Degree>(c, x, value, slope, error);
}

// The smallest power of two at or above x^(1/k), x >= 0: cheaper than the root, at most 2x
// larger. For normal doubles the exponent is read and written directly (frexp and ldexp are
// library calls that cost more than the rest of the bound).
template <class Real>
Real power_of_two_root(Real x, int k) {
    if (x == 0 || !std::isfinite(x)) return x;
    int exponent;  // x < 2^exponent
    if constexpr (std::is_same_v<Real, double>) {
        const int biased = static_cast<int>(std::bit_cast<std::uint64_t>(x) >> 52) & 0x7ff;
        if (biased == 0) {
            std::frexp(x, &exponent);  // subnormal
        } else {
            exponent = biased - 1022;
        }
    } else {
        std::frexp(x, &exponent);
    }
    const int root_exponent = exponent >= 0 ? (exponent + k - 1) / k : -(-exponent / k);
    if constexpr (std::is_same_v<Real, double>) {
        if (root_exponent > -1022 && root_exponent < 1024) {  // else ldexp's slow path
            return std::bit_cast<double>(static_cast<std::uint64_t>(root_exponent + 1023) << 52);
        }
    }
    return std::ldexp(Real(1), root_exponent);
}

// Fujiwara's bound (1916): every complex root z of sum c_i z^i has
// |z| <= 2 max_k |c_{n-k} / c_n|^(1/k), with c_0 halved; each k-th root is rounded up to a
// power of two.
template <class Real, int Degree>
Real root_bound(const Real* c) {
    Real bound = 0;
    for (int k = 1; k <= Degree; ++k) {
        Real ratio = std::abs(c[Degree - k] / c[Degree]);
        if (k == Degree) ratio /= 2;
        bound = std::max(bound, power_of_two_root(ratio, k));
    }
    // A positive bound even for c_n t^n, so its root 0 gets neighbours to be judged against.
    return bound > 0 ? 2 * bound : Real(1);
}

template <class Real>
int sign_of(Real value) {
    return (value > 0) - (value < 0);
}

// The real roots of sum c_i t^i (ascending) in [lo, hi], counted as documented for
// solve_quartic. Each degree isolates its roots between the roots of its derivative, found by
// the degree below on the same interval; the quadratic is solved in closed form. `clamp`
// narrows [lo, hi] to the root bound first, which keeps brackets (and Newton's far-field
// phase, where it gains only a factor (n - 1) / n per step) short; the derivative needs no
// clamping, as its roots lie within the hull of the polynomial's (Gauss-Lucas).
template <class Real, int Degree>
int roots_in_interval(const Real* c, const Real* errors, Real lo, Real hi, Real* roots,
                      bool clamp) {
    if constexpr (Degree <= 2) {
        Real pair[2];
        const int found = detail::solve_quadratic(c[2], c[1], c[0], pair);
        int count = 0;
        for (int i = 0; i < found; ++i) {
            if (pair[i] >= lo && pair[i] <= hi) roots[count++] = pair[i];
        }
        return count;
    } else {
        if (c[Degree] == 0) {
            return roots_in_interval<Real, Degree - 1>(c, errors, lo, hi, roots, clamp);
        }
        if (clamp) {
            const Real bound = root_bound<Real, Degree>(c);
            lo = std::max(lo, -bound);
            hi = std::min(hi, bound);
        }
        if (!(lo <= hi)) return 0;

        // p is monotone between consecutive roots of p' (the extrema).
        Real derivative[Degree];
        for (int i = 0; i < Degree; ++i) derivative[i] = Real(i + 1) * c[i + 1];
        Real extrema[Degree - 1];
        const int extremum_count =
            roots_in_interval<Real, Degree - 1>(derivative, nullptr, lo, hi, extrema, false);

        Real knots[Degree + 1];
        Real values[Degree + 1];
        int signs[Degree + 1];
        int knot_count = 0;
        knots[knot_count++] = lo;
        for (int i = 0; i < extremum_count; ++i) {
            // Double roots of p' come twice and are no extrema; ends are knots already.
            if (extrema[i] > knots[knot_count - 1] && extrema[i] < hi) {
                knots[knot_count++] = extrema[i];
            }
        }
        if (hi > lo) knots[knot_count++] = hi;

        for (int k = 0; k < knot_count; ++k) {
            Real slope;
            evaluate<Real, Degree>(c, knots[k], values[k], slope);
            signs[k] = sign_of(values[k]);
            const bool is_extremum = k > 0 && k < knot_count - 1;
            if (is_extremum) {
                // An extremum whose value is within the rounding error (and the caller's
                // coefficient error) of zero is a double root: the sign there is noise.
                Real tolerance =
                    rounding_bound<Real>(2 * Degree + 1) * magnitude<Real, Degree>(c, knots[k]);
                if (errors) tolerance += magnitude<Real, Degree>(errors, knots[k]);
                if (std::abs(values[k]) <= tolerance) signs[k] = 0;
            }
        }

        auto polynomial = [c](Real x, Real& value, Real& slope, Real& error) {
            evaluate<Real, Degree>(c, x, value, slope, error);
        };
        int count = 0;
        int k = 0;
        while (k < knot_count && count < Degree) {
            if (signs[k] == 0) {
                // A run of knots at zero is one root; it touches zero (two roots) when the
                // polynomial has the same sign on both sides, and crosses it otherwise.
                int last = k;
                Real best = knots[k];
                Real best_value = std::abs(values[k]);
                while (last + 1 < knot_count && signs[last + 1] == 0) {
                    ++last;
                    if (std::abs(values[last]) < best_value) {
                        best = knots[last];
                        best_value = std::abs(values[last]);
                    }
                }
                const int before = k > 0 ? signs[k - 1] : 0;
                const int after = last + 1 < knot_count ? signs[last + 1] : 0;
                roots[count++] = best;
                if (before != 0 && before == after && count < Degree) roots[count++] = best;
                k = last + 1;
                continue;
            }
            if (k + 1 < knot_count && signs[k + 1] == -signs[k]) {
                // Start from the secant point: the root of the chord over the monotone piece.
                const Real a = knots[k];
                const Real b = knots[k + 1];
                const Real secant = a + (b - a) * (values[k] / (values[k] - values[k + 1]));
                roots[count++] = detail::bracketed_root(polynomial, a, b, signs[k] < 0, secant);
            }
            ++k;
        }
        return count;
    }
}

template <class Real, int Degree>
bool all_finite(const Real* c) {
    for (int i = 0; i <= Degree; ++i) {
        if (!std::isfinite(c[i])) return false;
    }
    return true;
}

template <class Real>
int solve_cubic_any(Real a, Real b, Real c, Real d, Real roots[3]) {
    const Real coeffs[4] = {d, c, b, a};
    if (!all_finite<Real, 3>(coeffs)) return 0;
    const Real infinity = std::numeric_limits<Real>::infinity();
    return roots_in_interval<Real, 3>(coeffs, nullptr, -infinity, infinity, roots, true);
}

template <class Real>
int solve_quartic_bracketing(const Real coeffs[5], const Real* errors, Real t_lo, Real t_hi,
                             Real roots[4]) {
    if (!all_finite<Real, 4>(coeffs) || std::isnan(t_lo) || std::isnan(t_hi)) return 0;
    return roots_in_interval<Real, 4>(coeffs, errors, t_lo, t_hi, roots, true);
}

// The largest real root of m^3 + b m^2 + c m + d = 0 in closed form (Cardano, in the
// trigonometric form when there are three real roots), polished by one Newton step.
double largest_cubic_root(double b, double c, double d) {
    // m = y - b/3 gives y^3 + p y + q = 0.
    const double shift = b / 3.0;
    const double p = c - b * shift;
    const double q = d - shift * (c - 2.0 / 9.0 * b * b);
    const double half_q = 0.5 * q;
    const double third_p = p / 3.0;
    const double discriminant = half_q * half_q + third_p * third_p * third_p;
    double y;
    if (discriminant >= 0.0) {
        // One real root: A + B with A B = -p/3, A taken without cancellation.
        const double a =
            -std::copysign(std::cbrt(std::abs(half_q) + std::sqrt(discriminant)), half_q);
        y = a != 0.0 ? a - third_p / a : 0.0;
    } else {
        const double radius = std::sqrt(-third_p);
        const double cosine = std::clamp(-half_q / (radius * radius * radius), -1.0, 1.0);
        y = 2.0 * radius * std::cos(std::acos(cosine) / 3.0);
    }
    double m = y - shift;
    const double value = ((m + b) * m + c) * m + d;
    const double slope = (3.0 * m + 2.0 * b) * m + c;
    if (slope != 0.0) m -= value / slope;
    return m;
}

// Ferrari's method in Descartes' form: depress t = y - a/4 to y^4 + P y^2 + Q y + R, factor
// it as (y^2 + s y + u)(y^2 - s y + v) with m = s^2 the positive root of the resolvent cubic
// m^3 + 2 P m^2 + (P^2 - 4 R) m - Q^2 = 0, then solve both quadratics and polish every root by
// Newton on the original polynomial (kept only while it lowers |p|).
int solve_quartic_closed_form(const double coeffs[5], double t_lo, double t_hi, double roots[4]) {
    if (!all_finite<double, 4>(coeffs) || std::isnan(t_lo) || std::isnan(t_hi)) return 0;
    if (coeffs[4] == 0) return solve_cubic(coeffs, t_lo, t_hi, roots);
    const double a = coeffs[3] / coeffs[4];
    const double b = coeffs[2] / coeffs[4];
    const double c = coeffs[1] / coeffs[4];
    const double d = coeffs[0] / coeffs[4];
    const double a2 = a * a;
    const double p = b - 0.375 * a2;
    const double q = c - 0.5 * a * b + 0.125 * a2 * a;
    const double r = d - 0.25 * a * c + 0.0625 * a2 * b - 3.0 / 256.0 * a2 * a2;

    double found[4];
    int found_count = 0;
    auto add_quadratic = [&](double qa, double qb, double qc) {
        double pair[2];
        const int n = solve_quadratic(qa, qb, qc, pair);
        for (int i = 0; i < n; ++i) found[found_count++] = pair[i] - 0.25 * a;
    };
    // Q below its own rounding error: the quartic is biquadratic (the resolvent's root is 0).
    const double q_error =
        4 * kUnitRoundoff * (std::abs(c) + std::abs(0.5 * a * b) + std::abs(0.125 * a2 * a));
    if (std::abs(q) <= q_error) {
        // Biquadratic: z = y^2 solves z^2 + P z + R = 0.
        double z[2];
        const int n = solve_quadratic(1.0, p, r, z);
        for (int i = 0; i < n; ++i) {
            if (z[i] < 0) continue;
            const double y = std::sqrt(z[i]);
            found[found_count++] = -y - 0.25 * a;
            found[found_count++] = y - 0.25 * a;
        }
    } else {
        const double m_max =
            largest_cubic_root(2 * p, difference_of_products(p, p, 4.0, r), -q * q);
        if (m_max > 0) {
            const double s = std::sqrt(m_max);
            const double u = 0.5 * (p + m_max - q / s);
            const double v = 0.5 * (p + m_max + q / s);
            add_quadratic(1.0, s, u);
            add_quadratic(1.0, -s, v);
        }
    }

    int count = 0;
    for (int i = 0; i < found_count; ++i) {
        double t = found[i];
        double value, slope;
        evaluate<double, 4>(coeffs, t, value, slope);
        for (int step = 0; step < 4 && value != 0 && slope != 0; ++step) {
            const double next = t - value / slope;
            double next_value, next_slope;
            evaluate<double, 4>(coeffs, next, next_value, next_slope);
            if (!(std::abs(next_value) < std::abs(value))) break;
            t = next;
            value = next_value;
            slope = next_slope;
        }
        if (t >= t_lo && t <= t_hi) roots[count++] = t;
    }
    std::sort(roots, roots + count);
    return count;
}

}  // namespace

int solve_cubic(double a, double b, double c, double d, double roots[3]) {
    return solve_cubic_any(a, b, c, d, roots);
}

int solve_cubic(long double a, long double b, long double c, long double d, long double roots[3]) {
    return solve_cubic_any(a, b, c, d, roots);
}

int solve_cubic(const double coeffs[4], double t_lo, double t_hi, double roots[3]) {
    if (!all_finite<double, 3>(coeffs) || std::isnan(t_lo) || std::isnan(t_hi)) return 0;
    return roots_in_interval<double, 3>(coeffs, nullptr, t_lo, t_hi, roots, true);
}

int solve_quartic(const double coeffs[5], double t_lo, double t_hi, double roots[4],
                  QuarticMethod method) {
    if (method == QuarticMethod::kClosedForm) {
        return solve_quartic_closed_form(coeffs, t_lo, t_hi, roots);
    }
    return solve_quartic_bracketing<double>(coeffs, nullptr, t_lo, t_hi, roots);
}

int solve_quartic(const double coeffs[5], const double coefficient_errors[5], double t_lo,
                  double t_hi, double roots[4]) {
    return solve_quartic_bracketing<double>(coeffs, coefficient_errors, t_lo, t_hi, roots);
}

int solve_quartic(const long double coeffs[5], long double t_lo, long double t_hi,
                  long double roots[4]) {
    return solve_quartic_bracketing<long double>(coeffs, nullptr, t_lo, t_hi, roots);
}

}  // namespace csgrt
