#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "csgrt/core/aabb.h"
#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"

namespace csgrt::test {

/// Seeded random numbers for property tests: a failure reproduces from the seed it prints.
class Random {
public:
    explicit Random(std::uint64_t seed) : engine_(seed) {}

    double uniform(double lo = 0.0, double hi = 1.0) {
        return std::uniform_real_distribution<double>(lo, hi)(engine_);
    }
    int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(engine_); }

    // The order in which a function's arguments are evaluated is unspecified (GCC goes right
    // to left, clang left to right), so the draws below are sequenced explicitly: z first, as
    // GCC did when the tests' thresholds were measured, and the same numbers with any compiler.

    /// Uniform on the unit sphere (Marsaglia's normal-deviate method).
    Vector3 unit_vector() {
        std::normal_distribution<double> normal;
        Vector3 v;
        do {
            const double z = normal(engine_);
            const double y = normal(engine_);
            const double x = normal(engine_);
            v = Vector3(x, y, z);
        } while (v.squaredNorm() < 1e-12);
        return v.normalized();
    }

    Point3 in_box(const Aabb& box) {
        const double z = uniform(box.lower.z(), box.upper.z());
        const double y = uniform(box.lower.y(), box.upper.y());
        const double x = uniform(box.lower.x(), box.upper.x());
        return Point3(x, y, z);
    }

    /// A ray from a random point of `from` toward a random point of `toward`, with a direction
    /// of random length in [0.25, 4] so nothing relies on unit directions.
    Ray ray_between(const Aabb& from, const Aabb& toward) {
        Ray ray;
        ray.origin = in_box(from);
        Vector3 direction = in_box(toward) - ray.origin;
        if (direction.squaredNorm() == 0.0) direction = unit_vector();
        ray.direction = direction.normalized() * uniform(0.25, 4.0);
        return ray;
    }

    std::mt19937_64& engine() { return engine_; }

private:
    std::mt19937_64 engine_;
};

/// A direction whose cosine with `axis` (unit) is at least `minimum_cosine`, or its opposite
/// when that one is, of random length in [0.25, 4].
inline Vector3 direction_around(Random& random, const Vector3& axis, double minimum_cosine) {
    for (;;) {
        const Vector3 d = random.unit_vector();
        const double cosine = d.dot(axis);
        if (cosine >= minimum_cosine) return d * random.uniform(0.25, 4.0);
        if (-cosine >= minimum_cosine) return -d * random.uniform(0.25, 4.0);
    }
}

/// `box` grown by `factor` times its diagonal on every side.
inline Aabb enlarged(const Aabb& box, double factor) {
    const Vector3 margin = box.diagonal() * factor;
    return Aabb(box.lower - margin, box.upper + margin);
}

/// The `i`-th of a run of random rays toward `box`: from a box around it (ray_between
/// enlarged(box, 1.0) and box), and from inside it every fourth ray.
inline Ray ray_toward(Random& random, const Aabb& box, int i) {
    Ray ray = random.ray_between(enlarged(box, 1.0), box);
    if (i % 4 == 0) ray.origin = random.in_box(box);
    return ray;
}

}  // namespace csgrt::test
