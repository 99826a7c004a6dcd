#include "csgrt/core/triangle.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "csgrt/core/error.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

// Exact predicates on integer coordinates: every product below is an exact 64-bit integer for
// the coordinates used here (|coordinate| <= 100), so the classification is exact arithmetic.
using Int3 = std::array<long long, 3>;

Int3 minus(const Int3& a, const Int3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Int3 cross(const Int3& a, const Int3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
long long dot(const Int3& a, const Int3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point3 to_point(const Int3& a) {
    return Point3(double(a[0]), double(a[1]), double(a[2]));
}

using IntTriangle = std::array<Int3, 3>;

enum class Exact { kMiss, kBoundary, kInterior, kCoplanar };

// Whether the ray o + t d, t >= 0, meets the closed triangle: the line does iff the signed
// volumes of d with the three edges seen from o share a sign and are not all zero; the ray
// does if moreover t = (p0 - o) . N / (d . N) >= 0. kBoundary: through an edge or vertex, or
// at t = 0. kCoplanar: the line lies in the triangle's plane (all volumes zero), a grazing
// case the double test only rejects when the rounded det is 0, so either answer is allowed.
Exact exact_ray_triangle(const Int3& o, const Int3& d, const IntTriangle& p) {
    const Int3 a = minus(p[0], o), b = minus(p[1], o), c = minus(p[2], o);
    const long long s0 = dot(d, cross(b, c)), s1 = dot(d, cross(c, a)), s2 = dot(d, cross(a, b));
    if ((s0 < 0 || s1 < 0 || s2 < 0) && (s0 > 0 || s1 > 0 || s2 > 0)) return Exact::kMiss;
    const Int3 normal = cross(minus(p[1], p[0]), minus(p[2], p[0]));
    const long long numerator = dot(a, normal), denominator = dot(d, normal);
    if (denominator == 0) return Exact::kCoplanar;
    if (numerator != 0 && (numerator > 0) != (denominator > 0)) return Exact::kMiss;
    return (s0 == 0 || s1 == 0 || s2 == 0 || numerator == 0) ? Exact::kBoundary : Exact::kInterior;
}

// Fires `ray`s from integer origins at integer targets on a mesh and checks every triangle's
// answer against the exact predicate: a hit must be an exact hit, an exact interior hit must
// be found, and where the ray crosses the mesh (all touched triangles face the same way along
// d, so the mesh around the target projects onto a full neighbourhood) at least one triangle
// must report it. Returns how many rays had that last check.
int check_mesh_against_exact(const std::vector<IntTriangle>& mesh, const std::vector<Int3>& targets,
                             int rays_per_target, std::uint64_t seed) {
    std::vector<Triangle> triangles;
    for (const IntTriangle& p : mesh)
        triangles.emplace_back(to_point(p[0]), to_point(p[1]), to_point(p[2]));
    test::Random random(seed);
    int crossing_rays = 0;
    for (const Int3& target : targets) {
        for (int i = 0; i < rays_per_target; ++i) {
            const int side = random.integer(0, 1) ? 1 : -1;
            const Int3 origin{random.integer(-40, 40), side * random.integer(15, 60),
                              random.integer(-40, 40)};
            const Int3 d = minus(target, origin);
            const Ray ray{to_point(origin), to_point(d)};
            int hits = 0, touched = 0, facing_sign = 0;
            bool transversal = true;
            for (std::size_t k = 0; k < mesh.size(); ++k) {
                const Exact exact = exact_ray_triangle(origin, d, mesh[k]);
                const bool hit = triangles[k].occluded(ray);
                EXPECT_EQ(hit, triangles[k].intersect(ray).has_value());
                if (hit) {
                    ++hits;
                    EXPECT_NE(exact, Exact::kMiss) << "false hit on triangle " << k;
                }
                if (exact == Exact::kInterior) {
                    EXPECT_TRUE(hit) << "missed interior " << k;
                }
                if (exact == Exact::kMiss) continue;
                ++touched;
                if (exact == Exact::kCoplanar) transversal = false;
                const Int3 normal =
                    cross(minus(mesh[k][1], mesh[k][0]), minus(mesh[k][2], mesh[k][0]));
                const long long facing = dot(d, normal);
                const int sign = facing > 0 ? 1 : -1;
                if (facing_sign == 0) facing_sign = sign;
                if (facing == 0 || sign != facing_sign) transversal = false;
            }
            if (touched == 0 || !transversal) continue;
            ++crossing_rays;
            EXPECT_GE(hits, 1) << "crack: origin (" << origin[0] << ", " << origin[1] << ", "
                               << origin[2] << ") target (" << target[0] << ", " << target[1]
                               << ", " << target[2] << ")";
        }
    }
    return crossing_rays;
}

const Triangle kUnitTriangle(Point3(0, 0, 0), Point3(2, 0, 0), Point3(0, 2, 0));

TEST(Triangle, AnalyticHitWithBarycentrics) {
    const std::optional<Hit> hit =
        kUnitTriangle.intersect(Ray{Point3(0.5, 0.25, 3), Vector3(0, 0, -2)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 1.5);
    EXPECT_EQ(hit->point, Point3(0.5, 0.25, 0));
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 0, 1));  // (p1 - p0) x (p2 - p0)
    EXPECT_TRUE(hit->front_face);
    // uv = (b1, b2): p = b0 p0 + b1 p1 + b2 p2 with p1 = (2, 0, 0), p2 = (0, 2, 0).
    EXPECT_EQ(hit->uv, Vector2(0.25, 0.125));
    EXPECT_EQ(hit->shape, &kUnitTriangle);
}

TEST(Triangle, BackSideKeepsTheNormal) {
    const std::optional<Hit> hit =
        kUnitTriangle.intersect(Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 1)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 0, 1));
    EXPECT_FALSE(hit->front_face);
}

