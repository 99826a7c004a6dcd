// Hostile rays against every shape and every structure: NaN and infinite origins and
// directions, zero and denormal directions, NaN and reversed intervals, and valid rays with
// extreme magnitudes. Nothing may crash (the asan preset runs this too) or hang (a watchdog
// aborts the program after a minute and names the case); invalid rays never hit.
//
// What a denormal direction means is defined here: is_valid (core/ray.h) asks for
// |d|^2 > 0, so a direction whose squared length underflows to zero (every denormal
// direction, and any |d| below about 1.5e-162) is a zero direction, rejected by the public
// queries and by every structure. A direction of length 1e-150 or 1e150 is valid and must give
// the same hit point as the unit direction, t scaled by 1 / |d|.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/mesh/mesh.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "stress/summary.h"
#include "support/example_shapes.h"
#include "support/meshes.h"
#include "support/random.h"

namespace csgrt {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kDenormal = std::numeric_limits<double>::denorm_min();
constexpr double kHuge = std::numeric_limits<double>::max();

/// Aborts the program, naming the case, if the scope is not left within `seconds`: a query
/// that loops forever must fail the test, not stall CI until its timeout.
class Watchdog {
public:
    explicit Watchdog(int seconds)
        : thread_([this, seconds] {
              std::unique_lock lock(mutex_);
              if (!done_condition_.wait_for(lock, std::chrono::seconds(seconds),
                                            [this] { return done_; })) {
                  std::fprintf(stderr, "watchdog: a query hung on case: %s\n",
                               where_.load() ? where_.load() : "?");
                  std::abort();
              }
          }) {}
    ~Watchdog() {
        {
            std::lock_guard lock(mutex_);
            done_ = true;
        }
        done_condition_.notify_one();
        thread_.join();
    }
    void at(const char* where) { where_.store(where); }

private:
    std::mutex mutex_;
    std::condition_variable done_condition_;
    bool done_ = false;
    std::atomic<const char*> where_{nullptr};
    std::thread thread_;
};

struct NamedRay {
    std::string name;
    Ray ray;
    /// A valid ray whose interval holds no finite t: no query may report a hit.
    bool never_hits = false;
};

/// Invalid rays (is_valid false), each aimed so that a valid version would hit the unit-sized
/// shapes near the world origin.
std::vector<NamedRay> invalid_rays() {
    const Point3 o(0.1, 0.2, -5.0);
    const Vector3 d(0.01, -0.02, 1.0);
    std::vector<NamedRay> rays;
    for (int axis = 0; axis < 3; ++axis) {
        for (const double bad : {kNan, kInfinity, -kInfinity}) {
            Ray origin{o, d};
            origin.origin[axis] = bad;
            rays.push_back(
                {"origin[" + std::to_string(axis) + "] = " + std::to_string(bad), origin});
            Ray direction{o, d};
            direction.direction[axis] = bad;
            rays.push_back(
                {"direction[" + std::to_string(axis) + "] = " + std::to_string(bad), direction});
        }
    }
    rays.push_back({"zero direction", Ray{o, Vector3(0, 0, 0)}});
    rays.push_back({"negative zero direction", Ray{o, Vector3(-0.0, -0.0, -0.0)}});
    rays.push_back({"denormal direction", Ray{o, Vector3(0, 0, kDenormal)}});
    rays.push_back({"denormal direction, all axes", Ray{o, Vector3::Constant(1e-310)}});
    rays.push_back({"direction 1e-170 (|d|^2 underflows)", Ray{o, d * 1e-170}});
    rays.push_back({"all NaN", Ray{Point3::Constant(kNan), Vector3::Constant(kNan)}});
    rays.push_back(
        {"all infinite", Ray{Point3::Constant(kInfinity), Vector3::Constant(-kInfinity)}});
    rays.push_back({"t_min NaN", Ray{o, d, kNan, kInfinity}});
    rays.push_back({"t_max NaN", Ray{o, d, 0.0, kNan}});
    rays.push_back({"t_min > t_max", Ray{o, d, 6.0, 4.0}});
    for (const NamedRay& named : rays) {
        EXPECT_FALSE(is_valid(named.ray)) << named.name;
    }
    return rays;
}

/// Valid rays with extreme magnitudes: queries must neither crash nor hang, and a reported hit
/// must have a t in the interval (so never NaN).
std::vector<NamedRay> extreme_valid_rays() {
    const Vector3 d(0.01, -0.02, 1.0);
    std::vector<NamedRay> rays = {
        {"origin 1e300", Ray{Point3(1e300, -1e300, 1e300), -Vector3(1e300, -1e300, 1e300)}},
        {"origin at max double", Ray{Point3(kHuge, 0, 0), Vector3(-1, 0, 0)}},
        {"direction 1e300", Ray{Point3(0.1, 0.2, -5), d * 1e300}},
        {"direction at max double", Ray{Point3(0.1, 0.2, -5), Vector3(0, 0, kHuge)}},
        {"direction 1e-160", Ray{Point3(0.1, 0.2, -5), d * 1e-160}},
        {"origin denormal", Ray{Point3(kDenormal, -kDenormal, kDenormal), d}},
        {"interval [-inf, inf]", Ray{Point3(0.1, 0.2, -5), d, -kInfinity, kInfinity}},
        {"interval [-max, max]", Ray{Point3(0.1, 0.2, -5), d, -kHuge, kHuge}},
        {"interval [t, t] at the hit", Ray{Point3(0, 0, -5), Vector3(0, 0, 1), 4.0, 4.0}},
        // Valid (t_min <= t_max) but holding no finite t: no hit can be reported.
        {"interval [+inf, +inf]", Ray{Point3(0.1, 0.2, -5), d, kInfinity, kInfinity}, true},
        {"interval [-inf, -inf]", Ray{Point3(0.1, 0.2, -5), d, -kInfinity, -kInfinity}, true},
    };
    for (const NamedRay& named : rays) {
        EXPECT_TRUE(is_valid(named.ray)) << named.name;
    }
    return rays;
}

/// The registry, built once so that names can be looked up by shape.
const std::vector<test::ExampleShape>& registered() {
    static const std::vector<test::ExampleShape> list = test::example_shapes();
    return list;
}

/// Every registered example shape (support/example_shapes.h), then the octahedral sphere mesh
/// under every structure in float and double.
std::vector<std::shared_ptr<const Shape>> every_shape() {
    std::vector<std::shared_ptr<const Shape>> shapes;
    for (const test::ExampleShape& example : registered()) {
        shapes.push_back(example.shape);
    }
    const test::TestMesh octahedron = test::sphere_mesh(2);
    for (const std::string_view name : accelerator_names()) {
        for (const bool double_precision : {false, true}) {
            MeshConfig config;
            config.accelerator = std::string(name);
            config.double_precision = double_precision;
            shapes.push_back(std::make_shared<Mesh>(
                TriangleMeshData{octahedron.vertices, octahedron.triangles, {}}, config));
        }
    }
    return shapes;
}

std::string shape_name(const Shape& shape) {
    for (const test::ExampleShape& example : registered()) {
        if (example.shape.get() == &shape) return example.name;
    }
    if (const auto* mesh = dynamic_cast<const Mesh*>(&shape)) {
        return "mesh (" + mesh->accelerator_stats().name +
               (mesh->double_precision() ? ", double)" : ", float)");
    }
    return std::string(shape.kind());
}

TEST(InvalidRays, EveryShapeRejectsThemWithoutCrashingOrHanging) {
    const std::vector<NamedRay> invalid = invalid_rays();
    const std::vector<NamedRay> extreme = extreme_valid_rays();
    Watchdog watchdog(60);
    QueryScratch scratch;
    long queries = 0;
    for (const auto& shape : every_shape()) {
        const std::string name = shape_name(*shape);
        for (const NamedRay& named : invalid) {
            const std::string where = name + ", " + named.name;
            watchdog.at(where.c_str());
            // The public queries reject the ray.
            EXPECT_FALSE(shape->intersect(named.ray)) << where;
            EXPECT_FALSE(shape->occluded(named.ray)) << where;
            EXPECT_TRUE(shape->spans(named.ray).empty()) << where;
            // The raw queries are not asked to reject it, only to return (ASan and UBSan watch
            // them in the asan preset); a hit they report must still lie in the interval.
            HitRecord record;
            if (shape->nearest_hit(named.ray, record, scratch)) {
                EXPECT_TRUE(named.ray.in_range(record.t)) << where;
            }
            (void)shape->any_hit(named.ray, scratch);
            SpanList spans;
            shape->find_spans(named.ray, spans, scratch);
            (void)shape->contains(named.ray.origin);
            queries += 6;
        }
        for (const NamedRay& named : extreme) {
            const std::string where = name + ", " + named.name;
            watchdog.at(where.c_str());
            const std::optional<Hit> hit = shape->intersect(named.ray);
            if (hit) {
                EXPECT_TRUE(named.ray.in_range(hit->t)) << where;
                EXPECT_FALSE(named.never_hits) << where;
            }
            const bool occluded = shape->occluded(named.ray);
            if (named.never_hits) {
                EXPECT_FALSE(occluded) << where;
            }
            for (const Span& span : shape->spans(named.ray)) {
                EXPECT_FALSE(std::isnan(span.enter.t) || std::isnan(span.exit.t)) << where;
            }
            queries += 3;
        }
    }
    std::printf("  %ld queries on %zu invalid and %zu extreme rays\n", queries, invalid.size(),
                extreme.size());
    test::summarize("every shape: invalid and extreme rays", queries, test::failed_assertions());
}

TEST(InvalidRays, TinyAndHugeValidDirectionsGiveTheSameHitPoint) {
    // |d| = 2^-500 (about 3e-151) and 2^500 are valid (|d|^2 is a normal double). Scaling by a
    // power of two is exact, so the scaled ray names exactly the same points and the hit point
    // o + t d must be the unit direction's up to the rounding of a point: 8 u (|o| + |p|), a few
    // ulps of the coordinates. Rays from a box 4 sizes around each shape aim at random points
    // of the box rays aim into (example.target); candidates are drawn until 100 of them hit
    // with the unit direction (at most 200000), so thin shapes (a torus with r/R = 1e-3) are
    // compared as often as thick ones.
    test::Random random(17);
    long total = 0;
    for (const auto& shape : every_shape()) {
        const std::string name = shape_name(*shape);
        Aabb target = shape->bounds();
        for (const test::ExampleShape& example : registered()) {
            if (example.shape == shape) target = example.target;
        }
        const Point3 middle = target.center();
        const double size = std::max(1.0, (target.upper - target.lower).maxCoeff());
        const Aabb around(middle - Vector3::Constant(4 * size), middle + Vector3::Constant(4 * size));
        int compared = 0, reference_hits = 0;
        for (int i = 0; i < 200000 && reference_hits < 100; ++i) {
            const Point3 origin = random.in_box(around);
            const Vector3 direction = (random.in_box(target) - origin).normalized();
            const std::optional<Hit> reference = shape->intersect(Ray{origin, direction});
            if (reference) ++reference_hits;
            for (const double length : {0x1p-500, 0x1p500}) {
                const Ray scaled{origin, direction * length};
                const std::optional<Hit> hit = shape->intersect(scaled);
                ASSERT_EQ(hit.has_value(), reference.has_value())
                    << name << " length " << length << " ray " << i;
                if (!hit) continue;
                ++compared;
                const double tolerance =
                    8 * kUnitRoundoff * (origin.norm() + reference->point.norm());
                EXPECT_LE((hit->point - reference->point).norm(), tolerance)
                    << name << " length " << length << " ray " << i;
                EXPECT_EQ(hit->shape, reference->shape);
            }
        }
        // Each hit counts at both lengths: over 60 means at least 30 rays hit.
        EXPECT_GT(compared, 60) << name;
        total += compared;
    }
    test::summarize("every shape: direction length 2^-500 and 2^500 vs 1", total,
                    test::failed_assertions());
}

TEST(InvalidRays, EveryStructureRejectsThemOnEverySet) {
    // The structure contract (accel/accelerator.h, the accel brief): invalid rays never hit,
    // whatever the set, and never hang.
    const std::vector<NamedRay> invalid = invalid_rays();
    const test::TestMesh mesh = test::sphere_mesh(3);
    const TriangleSet<float> float_set(mesh.vertices, mesh.triangles);
    const TriangleSet<double> double_set(mesh.vertices, mesh.triangles);
    std::vector<std::shared_ptr<const Shape>> spheres;
    test::Random random(5);
    for (int i = 0; i < 200; ++i) {
        spheres.push_back(std::make_shared<Sphere>(
            random.in_box(Aabb(Point3(-2, -2, -2), Point3(2, 2, 2))), random.uniform(0.05, 0.5)));
    }
    const ShapeSet shape_set(spheres);
    Watchdog watchdog(60);
    QueryScratch scratch;
    auto check = [&](const auto& structure, const std::string& label) {
        for (const NamedRay& named : invalid) {
            const std::string where = label + ", " + named.name;
            watchdog.at(where.c_str());
            HitRecord record;
            TraversalCounters counters;
            std::vector<HitRecord> hits;
            EXPECT_FALSE(structure.intersect(named.ray, record, scratch)) << where;
            EXPECT_FALSE(structure.occluded(named.ray, scratch)) << where;
            EXPECT_FALSE(structure.intersect_counted(named.ray, record, scratch, counters))
                << where;
            EXPECT_FALSE(structure.occluded_counted(named.ray, scratch, counters)) << where;
            structure.all_hits(named.ray, hits, scratch);
            EXPECT_TRUE(hits.empty()) << where;
        }
    };
    for (const std::string_view name : accelerator_names()) {
        check(*make_accelerator(name, float_set), std::string(name) + " float");
        check(*make_accelerator(name, double_set), std::string(name) + " double");
        check(*make_accelerator(name, shape_set), std::string(name) + " shapes");
    }
    test::summarize("every structure: invalid rays",
                    static_cast<long>(5 * 3 * invalid.size() * accelerator_names().size()),
                    test::failed_assertions());
}

}  // namespace
}  // namespace csgrt
