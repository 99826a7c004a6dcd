// CSG under stress: coincident faces, nearly tangent operands and deep trees (depth 20, with
// instanced subtrees nested as deep), at scene scales from 1e-4 to 1e6. The answers are
// checked against exact expectations where the geometry makes them exact (a solid minus
// itself is empty; boxes tiling a box are that box, hit for hit), and otherwise against point
// membership classification computed in long double from the leaves' own descriptions
// (tests/stress/reference_shapes.h), with the rules of docs/csg.md.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/mesh/mesh.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "stress/reference_shapes.h"
#include "stress/stress_config.h"
#include "stress/summary.h"
#include "support/membership.h"
#include "support/meshes.h"
#include "support/random.h"

namespace csgrt {
namespace {

using test::Long;
using test::LongMatrix;
using test::LongVector;
using ShapePointer = std::shared_ptr<const Shape>;

constexpr double kScales[] = {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6};

/// A placement at `scale`: rotated, scaled and moved 3 sizes away from the world origin.
Transform placement_at(double scale) {
    return Transform::translate(scale * Vector3(3.0, -2.0, 5.0)) *
           Transform::rotate(Vector3(1, 2, 3), 0.7) * Transform::scale(scale);
}

std::vector<std::pair<std::string, ShapePointer>> unit_solids() {
    auto unit_sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    TriangleMeshData octahedron{test::sphere_mesh(3).vertices, test::sphere_mesh(3).triangles, {}};
    return {
        {"sphere", unit_sphere},
        {"box", std::make_shared<Box>(Point3(-1, -0.5, -0.75), Point3(1, 0.5, 0.75))},
        {"cylinder", std::make_shared<Cylinder>(1.0, -1.0, 1.0, true)},
        {"cone", std::make_shared<Cone>(1.0, 0.0, 2.0, true)},
        {"frustum", std::make_shared<Cone>(1.0, 0.3, 1.0, true)},
        {"torus", std::make_shared<Torus>(1.0, 0.25)},
        {"ellipsoid",
         std::make_shared<Instance>(unit_sphere, Transform::scale(Vector3(1.5, 0.5, 1.0)))},
        {"sphere_mesh(3)", std::make_shared<Mesh>(octahedron)},
    };
}

TEST(CsgStress, CoincidentOperandsAtEveryScale) {
    // A - A is empty for every ray (no speckle); A u A and A n A are A hit for hit, with the
    // first operand's records (docs/csg.md, "Coincident and touching surfaces").
    test::Random random(401);
    const int rays = 4000 * test::stress_multiplier();
    std::printf(
        "\n  | solid | rays over 6 scales | hits of A | hits of A - A | A u A, A n A differing "
        "|\n");
    for (const auto& [name, unit] : unit_solids()) {
        long total = 0, hits = 0, speckles = 0, different = 0;
        for (const double scale : kScales) {
            const ShapePointer a = std::make_shared<Instance>(unit, placement_at(scale));
            const Boolean minus(BooleanOperation::Difference, a, a);
            const Boolean both(BooleanOperation::Union, a, a);
            const Boolean common(BooleanOperation::Intersection, a, a);
            for (int i = 0; i < rays; ++i) {
                const Ray ray = test::ray_toward(random, a->bounds(), i);
                ++total;
                const std::optional<Hit> hit = a->intersect(ray);
                hits += hit ? 1 : 0;
                if (minus.intersect(ray) || minus.occluded(ray) || !minus.spans(ray).empty()) {
                    ++speckles;
                    if (speckles <= 3) ADD_FAILURE() << name << " - itself hit at scale " << scale;
                }
                for (const Boolean* same : {&both, &common}) {
                    const std::optional<Hit> other = same->intersect(ray);
                    const bool equal = other.has_value() == hit.has_value() &&
                                       (!hit || (other->t == hit->t && other->shape == hit->shape &&
                                                 other->primitive_id == hit->primitive_id &&
                                                 other->geometric_normal == hit->geometric_normal));
                    if (!equal) {
                        ++different;
                        if (different <= 3) {
                            ADD_FAILURE() << name << " " << same->kind()
                                          << " itself differs at scale " << scale;
                        }
                    }
                }
            }
        }
        std::printf("  | %s | %ld | %ld | %ld | %ld |\n", name.c_str(), total, hits, speckles,
                    different);
        EXPECT_GT(hits, total / 5) << name;
        test::summarize(name + " with itself", total, speckles + different);
    }
}

TEST(CsgStress, BoxesTilingABoxAreThatBox) {
    // A 3 x 3 x 3 grid of boxes sharing faces, united (balanced by make_union), is the big box:
    // the same hit (t bit for bit, the outer face's normal) for every ray, and never a hit on
    // an internal face, even for rays that start inside and run along the internal planes.
    // Slab distances (plane - o) / d are the same expressions in the small boxes and the big
    // one, so equality is exact. The big box minus its upper layer is its lower two layers,
    // exactly (the cut is the subtracted boxes' bottom face, the same plane).
    test::Random random(402);
    const int rays = 20000 * test::stress_multiplier();
    for (const double scale : kScales) {
        // The grid planes, computed once, so neighbours share their faces' coordinates exactly.
        Point3 planes[4];
        for (int i = 0; i < 4; ++i) {
            planes[i] = scale * (Point3(1.0, -2.0, 3.0) + i * Vector3(0.5, 0.25, 1.0));
        }
        auto corner = [&](int i, int j, int k) {
            return Point3(planes[i].x(), planes[j].y(), planes[k].z());
        };
        std::vector<ShapePointer> cells, top_layer;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                for (int k = 0; k < 3; ++k) {
                    cells.push_back(
                        std::make_shared<Box>(corner(i, j, k), corner(i + 1, j + 1, k + 1)));
                    if (j == 2) top_layer.push_back(cells.back());
                }
            }
        }
        const ShapePointer tiled = make_union(cells);
        const Box whole(corner(0, 0, 0), corner(3, 3, 3));
        const ShapePointer cut =
            make_difference(std::make_shared<Box>(corner(0, 0, 0), corner(3, 3, 3)), top_layer);
        const Box bottom(corner(0, 0, 0), corner(3, 2, 3));
        long hits = 0, along_planes = 0;
        for (int i = 0; i < rays; ++i) {
            Ray ray = test::ray_toward(random, whole.bounds(), i);
            if (i % 8 == 1) {
                // Along an internal plane: origin on the plane x = planes[1].x, direction in it.
                ray.origin.x() = planes[1].x();
                ray.direction.x() = 0.0;
                ++along_planes;
            }
            for (const auto& [solid, expected] :
                 {std::pair<const Shape*, const Shape*>{tiled.get(), &whole},
                  std::pair<const Shape*, const Shape*>{cut.get(), &bottom}}) {
                const std::optional<Hit> want = expected->intersect(ray);
                const std::optional<Hit> got = solid->intersect(ray);
                ASSERT_EQ(got.has_value(), want.has_value())
                    << "scale " << scale << " ray " << i << " " << solid->kind();
                if (!got) continue;
                ++hits;
                ASSERT_EQ(got->t, want->t) << "scale " << scale << " ray " << i;
                EXPECT_EQ(got->geometric_normal, want->geometric_normal)
                    << "scale " << scale << " ray " << i;
            }
        }
        EXPECT_GT(hits, rays / 2);
        EXPECT_GT(along_planes, rays / 10);
    }
    test::summarize("27 boxes tiling a box, and the box cut",
                    2L * rays * static_cast<long>(std::size(kScales)), test::failed_assertions());
}