TEST(Triangle, MissesOutsideAndPointingAway) {
    EXPECT_FALSE(kUnitTriangle.intersect(Ray{Point3(1.5, 1.5, 1), Vector3(0, 0, -1)}));
    EXPECT_FALSE(kUnitTriangle.intersect(Ray{Point3(-0.1, 0.5, 1), Vector3(0, 0, -1)}));
    EXPECT_FALSE(kUnitTriangle.intersect(Ray{Point3(0.5, 0.5, 1), Vector3(0, 0, 1)}));
    EXPECT_FALSE(kUnitTriangle.occluded(Ray{Point3(0.5, 0.5, 1), Vector3(0, 0, 1)}));
}

TEST(Triangle, EdgesAndVerticesBelongToTheTriangle) {
    for (const Point3& target : {Point3(1, 0, 0), Point3(0, 1, 0), Point3(1, 1, 0), Point3(0, 0, 0),
                                 Point3(2, 0, 0), Point3(0, 2, 0)}) {
        const Point3 origin = target + Vector3(0.5, -0.25, 2);
        EXPECT_TRUE(kUnitTriangle.intersect(Ray{origin, target - origin})) << target.transpose();
    }
}

TEST(Triangle, RaysInOrParallelToThePlaneMiss) {
    for (const Ray& ray : {Ray{Point3(-1, 0.5, 0), Vector3(1, 0, 0)},         // in the plane
                           Ray{Point3(-1, -1, 0), Vector3(1, 1, 0)},          // in it, via p0
                           Ray{Point3(-1, 0.5, 0.1), Vector3(1, 0.2, 0)}}) {  // above it
        EXPECT_FALSE(kUnitTriangle.intersect(ray));
        EXPECT_FALSE(kUnitTriangle.occluded(ray));
    }
}

TEST(Triangle, RayStartingOnTheTriangle) {
    test::expect_hit_only_at_start(kUnitTriangle, Ray{Point3(0.5, 0.5, 0), Vector3(0.3, 0.1, 1)});
}

TEST(Triangle, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(0.5, 0.5, 4), Vector3(0, 0, -1)};  // crosses at t = 4
    test::expect_interval_honoured(kUnitTriangle, ray, 4.0);
    Ray clipped = ray;
    clipped.t_max = 4.0;
    ASSERT_TRUE(kUnitTriangle.intersect(clipped));
    EXPECT_EQ(kUnitTriangle.intersect(clipped)->t, 4.0);
    const Ray behind{Point3(0.5, 0.5, -3), Vector3(0, 0, -1), -kInfinity, 0.0};
    ASSERT_TRUE(kUnitTriangle.intersect(behind));
    EXPECT_EQ(kUnitTriangle.intersect(behind)->t, -3.0);
}

