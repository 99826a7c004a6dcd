// Degenerate geometry of every kind has a defined result: either the constructor refuses it
// with InvalidParameter (zero, negative or non-finite sizes, collinear corners, parallel edges,
// empty angle ranges, singular transforms, meshes with nothing left after validation), or the
// shape is accepted and every query on it returns a well-formed answer (t in the interval,
// finite point, unit normal, uv in [0, 1]^2, any_hit agreeing with nearest_hit, sorted spans),
// and where the answer is known (a ray aimed at the centre of a shape of radius 1e-300 or
// 1e300, A - A) it is that answer. Which way each case goes is fixed here, so a shape that
// starts accepting what it refused (or the reverse) fails the test.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/mesh/mesh.h"
#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "stress/summary.h"
#include "support/example_shapes.h"
#include "support/meshes.h"
#include "support/random.h"

namespace csgrt {
namespace {

/// The answers of `shape` for `ray` are well formed: occluded agrees with intersect; a hit
/// lies in the interval at a finite point with unit normals (1e-9 leaves room for a few
/// roundings of the normalisation, far below any real defect) and uv in [0, 1]^2; a solid's
/// spans are ordered and disjoint, and its membership test answers. Returns whether it hit.
bool expect_sane_answers(const Shape& shape, const Ray& ray, const std::string& where) {
    const std::optional<Hit> hit = shape.intersect(ray);
    EXPECT_EQ(shape.occluded(ray), hit.has_value()) << where;
    if (hit) {
        EXPECT_TRUE(ray.in_range(hit->t)) << where;
        EXPECT_TRUE(is_finite(hit->point)) << where;
        EXPECT_NEAR(hit->geometric_normal.norm(), 1.0, 1e-9) << where;
        EXPECT_NEAR(hit->shading_normal.norm(), 1.0, 1e-9) << where;
        EXPECT_TRUE(hit->uv.x() >= 0.0 && hit->uv.x() <= 1.0 && hit->uv.y() >= 0.0 &&
                    hit->uv.y() <= 1.0)
            << where;
    }
    if (shape.is_solid()) {
        const SpanList spans = shape.spans(ray);
        for (std::size_t k = 0; k < spans.size(); ++k) {
            EXPECT_LE(spans[k].enter.t, spans[k].exit.t) << where;
            if (k > 0) {
                EXPECT_LE(spans[k - 1].exit.t, spans[k].enter.t) << where;
            }
        }
        (void)shape.contains(ray.origin);
    }
    return hit.has_value();
}

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

using Make = std::function<std::shared_ptr<const Shape>()>;

struct RefusedCase {
    std::string name;
    Make make;
};

/// Degenerate input every constructor must refuse.
std::vector<RefusedCase> refused_cases() {
    auto unit_sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto mesh_of = [](std::vector<Eigen::Vector3d> vertices,
                      std::vector<std::array<std::uint32_t, 3>> triangles) {
        return [vertices, triangles]() -> std::shared_ptr<const Shape> {
            return std::make_shared<Mesh>(TriangleMeshData{vertices, triangles, {}});
        };
    };
    const Eigen::Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
    return {
        {"sphere radius 0", [] { return std::make_shared<Sphere>(Point3(0, 0, 0), 0.0); }},
        {"sphere radius -1", [] { return std::make_shared<Sphere>(Point3(0, 0, 0), -1.0); }},
        {"sphere radius NaN", [] { return std::make_shared<Sphere>(Point3(0, 0, 0), kNan); }},
        {"sphere radius inf", [] { return std::make_shared<Sphere>(Point3(0, 0, 0), kInfinity); }},
        {"sphere centre NaN", [] { return std::make_shared<Sphere>(Point3(kNan, 0, 0), 1.0); }},
        {"box flat in x", [] { return std::make_shared<Box>(Point3(0, 0, 0), Point3(0, 1, 1)); }},
        {"box inverted", [] { return std::make_shared<Box>(Point3(1, 1, 1), Point3(0, 0, 0)); }},
        {"box infinite",
         [] { return std::make_shared<Box>(Point3(0, 0, 0), Point3(kInfinity, 1, 1)); }},
        {"triangle collinear",
         [] {
             return std::make_shared<Triangle>(Point3(0, 0, 0), Point3(1, 1, 1), Point3(2, 2, 2));
         }},
        {"triangle one point",
         [] {
             return std::make_shared<Triangle>(Point3(1, 2, 3), Point3(1, 2, 3), Point3(1, 2, 3));
         }},
        {"triangle NaN corner",
         [] {
             return std::make_shared<Triangle>(Point3(0, 0, 0), Point3(1, 0, 0),
                                               Point3(0, kNan, 0));
         }},
        {"plane zero normal",
         [] { return std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 0, 0)); }},
        {"disk zero normal",
         [] { return std::make_shared<Disk>(Point3(0, 0, 0), Normal3(0, 0, 0), 1.0); }},
        {"disk radius 0",
         [] { return std::make_shared<Disk>(Point3(0, 0, 0), Normal3(0, 0, 1), 0.0); }},
        {"rectangle parallel edges",
         [] {
             return std::make_shared<Rectangle>(Point3(0, 0, 0), Vector3(1, 0, 0),
                                                Vector3(2, 0, 0));
         }},
        {"rectangle zero edge",
         [] {
             return std::make_shared<Rectangle>(Point3(0, 0, 0), Vector3(1, 0, 0),
                                                Vector3(0, 0, 0));
         }},
        {"annulus inner = outer",
         [] {
             return std::make_shared<Annulus>(Point3(0, 0, 0), Normal3(0, 0, 1), 1.0, 1.0, 0.0,
                                              kTwoPi);
         }},
        {"cylinder y_min = y_max", [] { return std::make_shared<Cylinder>(1.0, 1.0, 1.0, true); }},
        {"cylinder radius 0", [] { return std::make_shared<Cylinder>(0.0, -1.0, 1.0, true); }},
        {"cone both radii 0", [] { return std::make_shared<Cone>(0.0, 0.0, 1.0, true); }},
        {"cone height 0", [] { return std::make_shared<Cone>(1.0, 0.5, 0.0, true); }},
        {"torus minor = major", [] { return std::make_shared<Torus>(1.0, 1.0); }},
        {"torus minor 0", [] { return std::make_shared<Torus>(1.0, 0.0); }},
        {"part sphere theta_min = theta_max",
         [] { return std::make_shared<PartSphere>(Point3(0, 0, 0), 1.0, 0.0, kTwoPi, 1.0, 1.0); }},
        {"part sphere empty azimuth",
         [] { return std::make_shared<PartSphere>(Point3(0, 0, 0), 1.0, 2.0, 2.0, 0.0, kPi); }},
        {"part cylinder azimuth over 2 pi",
         [] { return std::make_shared<PartCylinder>(1.0, -1.0, 1.0, 0.0, 7.0); }},
        {"instance of nothing",
         [] { return std::make_shared<Instance>(nullptr, Transform::scale(2.0)); }},
        {"instance scaled by 0 on one axis",
         [unit_sphere] {
             return std::make_shared<Instance>(unit_sphere, Transform::scale(Vector3(1, 0, 1)));
         }},
        {"instance with a rank-2 matrix",
         [unit_sphere] {
             Eigen::Matrix3d linear;
             linear << 1, 0, 0, 0, 1, 0, 1, 1, 0;
             return std::make_shared<Instance>(unit_sphere, Transform(linear, Vector3::Zero()));
         }},
        {"instance with conditioning 1e-14",
         [unit_sphere] {
             Eigen::Matrix3d linear;
             linear << 1, 0, 1, 0, 1, 1, 0, 0, 1e-14;
             return std::make_shared<Instance>(unit_sphere, Transform(linear, Vector3::Zero()));
         }},
        {"mesh with no triangle", mesh_of({o, x, y}, {})},
        {"mesh of zero-area triangles only", mesh_of({o, x, 2 * x}, {{0, 1, 2}, {0, 0, 1}})},
        {"mesh index out of range", mesh_of({o, x, y}, {{0, 1, 3}})},
        {"mesh NaN vertex", mesh_of({o, x, Eigen::Vector3d(0, kNan, 0)}, {{0, 1, 2}})},
        {"mesh infinite vertex", mesh_of({o, x, Eigen::Vector3d(0, kInfinity, 0)}, {{0, 1, 2}})},
    };
}

