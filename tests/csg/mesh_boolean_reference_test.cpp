// Closed meshes in booleans, against CGAL's exact mesh booleans (issue 16, item 3): meshes with
// analytic solids and with other meshes, by difference, intersection and union, with touching
// and coincident faces and a mesh cutting an instance. CGAL corefines the operands exactly
// (reference/cgal_mesh_boolean.h) and its AABB tree casts every ray at the result
// (CgalReference, exact predicates); csgrt's Boolean casts the same rays at its own operands.
//
// Operands CGAL cannot take as they are (an analytic sphere) are tessellated twice, once inside
// the solid and once around it, so the true result lies between the two CGAL results (every
// operation is monotone in each operand, the subtracted one reversed): a ray from outside them
// must miss when it misses the outer result, must hit when it hits the inner one, and its first
// hit lies between the two first hits. That bracket is the tessellation error, bounded by
// construction rather than estimated. Boxes and meshes are their own tessellation (one result).
//
// A disagreement is a hit/miss or t outside the bracket widened by the operands' precision
// (kDoubleSpanCoincidence or kFloatSpanCoincidence of the coordinates) that persists when the
// ray is moved sideways by that precision: such a ray is no edge, tangent or coincident-face
// case, where both answers are right. CSGRT_DEBUG_JUDGE=1 prints every disagreeing ray.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/box.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/span_combine.h"
#include "csgrt/mesh/mesh.h"
#include "csgrt/reference/cgal_mesh_boolean.h"
#include "csgrt/reference/cgal_reference.h"
#include "support/meshes.h"
#include "support/random.h"
#include "support/rays.h"

