// Rays that lie in the planes of a mesh's faces and along its edges: the case where CGAL's
// exact predicates say "hit" and the plane's t is 0 / 0. The independent answer is the
// geometry of the integer cube [0, n]^3: an axis-aligned ray in a face's plane, coming from
// outside, first touches the cube where it crosses the cube's boundary, at an integer distance.
// The reference must give that t exactly, and every structure, in float and double, must agree
// with the reference wherever it reports a hit.

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/reference/cgal_reference.h"
#include "csgrt/accel/factory.h"
#include "csgrt/accel/triangle_set.h"
#include "support/meshes.h"

namespace csgrt {
namespace {

constexpr int kCubeSize = 4;

/// An axis-aligned ray lying in a plane of the cube's faces or along its edges, and the exact
/// t at which it first touches the cube.
struct PlanarRay {
    Ray ray;
    double t;
    /// False for rays that start on a face they lie in: only the reference sees that hit (a
    /// ray in a triangle's plane has a zero determinant in the watertight test, which counts
    /// it as a miss, the usual convention), and structures report a later crossing.
    bool structures_see_it = true;
};

/// Rays along every axis, in both directions, from 3 units outside the cube, whose other two
/// coordinates are on the cube's boundary planes (0 or n) or inside its extent: along faces
/// (one coordinate on a plane, the other inside, on or between grid lines) and along edges
/// (both on planes). Plus, for t_min > 0 and finite t_max, the same rays as segments.
std::vector<PlanarRay> planar_rays() {
    std::vector<PlanarRay> rays;
    const double n = kCubeSize;
    const std::vector<double> across = {0.0, 0.5, 1.0, 1.75, n - 1.0, n};
    for (int axis = 0; axis < 3; ++axis) {
        for (const double sign : {1.0, -1.0}) {
            for (const double u : across) {
                for (const double v : across) {
                    const bool on_face = u == 0.0 || u == n || v == 0.0 || v == n;
                    if (!on_face) continue;  // through the inside: not in any face's plane
                    Point3 origin;
                    origin[axis] = sign > 0 ? -3.0 : n + 3.0;
                    origin[(axis + 1) % 3] = u;
                    origin[(axis + 2) % 3] = v;
                    Vector3 direction = Vector3::Zero();
                    direction[axis] = sign * 0.5;  // |d| = 1/2: t = distance / |d|
                    rays.push_back({Ray{origin, direction}, 6.0, true});
                    Ray segment{origin, direction, 2.0, 9.0};
                    rays.push_back({segment, 6.0, true});
                    // Starting on the face itself: the ray touches it at once.
                    Ray on{origin, direction, 8.0, kInfinity};
                    rays.push_back({on, 8.0, false});
                }
            }
        }
    }
    return rays;
}

template <class Real>
void check_structures(const char* precision) {
    const test::TestMesh cube = test::integer_cube(kCubeSize);
    const TriangleSet<Real> set(cube.vertices, cube.triangles);
    const CgalReference reference(set);
    const std::vector<PlanarRay> rays = planar_rays();
    QueryScratch scratch;
    long reference_wrong = 0;
    std::printf("\n  | %s structure | rays | hits | same t as the exact reference | misses |\n",
                precision);
    for (const PlanarRay& planar : rays) {
        const std::optional<CgalReference::Answer> exact = reference.nearest(planar.ray);
        ASSERT_TRUE(exact.has_value()) << planar.ray.origin.transpose();
        if (exact->t != planar.t) {
            ++reference_wrong;
            ADD_FAILURE() << "reference t " << exact->t << ", exact " << planar.t << " for o ("
                          << planar.ray.origin.transpose() << ") d ("
                          << planar.ray.direction.transpose() << ") [" << planar.ray.t_min << ", "
                          << planar.ray.t_max << "]";
        }
    }
    for (const std::string_view name : accelerator_names()) {
        const auto structure = make_accelerator(name, set);
        long hits = 0, agreeing = 0, misses = 0;
        for (const PlanarRay& planar : rays) {
            if (!planar.structures_see_it) continue;
            HitRecord record;
            if (!structure->intersect(planar.ray, record, scratch)) {
                // The ray touches the cube only on the boundary of the triangles it meets
                // head on (their edges): the watertight test's tie rule may give it to none.
                ++misses;
                continue;
            }
            ++hits;
            // Integer coordinates and axis-aligned rays: every product is exact, so is t.
            EXPECT_EQ(record.t, planar.t) << name << " o (" << planar.ray.origin.transpose()
                                          << ") d (" << planar.ray.direction.transpose() << ") ["
                                          << planar.ray.t_min << ", " << planar.ray.t_max << "]";
            if (record.t == planar.t) ++agreeing;
        }
        std::printf("  | %s | %ld | %ld | %ld | %ld |\n", std::string(name).c_str(), hits + misses,
                    hits, agreeing, misses);
        // Rays along faces (not edges) meet the perpendicular face inside one of its edges,
        // which exactly one of the two triangles there owns: most rays hit.
        EXPECT_GT(hits, misses) << name;
    }
    EXPECT_EQ(reference_wrong, 0);
}

TEST(InPlaneReference, RaysAlongFacesAndEdgesGetTheExactDistanceFloat) {
    check_structures<float>("float");
}

TEST(InPlaneReference, RaysAlongFacesAndEdgesGetTheExactDistanceDouble) {
    check_structures<double>("double");
}

TEST(InPlaneReference, AnInPlaneRayMissingTheTriangleIsNoHit) {
    // One triangle in z = 0; a ray in its plane passing beside it is not hit, and one through
    // it is hit where it enters (x = 1 - y on the hypotenuse).
    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
    const TriangleSet<double> set(vertices, triangles);
    const CgalReference reference(set);
    EXPECT_FALSE(reference.nearest(Ray{Point3(3, 2, 0), Vector3(-1, 0, 0)}).has_value());
    const auto through = reference.nearest(Ray{Point3(3, 0.25, 0), Vector3(-1, 0, 0)});
    ASSERT_TRUE(through.has_value());
    EXPECT_EQ(through->t, 2.25);
    // Out of the plane, the plane's t as before.
    const auto across = reference.nearest(Ray{Point3(0.25, 0.25, 2), Vector3(0, 0, -4)});
    ASSERT_TRUE(across.has_value());
    EXPECT_EQ(across->t, 0.5);
}

}  // namespace
}  // namespace csgrt