TEST(DegenerateGeometry, ConstructorsRefuseIt) {
    for (const RefusedCase& refused : refused_cases()) {
        EXPECT_THROW((void)refused.make(), InvalidParameter) << refused.name;
    }
    test::summarize("degenerate input refused", static_cast<long>(refused_cases().size()),
                    test::failed_assertions());
}

struct AcceptedCase {
    std::string name;
    std::shared_ptr<const Shape> shape;
    /// Where random rays start and aim: around the shape's interesting part.
    Aabb region;
    /// A point that rays from outside `region` aimed at it must hit (NaN: no such promise),
    /// and whether the shape must never be hit at all.
    Point3 must_hit = Point3::Constant(kNan);
    bool never_hit = false;
};

std::vector<AcceptedCase> accepted_cases() {
    const Aabb unit(Point3(-1, -1, -1), Point3(1, 1, 1));
    auto around = [](double size) { return Aabb(Point3::Constant(-size), Point3::Constant(size)); };
    auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto box = std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1));
    std::shared_ptr<const Shape> nested = sphere;
    for (int level = 0; level < 40; ++level) {
        nested = std::make_shared<Instance>(
            nested, Transform::rotate(Vector3(1, 1 + level, 2), 0.3) * Transform::scale(1.01));
    }
    // Half of the triangles of this mesh are degenerate (a repeated corner, three collinear
    // corners, a sliver 1e-300 wide); validation drops those, the rest is a closed octahedron.
    test::TestMesh octahedron = test::sphere_mesh(0);
    const auto base = static_cast<std::uint32_t>(octahedron.vertices.size());
    octahedron.vertices.push_back({0.5, 0.5, 0});
    octahedron.vertices.push_back({0.5, 0.5 + 1e-300, 0});
    octahedron.triangles.push_back({0, 0, 2});
    octahedron.triangles.push_back({0, 1, base});
    octahedron.triangles.push_back({0, base, base + 1});
    test::TestMesh doubled = test::sphere_mesh(1);
    const std::size_t count = doubled.triangles.size();
    for (std::size_t i = 0; i < count; ++i) doubled.triangles.push_back(doubled.triangles[i]);
    return {
        {"sphere radius 1e-300", std::make_shared<Sphere>(Point3(0, 0, 0), 1e-300), around(1e-300),
         Point3(0, 0, 0)},
        {"sphere radius 1e300", std::make_shared<Sphere>(Point3(0, 0, 0), 1e300), around(1e300),
         Point3(0, 0, 0)},
        {"sphere radius 1e-8 at 1e8", std::make_shared<Sphere>(Point3(1e8, 0, 0), 1e-8),
         Aabb(Point3(1e8 - 1e-8, -1e-8, -1e-8), Point3(1e8 + 1e-8, 1e-8, 1e-8)), Point3(1e8, 0, 0)},
        {"box 1e-300 thick", std::make_shared<Box>(Point3(-1, -1e-300, -1), Point3(1, 1e-300, 1)),
         unit, Point3(0, 0, 0)},
        {"triangle 1e-300 wide",
         std::make_shared<Triangle>(Point3(0, 0, 0), Point3(1, 0, 0), Point3(0.5, 1e-300, 0)),
         unit},
        {"triangle at 1e300",
         std::make_shared<Triangle>(Point3(1e300, 0, 0), Point3(-1e300, 1e300, 0),
                                    Point3(0, -1e300, 1e300)),
         around(1e300)},
        {"disk radius 1e-300", std::make_shared<Disk>(Point3(0, 0, 0), Normal3(0, 1, 0), 1e-300),
         around(1e-300)},
        {"rectangle edges 1e300 and 1e-300",
         std::make_shared<Rectangle>(Point3(0, 0, 0), Vector3(1e300, 0, 0), Vector3(0, 1e-300, 0)),
         unit},
        {"cylinder 1e-9 tall", std::make_shared<Cylinder>(1.0, 0.0, 1e-9, true), unit},
        {"cone with equal radii", std::make_shared<Cone>(1.0, 1.0, 2.0, true), around(2),
         Point3(0, 1, 0)},
        {"cone radius 1e-300", std::make_shared<Cone>(1e-300, 0.0, 1.0, true), unit},
        {"torus minor 1e-12", std::make_shared<Torus>(1.0, 1e-12), around(1.5)},
        {"torus major 1e300", std::make_shared<Torus>(1e300, 1.0), around(1e300)},
        {"part sphere sliver 1e-12 wide",
         std::make_shared<PartSphere>(Point3(0, 0, 0), 1.0, 1.0, 1.0 + 1e-12, 0.0, kPi), unit},
        {"part torus sliver", std::make_shared<PartTorus>(1.0, 0.25, 1.0, 1.0 + 1e-12, 0.0, kTwoPi),
         around(1.5)},
        {"instance scaled by 1e-100", std::make_shared<Instance>(sphere, Transform::scale(1e-100)),
         around(1e-100), Point3(0, 0, 0)},
        {"instance flattened to 1e-14 in z",
         std::make_shared<Instance>(sphere, Transform::scale(Vector3(1, 1, 1e-14))), unit,
         Point3(0, 0, 0)},
        {"part sphere radius 1e-300",
         std::make_shared<PartSphere>(Point3(0, 0, 0), 1e-300, 0.0, kTwoPi, 0.0, kPi),
         around(1e-300), Point3(0, 0, 0)},
        {"part sphere radius 1e300",
         std::make_shared<PartSphere>(Point3(0, 0, 0), 1e300, 0.0, kTwoPi, 0.0, kPi), around(1e300),
         Point3(0, 0, 0)},
        {"cylinder radius 1e-300", std::make_shared<Cylinder>(1e-300, -1e-300, 1e-300, true),
         around(1e-300), Point3(0, 0, 0)},
        // Radius 1e300: rays from 1e301 square their coordinates past the largest double, so
        // the cylinder and the disk promise well-formed answers only, not hits (docs/accuracy.md:
        // the working range is coordinates below 2^500).
        {"cylinder radius 1e300", std::make_shared<Cylinder>(1e300, -1e300, 1e300, true),
         around(1e300)},
        {"part cylinder radius 1e-300",
         std::make_shared<PartCylinder>(1e-300, -1e-300, 1e-300, 0.0, kTwoPi), around(1e-300)},
        {"cone radius 1e300", std::make_shared<Cone>(1e300, 0.0, 1e300, true), around(1e300),
         Point3(0, 1e299, 0)},
        {"disk radius 1e300", std::make_shared<Disk>(Point3(0, 0, 0), Normal3(0, 1, 0), 1e300),
         around(1e300)},
        {"annulus radii 1e-300",
         std::make_shared<Annulus>(Point3(0, 0, 0), Normal3(0, 1, 0), 0.5e-300, 1e-300, 0.0,
                                   kTwoPi),
         around(1e-300)},
        {"box 1e300", std::make_shared<Box>(Point3::Constant(-1e300), Point3::Constant(1e300)),
         around(1e300), Point3(0, 0, 0)},
        {"instance 40 deep", nested, around(2), Point3(0, 0, 0)},
        {"box minus itself", std::make_shared<Boolean>(BooleanOperation::Difference, box, box),
         around(2), Point3::Constant(kNan), true},
        {"sphere intersect itself",
         std::make_shared<Boolean>(BooleanOperation::Intersection, sphere, sphere), around(2),
         Point3(0, 0, 0)},
        {"box union itself", std::make_shared<Boolean>(BooleanOperation::Union, box, box),
         around(2), Point3(0, 0, 0)},
        {"disjoint intersection",
         std::make_shared<Boolean>(
             BooleanOperation::Intersection, sphere,
             std::make_shared<Instance>(sphere, Transform::translate(Vector3(3, 0, 0)))),
         around(4), Point3::Constant(kNan), true},
        {"mesh with degenerate triangles",
         std::make_shared<Mesh>(TriangleMeshData{octahedron.vertices, octahedron.triangles, {}}),
         around(1.5), Point3(0, 0, 0)},
        {"mesh with every triangle twice",
         std::make_shared<Mesh>(TriangleMeshData{doubled.vertices, doubled.triangles, {}}),
         around(1.5), Point3(0, 0, 0)},
        {"mesh of one triangle",
         std::make_shared<Mesh>(
             TriangleMeshData{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}, {}}),
         unit},
    };
}