TEST(Triangle, InvalidRaysNeverHit) {
    for (const Ray& ray : test::invalid_variants(Ray{Point3(0.5, 0.5, 4), Vector3(0, 0, -1)})) {
        EXPECT_FALSE(kUnitTriangle.intersect(ray));
        EXPECT_FALSE(kUnitTriangle.occluded(ray));
        HitRecord record;
        QueryScratch scratch;
        // The raw query must not crash or report a hit either.
        EXPECT_FALSE(kUnitTriangle.nearest_hit(ray, record, scratch) && !ray.in_range(record.t));
    }
}

TEST(Triangle, RejectsDegenerateTrianglesNamingTheParameter) {
    const auto message = [](const Point3& p0, const Point3& p1, const Point3& p2) {
        try {
            Triangle(p0, p1, p2);
        } catch (const InvalidParameter& error) {
            return std::string(error.what());
        }
        return std::string("no exception");
    };
    const std::string collinear = message(Point3(0, 0, 0), Point3(1, 1, 1), Point3(3, 3, 3));
    EXPECT_NE(collinear.find("Triangle: p0, p1, p2"), std::string::npos) << collinear;
    EXPECT_NE(message(Point3(1, 2, 3), Point3(1, 2, 3), Point3(0, 0, 1)).find("non-zero area"),
              std::string::npos);
    EXPECT_NE(
        message(Point3(0, 0, 0), Point3(std::nan(""), 0, 0), Point3(0, 1, 0)).find("Triangle: p1"),
        std::string::npos);
    EXPECT_NE(
        message(Point3(0, 0, 0), Point3(1, 0, 0), Point3(0, kInfinity, 0)).find("Triangle: p2"),
        std::string::npos);
    // Tiny but proper triangles are accepted, get a unit normal and are hit; the edge
    // functions are products of two coordinates, so 1e-100 is far from underflow.
    const Triangle tiny(Point3(0, 0, 0), Point3(1e-100, 0, 0), Point3(0, 1e-100, 0));
    EXPECT_NEAR(tiny.normal().norm(), 1.0, 4 * kUnitRoundoff);
    EXPECT_TRUE(tiny.intersect(Ray{Point3(2e-101, 3e-101, 1), Vector3(0.1, 0.2, -1)}) ||
                tiny.intersect(Ray{Point3(2e-101, 3e-101, 1), Vector3(0, 0, -1)}));
    const Triangle huge(Point3(0, 0, 0), Point3(1e200, 0, 0), Point3(0, 0, 1e200));
    EXPECT_EQ(huge.normal(), Normal3(0, -1, 0));
}

TEST(Triangle, WatertightAtTheSharedVertexAndEdgesOfAFan) {
    // Eight triangles around the apex (0, 0, 0), with a bumpy ring, so the fan is not planar.
    // Coordinates are multiples of 4 so points at 1/4, 1/2 and 3/4 along the spokes are integer.
    const std::array<Int3, 8> ring = {Int3{8, 4, 0},  Int3{8, -4, 8},  Int3{0, 0, 8},
                                      Int3{-8, 4, 8}, Int3{-8, -4, 0}, Int3{-8, 0, -8},
                                      Int3{0, 4, -8}, Int3{8, 8, -8}};
    std::vector<IntTriangle> fan;
    for (int i = 0; i < 8; ++i) fan.push_back({Int3{0, 0, 0}, ring[i], ring[(i + 1) % 8]});
    std::vector<Int3> targets = {Int3{0, 0, 0}};
    for (const Int3& spoke : ring) {
        for (long long quarter = 1; quarter <= 3; ++quarter)
            targets.push_back(
                {spoke[0] * quarter / 4, spoke[1] * quarter / 4, spoke[2] * quarter / 4});
    }
    const int crossing = check_mesh_against_exact(fan, targets, 2000, 31);
    EXPECT_GT(crossing, 40000);
}