TEST(CsgStress, ThinShellsAndGapsAroundTheCoincidenceTolerance) {
    // A sphere of radius (1 + e) minus the unit sphere is a shell of thickness e. Rays from
    // outside hit its outer surface whatever e; rays from the centre hit the inner wall (the
    // subtracted surface, flipped) when e is far above the coincidence tolerance 256 u (|t| +
    // |o| / |d|) of docs/csg.md, and may see nothing of a shell far thinner (it vanishes,
    // as documented, and then from outside too: both entries fall in one group). The unit
    // sphere minus the larger one is empty for every e >= 0.
    test::Random random(403);
    std::printf("\n  | scale | e | rays from the centre seeing the inner wall | from outside |\n");
    for (const double scale : {1e-4, 1.0, 1e6}) {
        const Vector3 center = scale * Vector3(3.0, -2.0, 5.0);
        for (const double e : {1e-6, 1e-9, 1e-12, 1e-14, 1e-15, 0.0}) {
            auto inner = std::make_shared<Sphere>(center, scale);
            auto outer = std::make_shared<Sphere>(center, scale * (1 + e));
            const Boolean shell(BooleanOperation::Difference, outer, inner);
            const Boolean nothing(BooleanOperation::Difference, inner, outer);
            int inner_walls = 0, outer_hits = 0;
            const int rays = 1000;
            for (int i = 0; i < rays; ++i) {
                const Vector3 direction = random.unit_vector() * random.uniform(0.25, 4.0);
                const Ray from_center{center, direction};
                const Ray from_outside{center - 3 * scale * direction.normalized(), direction};
                EXPECT_FALSE(nothing.intersect(from_center) || nothing.intersect(from_outside))
                    << "e " << e;
                const std::optional<Hit> out = shell.intersect(from_outside);
                if (e >= 1e-12) {
                    ASSERT_TRUE(out) << "e " << e << " scale " << scale;
                }
                if (e == 0.0) {
                    EXPECT_FALSE(out);  // A - A
                }
                if (out) {
                    EXPECT_EQ(out->shape, outer.get());
                    ++outer_hits;
                }
                const std::optional<Hit> in = shell.intersect(from_center);
                if (in && in->shape == inner.get()) {
                    // The subtracted wall faces into the cavity, toward the ray.
                    ++inner_walls;
                    EXPECT_TRUE(in->front_face);
                    EXPECT_LT(in->geometric_normal.dot(direction), 0.0);
                }
            }
            std::printf("  | %g | %g | %d | %d |\n", scale, e, inner_walls, outer_hits);
            // 256 u (|t| + |o| / |d|) with |t d| = r, |o| = 6.2 r: about 2e-13 r.
            if (e >= 1e-12) {
                EXPECT_EQ(inner_walls, rays) << "e " << e;
            }
            if (e == 0.0) {
                EXPECT_EQ(inner_walls + outer_hits, 0);
            }
        }
    }
    // 3 scales x 6 thicknesses x 1000 rays, each from the centre and from outside.
    test::summarize("thin shells around the coincidence tolerance", 3L * 6 * 1000 * 2,
                    test::failed_assertions());
}

