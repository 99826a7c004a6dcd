// The float triangle test's exactness argument (watertightness, and every structure returning
// the very bits of TriangleSet<float>::intersect) assumes that every float operation rounds.
// GCC 12 auto-vectorises straight-line float code (SLP); a transformation that kept an
// intermediate in double or fused a multiply-add would drop a rounding and change bits on a
// fraction of rays. The independent answer here is the test written out operation by operation
// with each float rounding explicit: float(double(a) op double(b)) is the correctly rounded
// float result of a op b for +, -, * (double has 53 >= 2 * 24 + 2 bits, so rounding twice is
// innocuous; Figueroa, "When is double rounding innocuous?", 1995). Every registered structure,
// as built in the library with the library's flags, must give its bits on every ray; and the
// same emulation with one rounding dropped must differ, so the comparison can catch one.

#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/accel/triangle_set.h"
#include "support/random.h"

namespace csgrt {
namespace {

float rounded_sub(float a, float b) {
    return static_cast<float>(double(a) - double(b));
}
float rounded_mul(float a, float b) {
    return static_cast<float>(double(a) * double(b));
}
float rounded_add(float a, float b) {
    return static_cast<float>(double(a) + double(b));
}

struct EmulatedHit {
    double t, b1, b2;
};

/// TriangleSet<float>'s watertight test on triangle i, written out with every float rounding
/// explicit. With `drop_shear_rounding`, the shear's products are not rounded before their
/// differences (the rounding a fused multiply-add or a wider intermediate would drop).
std::optional<EmulatedHit> emulate(const TriangleSet<float>& set, std::size_t i, const Ray& ray,
                                   bool drop_shear_rounding = false) {
    const int kz = max_dimension(ray.direction), kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    const float ox = static_cast<float>(ray.origin[kx]), oy = static_cast<float>(ray.origin[ky]),
                oz = static_cast<float>(ray.origin[kz]);
    const double shear_z = 1.0 / ray.direction[kz];
    const float shear_x = static_cast<float>(ray.direction[kx] / ray.direction[kz]);
    const float shear_y = static_cast<float>(ray.direction[ky] / ray.direction[kz]);
    float x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
        const auto& c = set.corner(i, k);
        const float px = rounded_sub(c[kx], ox), py = rounded_sub(c[ky], oy),
                    pz = rounded_sub(c[kz], oz);
        if (drop_shear_rounding) {
            // The product's rounding dropped, as a fused multiply-add or a double
            // intermediate would: px - shear_x pz rounded once.
            x[k] = static_cast<float>(double(px) - double(shear_x) * double(pz));
            y[k] = static_cast<float>(double(py) - double(shear_y) * double(pz));
        } else {
            x[k] = rounded_sub(px, rounded_mul(shear_x, pz));
            y[k] = rounded_sub(py, rounded_mul(shear_y, pz));
        }
        z[k] = pz;
    }
    float u = rounded_sub(rounded_mul(x[2], y[1]), rounded_mul(y[2], x[1]));
    float v = rounded_sub(rounded_mul(x[0], y[2]), rounded_mul(y[0], x[2]));
    float w = rounded_sub(rounded_mul(x[1], y[0]), rounded_mul(y[1], x[0]));
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        u = static_cast<float>(double(x[2]) * double(y[1]) - double(y[2]) * double(x[1]));
        v = static_cast<float>(double(x[0]) * double(y[2]) - double(y[0]) * double(x[2]));
        w = static_cast<float>(double(x[1]) * double(y[0]) - double(y[1]) * double(x[0]));
    }
    if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return std::nullopt;
    if (rounded_add(rounded_add(u, v), w) == 0.0f) return std::nullopt;
    const double az = shear_z * double(z[0]), bz = shear_z * double(z[1]),
                 cz = shear_z * double(z[2]);
    const double scaled_t = double(u) * az + double(v) * bz + double(w) * cz;
    const double inverse = 1.0 / (double(u) + double(v) + double(w));
    return EmulatedHit{scaled_t * inverse, double(v) * inverse, double(w) * inverse};
}