TEST(Triangle, WatertightAlongTheDiagonalOfAQuad) {
    // A non-planar quad split along its diagonal (0, 0, 0) - (8, 0, 8).
    const std::vector<IntTriangle> quad = {{Int3{0, 0, 0}, Int3{8, 4, 0}, Int3{8, 0, 8}},
                                           {Int3{0, 0, 0}, Int3{8, 0, 8}, Int3{0, -4, 8}}};
    std::vector<Int3> targets;
    for (long long k = 1; k < 8; ++k) targets.push_back({k, 0, k});
    const int crossing = check_mesh_against_exact(quad, targets, 5000, 32);
    EXPECT_GT(crossing, 30000);
}

TEST(Triangle, WatertightOnARandomHeightField) {
    // A 6 x 6 cell height field with random even heights, cells split along alternating
    // diagonals; rays at every interior vertex and every interior edge midpoint.
    test::Random random(33);
    constexpr int kCells = 6;
    std::array<std::array<long long, kCells + 1>, kCells + 1> height;
    for (auto& row : height)
        for (long long& h : row) h = 2 * random.integer(-3, 3);
    const auto vertex = [&](int i, int j) { return Int3{4LL * i, height[i][j], 4LL * j}; };
    std::vector<IntTriangle> mesh;
    std::vector<Int3> targets;
    for (int i = 0; i < kCells; ++i) {
        for (int j = 0; j < kCells; ++j) {
            const Int3 a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1),
                       d = vertex(i, j + 1);
            if ((i + j) % 2 == 0) {
                mesh.push_back({a, b, c});
                mesh.push_back({a, c, d});
            } else {
                mesh.push_back({a, b, d});
                mesh.push_back({b, c, d});
            }
        }
    }
    const auto midpoint = [](const Int3& p, const Int3& q) {
        return Int3{(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
    };
    for (int i = 1; i < kCells; ++i) {
        for (int j = 1; j < kCells; ++j) {
            targets.push_back(vertex(i, j));
            targets.push_back(midpoint(vertex(i, j), vertex(i + 1, j)));
            targets.push_back(midpoint(vertex(i, j), vertex(i, j + 1)));
            // The cell diagonal that the split chose.
            targets.push_back((i + j) % 2 == 0 ? midpoint(vertex(i, j), vertex(i + 1, j + 1))
                                               : midpoint(vertex(i + 1, j), vertex(i, j + 1)));
        }
    }
    const int crossing = check_mesh_against_exact(mesh, targets, 300, 34);
    EXPECT_GT(crossing, 15000);
}

TEST(Triangle, AgreesWithALongDoublePredicateAwayFromTheEdges) {
    using LongVector = Eigen::Matrix<long double, 3, 1>;
    test::Random random(35);
    const Aabb box(Point3(-5, -5, -5), Point3(5, 5, 5));
    int compared = 0, hits = 0;
    double worst_t_ratio = 0.0;
    for (int i = 0; i < 100000; ++i) {
        const Point3 p0 = random.in_box(box), p1 = random.in_box(box), p2 = random.in_box(box);
        const Triangle triangle(p0, p1, p2);
        const Ray ray = random.ray_between(test::enlarged(box, 1.0), box);
        const LongVector o = ray.origin.cast<long double>(), d = ray.direction.cast<long double>();
        const LongVector a = p0.cast<long double>() - o, b = p1.cast<long double>() - o,
                         c = p2.cast<long double>() - o;
        const long double s0 = d.dot(b.cross(c)), s1 = d.dot(c.cross(a)), s2 = d.dot(a.cross(b));
        // Double rounding moves the ray and vertices by ~u |x|; only rays farther than 1e-9
        // relative from every edge and from t = 0 are decided in double beyond doubt.
        const long double size = std::max({a.norm(), b.norm(), c.norm()});
        const long double margin = 1e-9L * d.norm() * size * size;
        if (std::min({std::abs(s0), std::abs(s1), std::abs(s2)}) < margin) continue;
        const LongVector normal = (b - a).cross(c - a);
        const long double t = a.dot(normal) / d.dot(normal);
        if (std::abs(t) * d.norm() < 1e-9L * size) continue;
        ++compared;
        const bool expected = ((s0 > 0) == (s1 > 0)) && ((s1 > 0) == (s2 > 0)) && t >= 0;
        const std::optional<Hit> hit = triangle.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected) << "ray " << i;
        if (!hit) continue;
        ++hits;
        // First-order error of t = a . N / (d . N) when vertices and ray carry relative errors
        // of a few u: (|a| + |t d|) |edge|^2 / |d . N|, with 64 u for the chain of operations.
        const long double edges = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
        const long double allowed = 64 * kUnitRoundoff * (size + std::abs(t) * d.norm()) * edges *
                                    edges / std::abs(d.dot(normal));
        EXPECT_NEAR(hit->t, static_cast<double>(t), static_cast<double>(allowed)) << "ray " << i;
        worst_t_ratio = std::max(worst_t_ratio, double(std::abs(hit->t - t) / allowed));
        // The barycentrics reproduce the point (float storage: 2^-24 relative).
        const Point3 from_uv =
            (1.0 - hit->uv.x() - hit->uv.y()) * p0 + hit->uv.x() * p1 + hit->uv.y() * p2;
        EXPECT_LT((from_uv - hit->point).norm(), 1e-6 * (size + 1.0) * edges / double(size))
            << "ray " << i;
    }
    EXPECT_GT(compared, 90000);
    EXPECT_GT(hits, 5000);
    RecordProperty("worst_t_error_over_bound", std::to_string(worst_t_ratio));
}