// ----- Point membership classification in long double ---------------------------------------

/// A leaf of the model: a unit solid in its own space, placed by a long double affine map.
struct ModelLeaf {
    const Shape* surface = nullptr;  // the library leaf a hit on it must name
    std::shared_ptr<const test::ReferenceShape> reference;  // object space
    std::function<bool(const LongVector&)> inside;          // object space, open set
    LongMatrix linear = LongMatrix::Identity();             // world_from_object
    LongVector translation = LongVector::Zero();
};

struct ModelNode {
    int leaf = -1;  // >= 0: a leaf; otherwise an operation on two nodes
    BooleanOperation operation = BooleanOperation::Union;
    int first = -1, second = -1;
};

struct Model {
    std::vector<ModelLeaf> leaves;
    std::vector<ModelNode> nodes;
    int root = -1;

    bool contains(int index, const LongVector& p) const {
        const ModelNode& node = nodes[index];
        if (node.leaf >= 0) {
            const ModelLeaf& leaf = leaves[node.leaf];
            return leaf.inside(leaf.linear.inverse() * (p - leaf.translation));
        }
        const bool a = contains(node.first, p), b = contains(node.second, p);
        return test::combine_membership(node.operation, a, b);
    }
    bool contains(const LongVector& p) const { return contains(root, p); }
};

struct Event {
    Long t;
    const Shape* surface;
};

/// Every kept crossing of the ray's line with every leaf, sorted; false when one is ambiguous
/// (within `band` of a trim or a tangency: an edge, a rim, a near touch).
bool leaf_events(const Model& model, const Ray& ray, Long band, std::vector<Event>& events) {
    events.clear();
    const test::LongRay world = test::to_long(ray);
    for (const ModelLeaf& leaf : model.leaves) {
        const LongMatrix inverse = leaf.linear.inverse();
        const test::LongRay local{inverse * (world.origin - leaf.translation),
                                  inverse * world.direction};
        test::LineCrossings line;
        leaf.reference->crossings(local, line);
        // Object-space distances are turned into world ones by the largest stretch.
        const Long stretch = leaf.linear.norm();
        for (const test::Crossing& crossing : line.crossings) {
            if (std::abs(crossing.trim_distance) * stretch <= band) return false;
            if (crossing.trim_distance >= 0) events.push_back({crossing.t, leaf.surface});
        }
        for (const test::NearTangency& tangency : line.tangencies) {
            if (tangency.distance * stretch <= band && tangency.trim_distance >= -1e-6L) {
                return false;
            }
        }
    }
    std::sort(events.begin(), events.end(),
              [](const Event& a, const Event& b) { return a.t < b.t; });
    return true;
}