TEST(DegenerateGeometry, AcceptedShapesAnswerEveryQueryWellFormed) {
    test::Random random(23);
    QueryScratch scratch;
    long queries = 0;
    for (const AcceptedCase& accepted : accepted_cases()) {
        const Shape& shape = *accepted.shape;
        const Aabb from = test::enlarged(accepted.region, 2.0);
        int hits = 0;
        for (int i = 0; i < 2000; ++i) {
            const Ray ray = random.ray_between(from, accepted.region);
            hits += expect_sane_answers(shape, ray, accepted.name + ", ray " + std::to_string(i));
            queries += 3;
        }
        if (accepted.never_hit) {
            EXPECT_EQ(hits, 0) << accepted.name;
        }
        if (!std::isnan(accepted.must_hit.x())) {
            // Rays from 26 directions around the region, aimed at the point, all hit. Unit
            // directions: at 1e-300, |d|^2 of the offset would underflow (an invalid ray).
            // 8 times the region's largest extent (norm() would overflow at 1e300).
            const double reach = 8.0 * accepted.region.diagonal().cwiseAbs().maxCoeff();
            for (int dx = -1; dx <= 1; ++dx) {
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dz = -1; dz <= 1; ++dz) {
                        if (dx == 0 && dy == 0 && dz == 0) continue;
                        const Vector3 unit = Vector3(dx, dy, dz).normalized();
                        const Ray aimed{accepted.must_hit + unit * reach, -unit};
                        EXPECT_TRUE(shape.intersect(aimed).has_value())
                            << accepted.name << " from " << dx << ", " << dy << ", " << dz;
                        ++queries;
                    }
                }
            }
        }
    }
    std::printf("  %zu accepted degenerate shapes, %ld queries\n", accepted_cases().size(),
                queries);
    test::summarize("degenerate shapes accepted and queried", queries, test::failed_assertions());
}