namespace csgrt {
namespace {

constexpr BooleanOperation kDifference = BooleanOperation::Difference;
constexpr BooleanOperation kIntersection = BooleanOperation::Intersection;
constexpr BooleanOperation kUnion = BooleanOperation::Union;

/// One operand as csgrt sees it and as CGAL sees it: `inner` lies inside the solid and `outer`
/// around it (the same mesh when the tessellation is exact).
struct Operand {
    std::shared_ptr<const Shape> shape;
    TriangleMeshData inner;
    TriangleMeshData outer;
    bool holds_float = false;
    /// True when inner and outer differ (an analytic surface CGAL cannot take as it is).
    bool tessellated = false;
};

TriangleMeshData to_data(const test::TestMesh& mesh) {
    TriangleMeshData data;
    data.vertices = mesh.vertices;
    data.triangles = mesh.triangles;
    return data;
}

/// integer_cube(1) mapped onto [lower, upper]: each coordinate is lower's or upper's, exactly.
TriangleMeshData cube_data(const Point3& lower, const Point3& upper) {
    TriangleMeshData data = to_data(test::integer_cube(1));
    for (Eigen::Vector3d& p : data.vertices) {
        for (int axis = 0; axis < 3; ++axis) p[axis] = p[axis] == 0.0 ? lower[axis] : upper[axis];
    }
    return data;
}

/// sphere_mesh(levels) scaled to `radius` about `center`.
TriangleMeshData sphere_data(const Point3& center, double radius, int levels) {
    TriangleMeshData data = to_data(test::sphere_mesh(levels));
    for (Eigen::Vector3d& p : data.vertices) p = center + radius * p;
    return data;
}

/// A Mesh operand: CGAL gets the corners the Mesh stores (float-rounded by default), in the
/// orientation validation gave them.
Operand mesh_operand(const TriangleMeshData& data, bool double_precision = false) {
    MeshConfig config;
    config.double_precision = double_precision;
    auto mesh = std::make_shared<const Mesh>(data, config);
    EXPECT_TRUE(mesh->is_solid());
    TriangleMeshData stored;
    stored.vertices.resize(data.vertices.size());
    for (std::size_t i = 0; i < mesh->triangle_count(); ++i) {
        for (int k = 0; k < 3; ++k) stored.vertices[mesh->triangle(i)[k]] = mesh->corner(i, k);
        stored.triangles.push_back(mesh->triangle(i));
    }
    return Operand{mesh, stored, stored, !double_precision, false};
}

/// A Box operand: its 12 triangles are exact.
Operand box_operand(const Point3& lower, const Point3& upper) {
    const TriangleMeshData data = cube_data(lower, upper);
    return Operand{std::make_shared<const Box>(lower, upper), data, data, false, false};
}

/// An analytic sphere between two tessellations: the subdivided octahedron's vertices on a
/// sphere slightly smaller (inside), and the same polyhedron scaled until its nearest face
/// plane is slightly beyond the radius (around). The 2^-40 margins cover the rounding of the
/// vertices (a few ulps).
Operand sphere_operand(const Point3& center, double radius, int levels) {
    const test::TestMesh unit = test::sphere_mesh(levels);
    long double nearest_plane = 1.0L;
    for (const auto& [a, b, c] : unit.triangles) {
        using Long = Eigen::Matrix<long double, 3, 1>;
        const Long pa = unit.vertices[a].cast<long double>();
        const Long normal = (unit.vertices[b].cast<long double>() - pa)
                                .cross(unit.vertices[c].cast<long double>() - pa)
                                .normalized();
        nearest_plane = std::min(nearest_plane, std::abs(normal.dot(pa)));
    }
    const double shrink = 1.0 - 0x1.0p-40;
    const double grow = static_cast<double>(1.0L / nearest_plane) * (1.0 + 0x1.0p-40);
    Operand operand;
    operand.shape = std::make_shared<const Sphere>(center, radius);
    operand.inner = sphere_data(center, radius * shrink, levels);
    operand.outer = sphere_data(center, radius * grow, levels);
    operand.tessellated = true;
    return operand;
}

/// `operand` under `world_from_object`: CGAL gets the mapped vertices (rounded to double, a few
/// ulps, far inside the precision band).
Operand instance_operand(const Operand& operand, const Transform& world_from_object) {
    Operand result = operand;
    result.shape = std::make_shared<const Instance>(operand.shape, world_from_object);
    for (TriangleMeshData* data : {&result.inner, &result.outer}) {
        for (Eigen::Vector3d& p : data->vertices) p = world_from_object.apply_point(p);
        // A reflection would turn the mesh inside out; the cases use none.
    }
    return result;
}

/// CGAL's answer for one ray: the first hits on the inner and the outer result.
struct ReferenceAnswer {
    std::optional<double> inner;
    std::optional<double> outer;
};

/// The reference results of one case, with their AABB trees.
class ReferenceResult {
public:
    ReferenceResult(BooleanOperation operation, const Operand& first, const Operand& second) {
        // Monotone: union and intersection grow with both operands, a difference with the
        // first and against the second.
        const bool reversed = operation == kDifference;
        inner_data_ =
            cgal_mesh_boolean(operation, first.inner, reversed ? second.outer : second.inner);
        inner_ = make_tree(inner_data_);
        if (!first.tessellated && !second.tessellated) {
            outer_data_ = inner_data_;
            outer_ = inner_;
            return;
        }
        outer_data_ =
            cgal_mesh_boolean(operation, first.outer, reversed ? second.inner : second.outer);
        outer_ = make_tree(outer_data_);
    }

    ReferenceAnswer answer(const Ray& ray) const {
        ReferenceAnswer answer;
        if (inner_) {
            if (auto hit = inner_->nearest(ray)) answer.inner = hit->t;
        }
        if (outer_) {
            if (auto hit = outer_->nearest(ray)) answer.outer = hit->t;
        }
        return answer;
    }
    /// How far `point` lies from the nearer of the two results' surfaces.
    double distance(const Point3& point) const {
        double nearest = kInfinity;
        for (const auto* tree : {inner_.get(), outer_.get()}) {
            if (tree != nullptr) nearest = std::min(nearest, tree->distance(point));
        }
        return nearest;
    }
    std::size_t inner_triangles() const { return inner_data_.triangles.size(); }
    std::size_t outer_triangles() const { return outer_data_.triangles.size(); }

private:
    static std::shared_ptr<CgalReference> make_tree(const TriangleMeshData& data) {
        if (data.triangles.empty()) return nullptr;
        return std::make_shared<CgalReference>(TriangleSet<double>(data.vertices, data.triangles));
    }