ModelLeaf leaf_model(const std::string& kind, const Shape* surface) {
    ModelLeaf leaf;
    leaf.surface = surface;
    if (kind == "sphere") {
        leaf.reference = test::reference_sphere(Point3(0, 0, 0), 1.0);
        leaf.inside = [](const LongVector& p) { return p.squaredNorm() < 1; };
    } else if (kind == "box") {
        leaf.reference = test::reference_box(Point3(-1, -1, -1), Point3(1, 1, 1));
        leaf.inside = [](const LongVector& p) { return p.cwiseAbs().maxCoeff() < 1; };
    } else {
        leaf.reference = test::reference_cylinder(1.0, -1.0, 1.0, true);
        leaf.inside = [](const LongVector& p) {
            return p.x() * p.x() + p.z() * p.z() < 1 && std::abs(p.y()) < 1;
        };
    }
    return leaf;
}

/// A chain of `depth` operations, R_{k+1} = op(R_k, leaf_k), over unit spheres, boxes and
/// capped cylinders placed at random near the first; every `instance_every` levels the chain
/// so far is wrapped in an Instance (a small random rotation and shift), so instances nest up
/// to depth / instance_every deep. The model folds each instance into its leaves' maps.
ShapePointer deep_chain(test::Random& random, int depth, int instance_every, Model& model) {
    auto new_leaf = [&](double spread, double size) {
        // A shape of its own per leaf, so a hit's leaf pointer says which leaf it is.
        const int kind = random.integer(0, 2);
        const ShapePointer unit =
            kind == 0   ? ShapePointer(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0))
            : kind == 1 ? ShapePointer(std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1)))
                        : ShapePointer(std::make_shared<Cylinder>(1.0, -1.0, 1.0, true));
        const Transform placement =
            Transform::translate(random.unit_vector() * random.uniform(0.0, spread)) *
            Transform::rotate(random.unit_vector(), random.uniform(0.0, kTwoPi)) *
            Transform::scale(Vector3(random.uniform(0.5, 1.0), random.uniform(0.5, 1.0),
                                     random.uniform(0.5, 1.0)) *
                             size);
        ModelLeaf leaf = leaf_model(kind == 0   ? "sphere"
                                    : kind == 1 ? "box"
                                                : "cylinder",
                                    unit.get());
        leaf.linear = placement.linear().cast<Long>();
        leaf.translation = placement.translation().cast<Long>();
        model.leaves.push_back(leaf);
        model.nodes.push_back({static_cast<int>(model.leaves.size()) - 1});
        return std::pair<ShapePointer, int>(std::make_shared<Instance>(unit, placement),
                                            static_cast<int>(model.nodes.size()) - 1);
    };
    auto [chain, node] = new_leaf(0.0, 1.5);
    for (int level = 0; level < depth; ++level) {
        // Mostly unions and differences (intersections of many random solids are empty), the
        // intersecting operand large enough to keep something.
        const double pick = random.uniform();
        const BooleanOperation operation = pick < 0.55  ? BooleanOperation::Union
                                           : pick < 0.9 ? BooleanOperation::Difference
                                                        : BooleanOperation::Intersection;
        const bool intersect = operation == BooleanOperation::Intersection;
        auto [leaf, leaf_node] = new_leaf(intersect ? 0.3 : 1.2, intersect ? 2.5 : 0.7);
        chain = std::make_shared<Boolean>(operation, chain, leaf);
        model.nodes.push_back({-1, operation, node, leaf_node});
        node = static_cast<int>(model.nodes.size()) - 1;
        if ((level + 1) % instance_every == 0) {
            const Transform wrap = Transform::translate(random.unit_vector() * 0.05) *
                                   Transform::rotate(random.unit_vector(), random.uniform(0, 0.3));
            chain = std::make_shared<Instance>(chain, wrap);
            const LongMatrix linear = wrap.linear().cast<Long>();
            const LongVector translation = wrap.translation().cast<Long>();
            for (ModelLeaf& leaf : model.leaves) {
                leaf.translation = linear * leaf.translation + translation;
                leaf.linear = linear * leaf.linear;
            }
        }
    }
    model.root = node;
    return chain;
}