/// The nearest emulated hit in [t_min, t_max], ties to the lower index, by brute force.
std::optional<std::pair<std::size_t, EmulatedHit>> emulate_nearest(const TriangleSet<float>& set,
                                                                   const Ray& ray,
                                                                   bool drop = false) {
    std::optional<std::pair<std::size_t, EmulatedHit>> best;
    for (std::size_t i = 0; i < set.size(); ++i) {
        const std::optional<EmulatedHit> hit = emulate(set, i, ray, drop);
        if (!hit || !(hit->t >= ray.t_min && hit->t <= ray.t_max)) continue;
        if (!best || hit->t < best->second.t) best = {{i, *hit}};
    }
    return best;
}

TEST(FloatRounding, EveryStructureGivesTheBitsOfTheTestWithEveryRoundingExplicit) {
    // Small triangles of a soup at magnitudes from 1e-3 to 1e3 (far from the origin, the
    // roundings of corner - origin matter most), rays aimed at points inside them.
    test::Random random(122);
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (int i = 0; i < 600; ++i) {
        const double scale = std::pow(10.0, random.uniform(-3.0, 3.0));
        const Point3 centre =
            scale * Vector3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
        const auto first = static_cast<std::uint32_t>(vertices.size());
        for (int k = 0; k < 3; ++k)
            vertices.push_back(centre + 0.05 * scale * random.unit_vector());
        triangles.push_back({first, first + 1, first + 2});
    }
    const TriangleSet<float> set(vertices, triangles);
    std::vector<Ray> rays;
    for (int r = 0; r < 3000; ++r) {
        const std::size_t i = static_cast<std::size_t>(random.integer(0, int(set.size()) - 1));
        double a = random.uniform(), b = random.uniform();
        if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
        const Point3 target = (1.0 - a - b) * set.corner(i, 0).cast<double>() +
                              a * set.corner(i, 1).cast<double>() +
                              b * set.corner(i, 2).cast<double>();
        const double distance = 3.0 * (target.norm() + 1e-3);
        const Point3 origin = target + distance * random.unit_vector();
        rays.push_back(Ray{origin, (target - origin) * random.uniform(0.5, 2.0)});
    }
    std::vector<std::optional<std::pair<std::size_t, EmulatedHit>>> expected(rays.size());
    long hits = 0, changed_by_a_dropped_rounding = 0;
    for (std::size_t r = 0; r < rays.size(); ++r) {
        expected[r] = emulate_nearest(set, rays[r]);
        if (!expected[r]) continue;
        ++hits;
        const std::optional<EmulatedHit> dropped = emulate(set, expected[r]->first, rays[r], true);
        if (!dropped || dropped->t != expected[r]->second.t ||
            dropped->b1 != expected[r]->second.b1)
            ++changed_by_a_dropped_rounding;
    }
    ASSERT_GT(hits, 2500);
    // The comparison below can see one dropped rounding: it changes the bits of many hits.
    EXPECT_GT(changed_by_a_dropped_rounding, hits / 20);
    std::printf("\n  | structure | rays | hits | bit-identical to the explicit-rounding test |\n");
    QueryScratch scratch;
    for (const std::string_view name : accelerator_names()) {
        const auto structure = make_accelerator(name, set);
        long same = 0, structure_hits = 0;
        for (std::size_t r = 0; r < rays.size(); ++r) {
            HitRecord record;
            const bool hit = structure->intersect(rays[r], record, scratch);
            structure_hits += hit;
            ASSERT_EQ(hit, expected[r].has_value()) << name << " ray " << r;
            if (!hit) continue;
            const EmulatedHit& e = expected[r]->second;
            const bool identical = record.t == e.t && record.u == static_cast<float>(e.b1) &&
                                   record.v == static_cast<float>(e.b2);
            EXPECT_TRUE(identical) << name << " ray " << r << ": t " << record.t << " vs " << e.t;
            EXPECT_EQ(record.primitive, expected[r]->first) << name << " ray " << r;
            same += identical;
        }
        std::printf("  | %s | %zu | %ld | %ld |\n", std::string(name).c_str(), rays.size(),
                    structure_hits, same);
    }
    std::printf("  | (the shear's product rounding dropped) | %zu | %ld | %ld |\n", rays.size(),
                hits, hits - changed_by_a_dropped_rounding);
}

}  // namespace
}  // namespace csgrt