TEST(DegenerateGeometry, EveryRegisteredKindAtExtremeSizesAnswersWellFormed) {
    // Every kind of the registry (support/example_shapes.h) built by its own parameters at
    // sizes 1e-300, 1e-150, 1e150 and 1e300 around the origin: a constructor may refuse a size
    // (InvalidParameter, a defined answer), otherwise every query is well formed as above (t in
    // the interval, finite point, unit normals, uv in [0, 1], ordered spans, occluded equal to
    // intersect). The unit directions of random.ray_between keep |d|^2 a normal double.
    test::Random random(29);
    long queries = 0, refused = 0, hits = 0;
    for (const test::ExampleKind& kind : test::example_kinds()) {
        for (const double size : {1e-300, 1e-150, 1e150, 1e300}) {
            std::shared_ptr<const Shape> shape;
            Point3 placed;
            try {
                shape = kind.make(Point3(0, 0, 0), size, placed).first;
            } catch (const InvalidParameter&) {
                ++refused;
                continue;
            }
            const Aabb region(Point3::Constant(-size), Point3::Constant(size));
            const Aabb from = test::enlarged(region, 2.0);
            for (int i = 0; i < 300; ++i) {
                const Ray ray = random.ray_between(from, region);
                hits += expect_sane_answers(
                    *shape, ray,
                    kind.name + " size " + std::to_string(size) + ", ray " + std::to_string(i));
                queries += 3;
            }
        }
    }
    std::printf("  registry kinds at extreme sizes: %ld queries, %ld hits, %ld sizes refused\n",
                queries, hits, refused);
    // The rays aim into the region the shapes fill: far more than a few must hit.
    EXPECT_GT(hits, queries / 100);
    test::summarize("registry kinds at sizes 1e-300 to 1e300", queries,
                    test::failed_assertions());
}

}  // namespace
}  // namespace csgrt