TEST(CsgStress, DeepTreesAgreeWithPointMembership) {
    // Chains of 20 operations (depth 20) with instanced subtrees nested up to 20 deep, placed
    // at every scale by one more instance. For each ray the reference first boundary is the
    // first leaf crossing where the model's membership changes; the hit must be that crossing
    // of that leaf, and the spans must agree with membership between their ends. Rays with
    // events closer than 1e-9 sizes (to each other, to an edge, to a tangency) depend on
    // rounding and are skipped; double is good to ~1e-15 here, so a hit more than 1e-9 sizes
    // from the reference is on a wrong surface.
    test::Random random(404);
    const int trees = 12, rays = 1500 * test::stress_multiplier();
    long total = 0, judged = 0, hits = 0, skipped = 0, span_checks = 0;
    std::vector<Event> events;
    for (int tree = 0; tree < trees; ++tree) {
        Model model;
        const ShapePointer chain = deep_chain(random, 20, tree % 2 ? 1 : 4, model);
        const double scale = kScales[tree % 6];
        const Transform world = placement_at(scale);
        const ShapePointer solid = std::make_shared<Instance>(chain, world);
        const LongMatrix linear = world.linear().cast<Long>();
        const LongVector translation = world.translation().cast<Long>();
        for (ModelLeaf& leaf : model.leaves) {
            leaf.translation = linear * leaf.translation + translation;
            leaf.linear = linear * leaf.linear;
        }
        const Aabb box = solid->bounds();
        ASSERT_FALSE(box.is_empty());
        const Long band = 1e-9L * scale;
        for (int i = 0; i < rays; ++i) {
            Ray ray = test::ray_toward(random, box, i);
            if (i % 2) {
                // Toward a leaf's centre: the box of a long chain is mostly empty.
                const ModelLeaf& leaf = model.leaves[i / 2 % model.leaves.size()];
                const Point3 target = leaf.translation.cast<double>();
                ray.direction = (target - ray.origin) * random.uniform(0.25, 4.0);
            }
            ++total;
            const test::LongRay line = test::to_long(ray);
            if (!leaf_events(model, ray, band, events)) {
                ++skipped;
                continue;
            }
            const Long length = line.direction.norm();
            bool close = false;
            for (std::size_t k = 0; k < events.size(); ++k) {
                if (std::abs(events[k].t) * length <= band) close = true;
                if (k > 0 && (events[k].t - events[k - 1].t) * length <= band) close = true;
            }
            if (close) {
                ++skipped;
                continue;
            }
            ++judged;
            auto inside_at = [&](Long t) { return model.contains(line.at(t)); };
            const Event* expected = nullptr;
            for (std::size_t k = 0; k < events.size() && !expected; ++k) {
                if (events[k].t < 0) continue;
                const Long before = k > 0 ? (events[k - 1].t + events[k].t) / 2 : events[k].t - 1;
                const Long after =
                    k + 1 < events.size() ? (events[k].t + events[k + 1].t) / 2 : events[k].t + 1;
                if (inside_at(before) != inside_at(after)) {
                    expected = &events[k];
                }
            }
            const std::optional<Hit> hit = solid->intersect(ray);
            SCOPED_TRACE(::testing::Message()
                         << "tree " << tree << " scale " << scale << " ray " << i);
            ASSERT_EQ(hit.has_value(), expected != nullptr);
            EXPECT_EQ(solid->occluded(ray), hit.has_value());
            if (hit) {
                ++hits;
                EXPECT_LE(std::abs(hit->t - expected->t) * length, band);
                EXPECT_EQ(hit->shape, expected->surface) << "the hit names the wrong leaf";
            }
            // Spans against membership, at the middle of every stretch between span ends.
            std::vector<Long> ends{0};
            std::vector<bool> inside;
            const SpanList spans = solid->spans(ray);
            for (const Span& span : spans) {
                for (const double t : {span.enter.t, span.exit.t}) {
                    if (std::isfinite(t) && t > 0) ends.push_back(t);
                }
            }
            std::sort(ends.begin(), ends.end());
            ends.push_back(ends.back() + 1);
            for (std::size_t k = 1; k < ends.size(); ++k) {
                const Long middle = (ends[k - 1] + ends[k]) / 2;
                bool in_span = false;
                for (const Span& span : spans)
                    in_span |= middle > span.enter.t && middle < span.exit.t;
                ++span_checks;
                EXPECT_EQ(in_span, inside_at(middle)) << "stretch " << k;
            }
        }
    }
    std::printf("  deep trees: %ld rays, %ld judged, %ld hits, %ld skipped, %ld span stretches\n",
                total, judged, hits, skipped, span_checks);
    EXPECT_GT(hits, judged / 5);
    EXPECT_LT(skipped, total / 20);
    test::summarize("depth-20 trees vs membership", judged, test::failed_assertions());
}