TEST(Triangle, NeedleTrianglesStillHit) {
    // A Moeller-Trumbore test that rejects |det| < 1e-8 drops all of these: det is about twice
    // the area times |d|. The watertight test has no epsilon.
    test::Random random(36);
    for (const double width : {1e-6, 1e-9, 1e-12}) {
        int hits = 0, misses = 0;
        for (int i = 0; i < 2000; ++i) {
            const Eigen::Matrix3d rotation =
                Eigen::AngleAxisd(random.uniform(0, kTwoPi), random.unit_vector()).matrix();
            const Point3 offset = random.in_box(Aabb(Point3(-3, -3, -3), Point3(3, 3, 3)));
            const Point3 p0 = offset;
            const Point3 p1 = offset + rotation * Vector3(1, 0, 0);
            const Point3 p2 = offset + rotation * Vector3(1, width, 0);
            const Triangle needle(p0, p1, p2);
            const double along = random.uniform(0.3, 0.6), across = random.uniform(0.2, 0.35);
            const Point3 inside = p0 + along * (p1 - p0) + across * (p2 - p0);
            // Just past the edge p0 p1, by as much as `inside` is within it.
            const Point3 outside = p0 + along * (p1 - p0) - across * (p2 - p1);
            Vector3 direction = random.unit_vector();
            if (std::abs(direction.dot(needle.normal())) < 0.2) direction = needle.normal();
            const double distance = random.uniform(1.0, 5.0);
            const std::optional<Hit> hit =
                needle.intersect(Ray{inside - distance * direction, direction});
            ASSERT_TRUE(hit) << "width " << width << " ray " << i;
            EXPECT_NEAR(hit->t, distance, 64 * kUnitRoundoff * 10);
            ++hits;
            if (!needle.intersect(Ray{outside - distance * direction, direction})) ++misses;
        }
        EXPECT_EQ(hits, 2000);
        EXPECT_EQ(misses, 2000) << "width " << width;
    }
}

TEST(Triangle, PropertiesOnRandomRays) {
    const Triangle triangle(Point3(0.3, -1.2, 2.0), Point3(2.1, 0.4, 1.1), Point3(-0.7, 1.5, 0.2));
    const test::SurfaceDescription surface =
        test::plane_surface(triangle.vertex(0), triangle.normal(), 2.0, triangle.bounds());
    const test::PropertyCounts counts = test::check_shape_properties(triangle, surface, 100000, 37);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 20000);
}

}  // namespace
}  // namespace csgrt
