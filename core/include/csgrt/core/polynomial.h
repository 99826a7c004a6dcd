#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "csgrt/core/math.h"

namespace csgrt {

namespace detail {

/// solve_quadratic for double and long double (long double serves as the reference precision
/// in tests).
template <class Real>
int solve_quadratic(Real a, Real b, Real c, Real roots[2]) {
    if (a == 0) {
        if (b == 0) return 0;
        roots[0] = -c / b;
        return 1;
    }
    // b^2 - 4ac with the rounding of 4ac compensated by FMA (Kahan): one rounding in all.
    const Real four_ac = 4 * a * c;
    const Real discriminant = std::fma(b, b, -four_ac) + std::fma(-4 * a, c, four_ac);
    if (!(discriminant >= 0)) return 0;  // also rejects NaN coefficients
    const Real q = Real(-0.5) * (b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0) {
        // b == 0 and disc == 0, so c == 0: the double root 0.
        roots[0] = roots[1] = 0;
        return 2;
    }
    roots[0] = q / a;
    roots[1] = c / q;
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    return 2;
}

/// A root of a continuous function f in [lo, hi], given that f(lo) and f(hi) are nonzero with
/// opposite signs (`negative_at_lo` says which), starting from `start` in [lo, hi].
/// `evaluate(x, value, slope, error)` gives f(x), f'(x) and a bound on the rounding error of
/// the computed f(x). Safeguarded Newton as in "rtsafe" (Press et al., "Numerical Recipes",
/// 3rd ed., 9.4): a Newton step is taken only when it stays inside the bracket and at least
/// halves the step before the last one, otherwise the bracket is bisected, and every
/// evaluation shrinks the bracket by its sign. So it always converges (at worst linearly),
/// quadratically near a simple root, and never leaves the bracket. Stops as soon as |f(x)| is
/// within its rounding error (x is then as close to the root as f's precision can tell; one
/// last Newton step from there is free), when
/// a step falls below 2 ulps of x, or after 200 evaluations (bisection alone gains a bit per
/// evaluation, so this only cuts off brackets spanning ~1e60).
template <class Real, class Evaluate>
Real bracketed_root(const Evaluate& evaluate, Real lo, Real hi, bool negative_at_lo, Real start) {
    constexpr Real kUlps = 2 * std::numeric_limits<Real>::epsilon();
    Real x = start >= lo && start <= hi ? start : lo + Real(0.5) * (hi - lo);
    Real step = hi - lo;
    Real step_before = step;
    for (int iteration = 0; iteration < 200; ++iteration) {
        Real value, slope, error;
        evaluate(x, value, slope, error);
        const Real newton = x - value / slope;
        if (std::abs(value) <= error) {
            // The last step costs no evaluation and, as the error bound is pessimistic,
            // usually still gains digits.
            return newton >= lo && newton <= hi ? newton : x;
        }
        if ((value < 0) == negative_at_lo) {
            lo = x;
        } else {
            hi = x;
        }
        Real next;
        if (newton > lo && newton < hi && std::abs(newton - x) <= Real(0.5) * step_before) {
            next = newton;
        } else {
            next = lo + Real(0.5) * (hi - lo);
            if (!(next > lo && next < hi)) return x;  // the bracket is two adjacent numbers
        }
        step_before = step;
        step = std::abs(next - x);
        x = next;
        if (step <= kUlps * std::abs(x)) return x;
    }
    return x;
}

}  // namespace detail

/// Real roots of a x^2 + b x + c = 0, written to roots[] in increasing order; returns how many
/// (0, 1 or 2; a double root is reported twice). The discriminant is formed with one rounding
/// (as in difference_of_products) and the roots by the cancellation-free pair q = -(b + sign(b)
/// sqrt(disc)) / 2, x = q / a and x = c / q (Press et al., "Numerical Recipes", 5.6).
/// a == 0 falls back to the linear equation; a == b == 0 has no isolated roots (returns 0).
inline int solve_quadratic(double a, double b, double c, double roots[2]) {
    return detail::solve_quadratic(a, b, c, roots);
}
/// solve_quadratic in long double, for reference solutions in tests.
inline int solve_quadratic(long double a, long double b, long double c, long double roots[2]) {
    return detail::solve_quadratic(a, b, c, roots);
}

/// How solve_quartic finds its roots (both are compared in the benchmark; docs/accuracy.md).
enum class QuarticMethod {
    /// Isolation between the extrema, then safeguarded Newton on each monotone piece: exact in
    /// its root count up to the rounding of p, accurate to the conditioning of each root. The
    /// default, and the most accurate.
    kBracketing,
    /// Ferrari's closed form through the resolvent cubic, each root then polished by Newton on
    /// the original polynomial: the textbook method, faster but less robust (it can lose or
    /// duplicate roots near multiple roots and at widely spread magnitudes).
    kClosedForm,
};

/// Real roots of a t^3 + b t^2 + c t + d = 0 in increasing order; returns how many (0 to 3).
/// Found by bracketing (see solve_quartic). A root where the polynomial changes sign is
/// reported once, a root where it touches zero without changing sign (a double root) twice;
/// so a triple root is reported once. a == 0 falls back to solve_quadratic. Assumes the
/// coefficients are finite (otherwise returns 0) and the roots are below about 1e75 in
/// magnitude (so that p can be evaluated at them without overflow).
int solve_cubic(double a, double b, double c, double d, double roots[3]);
/// solve_cubic in long double, for reference solutions in tests.
int solve_cubic(long double a, long double b, long double c, long double d, long double roots[3]);

/// The real roots of the cubic sum_i coeffs[i] t^i (coefficients in ascending powers) in the
/// closed interval [t_lo, t_hi] (infinite ends allowed), in increasing order, counted as in
/// solve_cubic.
int solve_cubic(const double coeffs[4], double t_lo, double t_hi, double roots[3]);

/// The real roots of the quartic p(t) = sum_i coeffs[i] t^i (coefficients in ASCENDING powers:
/// coeffs[4] multiplies t^4) in the closed interval [t_lo, t_hi] (infinite ends allowed: the
/// roots are then bracketed by Fujiwara's bound), in increasing order; returns how many.
///
/// kBracketing: the roots of p' (a cubic, solved the same way on the same interval, its
/// extrema in turn from a quadratic) split [t_lo, t_hi] into pieces on which p is monotone;
/// a piece whose ends have strictly opposite signs holds exactly one root, refined by
/// safeguarded Newton. An extremum where |p| is within the rounding error of evaluating p
/// there (gamma(9) sum |coeffs[i]| |t|^i: Horner's error plus one rounding of each
/// coefficient) is a double root (a tangent ray), reported twice, so it is neither lost nor
/// duplicated by a neighbouring piece. Hence: a root where p changes sign is reported once, a
/// root where p touches zero twice (like solve_quadratic), and the count has the parity of
/// the sign change between t_lo and t_hi. A root exactly at an end is reported once.
/// Leading coefficients that are zero fall back to the cubic and quadratic. Assumes finite
/// coefficients (otherwise returns 0) and roots below about 1e75 in magnitude.
int solve_quartic(const double coeffs[5], double t_lo, double t_hi, double roots[4],
                  QuarticMethod method = QuarticMethod::kBracketing);

/// solve_quartic (kBracketing) for coefficients known only to within absolute errors
/// coefficient_errors[i] (e.g. computed from a ray): an extremum where |p| is within the
/// error of p there (sum coefficient_errors[i] |t|^i, plus rounding) is reported as a double
/// root, so the caller can decide every near-tangency with a better-conditioned function
/// rather than have it decided by noise.
int solve_quartic(const double coeffs[5], const double coefficient_errors[5], double t_lo,
                  double t_hi, double roots[4]);

/// solve_quartic (kBracketing) in long double, for reference solutions in tests.
int solve_quartic(const long double coeffs[5], long double t_lo, long double t_hi,
                  long double roots[4]);

}  // namespace csgrt