TEST(CsgStress, NearlyTangentSpheres) {
    // Two spheres of radius 1 (placed by instances at each scale) whose centres are 2 + g
    // apart, g from -1e-3 (overlapping) through 0 (touching) to 1e-3 (apart); union,
    // intersection and both differences; rays aimed at the contact region. Judged by point
    // membership as above; rays whose events come within 1e-9 sizes of each other are skipped.
    test::Random random(405);
    const auto unit_a = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    const auto unit_b = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    long judged = 0, skipped = 0;
    std::vector<Event> events;
    for (const double scale : kScales) {
        for (const double gap : {-1e-3, -1e-9, -1e-13, 0.0, 1e-13, 1e-9, 1e-3}) {
            const Transform world = placement_at(scale);
            const Transform left = world * Transform::translate(Vector3(-1 - gap / 2, 0, 0));
            const Transform right = world * Transform::translate(Vector3(1 + gap / 2, 0, 0));
            const ShapePointer a = std::make_shared<Instance>(unit_a, left);
            const ShapePointer b = std::make_shared<Instance>(unit_b, right);
            for (const BooleanOperation operation :
                 {BooleanOperation::Union, BooleanOperation::Intersection,
                  BooleanOperation::Difference}) {
                for (const bool swapped : {false, true}) {
                    const Boolean solid(operation, swapped ? b : a, swapped ? a : b);
                    Model model;
                    for (const bool first : {true, false}) {
                        const bool is_b = first == swapped;
                        const Transform* placement = is_b ? &right : &left;
                        ModelLeaf leaf = leaf_model("sphere", is_b ? unit_b.get() : unit_a.get());
                        leaf.linear = placement->linear().cast<Long>();
                        leaf.translation = placement->translation().cast<Long>();
                        model.leaves.push_back(leaf);
                        model.nodes.push_back({static_cast<int>(model.leaves.size()) - 1});
                    }
                    model.nodes.push_back({-1, operation, 0, 1});
                    model.root = 2;
                    const Point3 contact = world.apply_point(Point3(0, 0, 0));
                    const Long band = 1e-9L * scale;
                    for (int i = 0; i < 300; ++i) {
                        Ray ray;
                        ray.origin = contact + 3 * scale * random.unit_vector();
                        const Point3 target = contact + scale *
                                                            std::pow(10.0, random.uniform(-7, 0)) *
                                                            random.unit_vector();
                        ray.direction = (target - ray.origin) * random.uniform(0.25, 4.0);
                        const test::LongRay line = test::to_long(ray);
                        bool ambiguous = !leaf_events(model, ray, band, events);
                        const Long length = line.direction.norm();
                        for (std::size_t k = 0; k < events.size() && !ambiguous; ++k) {
                            ambiguous |= k > 0 && (events[k].t - events[k - 1].t) * length <= band;
                        }
                        if (ambiguous) {
                            ++skipped;
                            continue;
                        }
                        ++judged;
                        const Event* expected = nullptr;
                        for (std::size_t k = 0; k < events.size() && !expected; ++k) {
                            if (events[k].t < 0) continue;
                            const Long before =
                                k > 0 ? (events[k - 1].t + events[k].t) / 2 : events[k].t - 1;
                            const Long after = k + 1 < events.size()
                                                   ? (events[k].t + events[k + 1].t) / 2
                                                   : events[k].t + 1;
                            if (model.contains(line.at(before)) != model.contains(line.at(after)))
                                expected = &events[k];
                        }
                        const std::optional<Hit> hit = solid.intersect(ray);
                        ASSERT_EQ(hit.has_value(), expected != nullptr)
                            << solid.kind() << " gap " << gap << " scale " << scale << " ray " << i;
                        if (!hit) continue;
                        EXPECT_LE(std::abs(hit->t - expected->t) * length, band);
                        EXPECT_EQ(hit->shape, expected->surface);
                    }
                }
            }
        }
    }
    std::printf("  nearly tangent spheres: %ld rays judged, %ld skipped\n", judged, skipped);
    // Rays aimed within 1e-7 sizes of the contact point are often ambiguous by design.
    EXPECT_GT(judged, 3 * skipped);
    test::summarize("nearly tangent spheres vs membership", judged, test::failed_assertions());
}

}  // namespace
}  // namespace csgrt