    TriangleMeshData inner_data_;
    TriangleMeshData outer_data_;
    std::shared_ptr<CgalReference> inner_;
    std::shared_ptr<CgalReference> outer_;
};

/// What the judge counts for one case.
struct Tally {
    int rays = 0;
    int reference_hits = 0;  // rays hitting the inner result
    int csgrt_hits = 0;
    int tessellation_band = 0;  // rays hitting the outer result only (no verdict on hit)
    int ambiguous = 0;          // the reference's answer changes within the precision
    int operand_edges = 0;      // csgrt's answer changes there, and only on the exact ray
    int hit_miss_disagreements = 0;
    int t_disagreements = 0;
    double max_t_error = 0.0;  // of agreeing hits, beyond the bracket, relative to the size
    int disagreements() const { return hit_miss_disagreements + t_disagreements; }
};

/// The first hit csgrt reports for a ray, as a function so that the controls can swap in
/// another evaluation.
using CsgrtFirstHit = std::function<std::optional<double>(const Ray&)>;

/// Unit vectors perpendicular to `direction` and to each other.
std::array<Vector3, 2> sideways(const Vector3& direction) {
    const Vector3 d = direction.normalized();
    const Vector3 helper = std::abs(d.x()) < 0.6 ? Vector3::UnitX() : Vector3::UnitY();
    const Vector3 first = d.cross(helper).normalized();
    return {first, d.cross(first)};
}

Tally judge(const ReferenceResult& reference, const std::vector<Ray>& rays,
            const CsgrtFirstHit& csgrt, double relative, double size) {
    Tally tally;
    for (const Ray& ray : rays) {
        ++tally.rays;
        const ReferenceAnswer answer = reference.answer(ray);
        const std::optional<double> hit = csgrt(ray);
        tally.reference_hits += answer.inner.has_value();
        tally.csgrt_hits += hit.has_value();
        if (answer.outer && !answer.inner) ++tally.tessellation_band;
        const double origin_over_direction =
            ray.origin.cwiseAbs().maxCoeff() / ray.direction.cwiseAbs().maxCoeff();
        auto precision = [&](double t) { return relative * (std::abs(t) + origin_over_direction); };
        // The bracket [outer t, inner t] widened by the precision; a miss is t = infinity.
        auto within = [&](const ReferenceAnswer& a, double t) {
            if (!a.outer) return false;
            const double upper = a.inner ? *a.inner + precision(*a.inner) : kInfinity;
            return t >= *a.outer - precision(*a.outer) && t <= upper;
        };
        // csgrt's answer against one reference answer: a miss where the inner result is
        // missed, a hit where the outer result is hit, within the bracket.
        auto agrees = [&](const ReferenceAnswer& a, const std::optional<double>& t) {
            return t ? a.outer.has_value() && within(a, *t) : !a.inner.has_value();
        };
        if (agrees(answer, hit)) {
            if (hit) {
                const double below = *answer.outer - *hit;
                const double above = answer.inner ? *hit - *answer.inner : 0.0;
                tally.max_t_error = std::max(
                    tally.max_t_error, std::max({below, above, 0.0}) * ray.direction.norm() / size);
            }
            continue;
        }
        // Moved sideways by twice the precision at the answers' distance, along two
        // perpendicular axes and their diagonals. If a moved ray's reference answer accepts
        // csgrt's, the ray passes within the precision of an edge of the result. If the moved
        // rays' reference answers are hits and misses both, the ray grazes the result (along a
        // face, an edge or a silhouette): a miss is right, and so is a hit on the result's
        // surface no earlier than its first contact. If instead csgrt answers every moved ray as
        // the reference does, its own answer changes there: the ray runs within the precision
        // of an operand's edge or face that the result does not have (exactly along the edge
        // where a box and a float cube meet). Each is in the ambiguity band; a disagreement
        // persists on moved rays.
        const double t_scale = hit ? *hit : answer.outer.value_or(0.0);
        const double shift = precision(t_scale) * ray.direction.cwiseAbs().maxCoeff() * 2.0;
        // At angles off the axes, so that a ray in an axis-aligned face plane leaves it.
        const auto [e1, e2] = sideways(ray.direction);
        bool near_result_edge = false;
        bool moved_agree = true;
        bool moved_hit = answer.outer.has_value(), moved_miss = !answer.inner.has_value();
        double first_contact = answer.outer.value_or(kInfinity);
        for (int k = 0; k < 8; ++k) {
            const double angle = 0.3 + k * kPi / 4.0;
            const Vector3 offset = std::cos(angle) * e1 + std::sin(angle) * e2;
            Ray moved = ray;
            moved.origin += shift * offset;
            const ReferenceAnswer other = reference.answer(moved);
            if (agrees(other, hit)) {
                near_result_edge = true;
                break;
            }
            moved_agree = moved_agree && agrees(other, csgrt(moved));
            moved_hit = moved_hit || other.outer.has_value();
            moved_miss = moved_miss || !other.inner.has_value();
            if (other.outer) first_contact = std::min(first_contact, *other.outer);
        }
        if (!near_result_edge && moved_hit && moved_miss) {
            near_result_edge = !hit || (*hit >= first_contact - precision(first_contact) &&
                                        reference.distance(ray.at(*hit)) <=
                                            precision(*hit) * ray.direction.cwiseAbs().maxCoeff());
        }
        if (std::getenv("CSGRT_DEBUG_JUDGE") && !near_result_edge && !moved_agree) {
            const Vector3 d = ray.direction.normalized();
            std::printf("  o (%.17g %.17g %.17g) d (%.6f %.6f %.6f) csgrt %.17g ref %.17g/%.17g\n",
                        ray.origin.x(), ray.origin.y(), ray.origin.z(), d.x(), d.y(), d.z(),
                        hit.value_or(-1.0), answer.inner.value_or(-1.0),
                        answer.outer.value_or(-1.0));
        }
        if (near_result_edge) {
            ++tally.ambiguous;
        } else if (moved_agree) {
            ++tally.operand_edges;
        } else if (hit.has_value() != answer.outer.has_value() || !hit) {
            ++tally.hit_miss_disagreements;
        } else {
            ++tally.t_disagreements;
        }
    }
    return tally;
}

/// The operands' vertex coordinates along each axis, sorted, without repeats.
test::AxisCoordinates vertex_coordinates(const Operand& first, const Operand& second) {
    std::vector<Eigen::Vector3d> points = first.inner.vertices;
    points.insert(points.end(), second.inner.vertices.begin(), second.inner.vertices.end());
    return test::axis_coordinates(points);
}

/// Camera-like rays at the case's box, and axis-parallel rays: a third at random, a third in a
/// plane through operand vertices (along faces), a third on a line through them (along edges).
std::vector<Ray> case_rays(const Aabb& box, const test::AxisCoordinates& coordinates, int camera,
                           int axis_rays, std::uint64_t seed) {
    std::vector<Ray> rays;
    test::Random random(seed);
    const double size = box.diagonal().norm();
    for (int i = 0; i < camera; ++i) {
        const Point3 eye = box.center() + random.unit_vector() * size * random.uniform(1.0, 2.0);
        const Point3 target = random.in_box(box);
        rays.push_back(Ray{eye, (target - eye) / size});
    }
    test::append_rays_along_faces_and_edges(random, box, coordinates, axis_rays, rays);
    return rays;
}

struct Case {
    std::string name;
    BooleanOperation operation;
    Operand first;
    Operand second;
};

const char* operation_name(BooleanOperation operation) {
    switch (operation) {
        case kDifference:
            return "-";
        case kIntersection:
            return "&";
        case kUnion:
            return "|";
    }
    return "?";
}

constexpr int kCameraRays = 1500;
constexpr int kAxisRays = 600;

/// Judges one case with csgrt's Boolean (or `evaluate` when given) and prints its row.
Tally run_case(const Case& c, const ReferenceResult& reference,
               const CsgrtFirstHit& evaluate = {}) {
    const Boolean boolean(c.operation, c.first.shape, c.second.shape);
    Aabb box = join(c.first.shape->bounds(), c.second.shape->bounds());
    const double size = box.diagonal().norm();
    const std::vector<Ray> rays =
        case_rays(box, vertex_coordinates(c.first, c.second), kCameraRays, kAxisRays, 1601);
    const double relative = c.first.holds_float || c.second.holds_float ? kFloatSpanCoincidence
                                                                        : kDoubleSpanCoincidence;
    CsgrtFirstHit csgrt = evaluate;
    if (!csgrt) {
        csgrt = [&](const Ray& ray) -> std::optional<double> {
            if (auto hit = boolean.intersect(ray)) return hit->t;
            return std::nullopt;
        };
    }
    const Tally tally = judge(reference, rays, csgrt, relative, size);
    std::printf("%-50s %5d %5d %5d %4d %4d %4d %3d %3d %9.2e  (%zu/%zu triangles)\n",
                c.name.c_str(), tally.rays, tally.reference_hits, tally.csgrt_hits,
                tally.tessellation_band, tally.ambiguous, tally.operand_edges,
                tally.hit_miss_disagreements, tally.t_disagreements, tally.max_t_error,
                reference.inner_triangles(), reference.outer_triangles());
    return tally;
}

void print_header() {
    std::printf("%-50s %5s %5s %5s %4s %4s %4s %3s %3s %9s\n", "case", "rays", "ref", "csgrt",
                "band", "amb", "edge", "h/m", "t", "t error");
}

// The operands (dyadic coordinates where faces are meant to coincide: exact in float and
// double alike, so the float mesh's face is the box's face).
Operand float_cube(const Point3& lower, const Point3& upper) {
    return mesh_operand(cube_data(lower, upper));
}
Operand float_sphere() {
    return mesh_operand(sphere_data({0.5, 0.5, 0.5}, 0.7, 2));
}

std::vector<Case> mesh_cases() {
    std::vector<Case> cases;
    const Operand sphere_mesh = float_sphere();
    const Operand box = box_operand({0.2, 0.0, 0.3}, {1.4, 1.0, 0.9});
    for (BooleanOperation op : {kDifference, kIntersection, kUnion}) {
        cases.push_back({std::string("float sphere mesh ") + operation_name(op) + " box", op,
                         sphere_mesh, box});
        cases.push_back({std::string("box ") + operation_name(op) + " float sphere mesh", op, box,
                         sphere_mesh});
    }
    const Operand unit_cube = float_cube({0, 0, 0}, {1, 1, 1});
    const Operand half_box = box_operand({0.5, 0, 0}, {1, 1, 1});
    for (BooleanOperation op : {kDifference, kIntersection, kUnion}) {
        cases.push_back(
            {std::string("float cube ") + operation_name(op) + " box, 5 coincident faces", op,
             unit_cube, half_box});
    }
    cases.push_back({"box - float cube, 5 coincident faces", kDifference,
                     box_operand({0, 0, 0}, {1, 1, 1}), float_cube({0.5, 0, 0}, {1, 1, 1})});
    cases.push_back({"box - float cube, a pocket (1 coincident face)", kDifference,
                     box_operand({0, 0, 0}, {1, 1, 1}),
                     float_cube({0.25, 0.25, 0.5}, {0.75, 0.75, 1})});
    const Operand touching = box_operand({1, 0, 0}, {2, 1, 1});
    for (BooleanOperation op : {kDifference, kIntersection, kUnion}) {
        cases.push_back({std::string("float cube ") + operation_name(op) + " touching box", op,
                         unit_cube, touching});
    }
    const Operand cube = float_cube({0.25, -0.5, 0.25}, {1.5, 0.75, 0.75});
    for (BooleanOperation op : {kDifference, kIntersection, kUnion}) {
        cases.push_back({std::string("float sphere mesh ") + operation_name(op) + " float cube", op,
                         sphere_mesh, cube});
    }
    cases.push_back({"double sphere mesh - float cube", kDifference,
                     mesh_operand(sphere_data({0.5, 0.5, 0.5}, 0.7, 2), true), cube});
    cases.push_back({"float cube - float cube, 4 coincident faces", kDifference, unit_cube,
                     float_cube({0.5, 0, 0}, {1.5, 1, 1})});
    const Transform turned = Transform::translate({0.5, 0.5, 0.5}) *
                             Transform::rotate({1, 2, 3}, 0.7) * Transform::scale({1, 0.5, 1.25});
    cases.push_back({"instance(box, rotated, scaled) - float sphere mesh", kDifference,
                     instance_operand(box_operand({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}), turned),
                     sphere_mesh});
    cases.push_back({"float sphere mesh - instance(float cube, rotated)", kDifference, sphere_mesh,
                     instance_operand(float_cube({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}), turned)});
    cases.push_back(
        {"instance(float cube, sheared) & box", kIntersection,
         instance_operand(float_cube({0, 0, 0}, {1, 1, 1}), Transform::shear(0, 1, 0.5)),
         box_operand({0.25, 0.25, -0.5}, {1.25, 0.75, 0.5})});
    const Vector3 far{1024, -2048, 512};
    cases.push_back({"box - float cube at (1024, -2048, 512)", kDifference,
                     box_operand(far + Vector3(0, 0, 0), far + Vector3(1, 1, 1)),
                     float_cube(far + Vector3(0.5, 0, 0), far + Vector3(1, 1, 1))});
    return cases;
}

TEST(MeshBooleanReference, MeshesAndBoxesAgreeWithCgalsExactBooleans) {
    print_header();
    for (const Case& c : mesh_cases()) {
        const ReferenceResult reference(c.operation, c.first, c.second);
        const Tally tally = run_case(c, reference);
        EXPECT_EQ(tally.disagreements(), 0) << c.name;
        // Most rays must be decided, or the check says nothing.
        EXPECT_LT(tally.ambiguous + tally.operand_edges, tally.rays / 10) << c.name;
    }
}

TEST(MeshBooleanReference, AnAnalyticSphereLiesBetweenItsTessellations) {
    print_header();
    const Operand sphere = sphere_operand({0.5, 0.5, 0.5}, 0.7, 3);
    const Operand cube = float_cube({0.25, -0.5, 0.25}, {1.5, 0.75, 0.75});
    for (BooleanOperation op : {kDifference, kIntersection, kUnion}) {
        for (const Case& c :
             {Case{std::string("sphere ") + operation_name(op) + " float cube", op, sphere, cube},
              Case{std::string("float cube ") + operation_name(op) + " sphere", op, cube,
                   sphere}}) {
            const ReferenceResult reference(c.operation, c.first, c.second);
            const Tally tally = run_case(c, reference);
            EXPECT_EQ(tally.disagreements(), 0) << c.name;
            EXPECT_LT(tally.tessellation_band, tally.rays / 10) << c.name;
        }
    }
}

// The controls: the judge must see a wrong answer. Judged against the reference of another
// operation, csgrt disagrees on many rays; and the sliver that a float face on a box face
// left with the double coincidence tolerance shows as disagreements.
TEST(MeshBooleanReference, TheJudgeCatchesAWrongOperationAndTheDoubleToleranceSliver) {
    print_header();
    const Case wrong{"control: float cube - box judged as union", kDifference,
                     float_cube({0, 0, 0}, {1, 1, 1}), box_operand({0.5, 0.25, 0.25}, {1.5, 1, 1})};
    const ReferenceResult union_reference(kUnion, wrong.first, wrong.second);
    EXPECT_GT(run_case(wrong, union_reference).disagreements(), 100);

    // The same evaluation as Boolean's (the operands' spans, combined), with the coincidence
    // tolerance as a parameter: from double's 256 ulps up through float's, printed per size,
    // at the origin and 2^11 away (where float's ulp is 2^11 times larger).
    const Vector3 far{1024, -2048, 512};
    for (const Vector3& offset : {Vector3(0, 0, 0), far}) {
        const Case sliver{"box - float cube, 5 coincident faces", kDifference,
                          box_operand(offset, offset + Vector3(1, 1, 1)),
                          float_cube(offset + Vector3(0.5, 0, 0), offset + Vector3(1, 1, 1))};
        const ReferenceResult reference(sliver.operation, sliver.first, sliver.second);
        auto combined_with = [&](double relative) {
            return [&, relative](const Ray& ray) -> std::optional<double> {
                HitRecord record;
                if (!first_combined_boundary(kDifference, sliver.first.shape->spans(ray),
                                             sliver.second.shape->spans(ray), ray, record,
                                             relative))
                    return std::nullopt;
                return record.t;
            };
        };
        std::printf("spans combined with a tolerance of (offset %g):\n", offset.x());
        std::printf("  double's 256 ulps (2^-45): ");
        const Tally double_sized =
            run_case(sliver, reference, combined_with(kDoubleSpanCoincidence));
        EXPECT_GT(double_sized.disagreements(), 10);
        for (int ulps = 1; ulps <= 256; ulps *= 2) {
            std::printf("  %3d float ulps: ", ulps);
            const Tally tally = run_case(sliver, reference, combined_with(ulps * 0x1.0p-24));
            if (ulps * 0x1.0p-24 == kFloatSpanCoincidence) {
                EXPECT_EQ(tally.disagreements(), 0);
            }
        }
    }
}

}  // namespace
}  // namespace csgrt
