#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <new>

#include "csgrt/core/instance.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "support/membership.h"
#include "support/random.h"

// Counts operator new calls on this thread while `counting` is set, to show that queries on a
// warmed-up QueryScratch do not allocate. Replacing the global operators is per program; these
// only count and forward to malloc/free.
namespace {
thread_local bool counting = false;
thread_local long allocations = 0;

void* counted_allocation(std::size_t size) {
    if (counting) ++allocations;
    if (void* memory = std::malloc(size == 0 ? 1 : size)) return memory;
    throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) {
    return counted_allocation(size);
}
void* operator new[](std::size_t size) {
    return counted_allocation(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    try {
        return counted_allocation(size);
    } catch (...) {
        return nullptr;
    }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
    try {
        return counted_allocation(size);
    } catch (...) {
        return nullptr;
    }
}
void operator delete(void* memory) noexcept {
    std::free(memory);
}
void operator delete[](void* memory) noexcept {
    std::free(memory);
}
void operator delete(void* memory, std::size_t) noexcept {
    std::free(memory);
}
void operator delete[](void* memory, std::size_t) noexcept {
    std::free(memory);
}

namespace csgrt {
namespace {

using Real = long double;
using RealVector = Eigen::Matrix<Real, 3, 1>;
using RealMatrix = Eigen::Matrix<Real, 3, 3>;

// The independent model of a random CSG tree: every leaf is the unit ball in its own space,
// placed by the product of the transforms on its path (its own and those of instanced
// subtrees). Membership and the leaves' crossings with a ray are computed here in long double
// from the matrices, without the library's shapes.
struct ModelNode {
    bool leaf = true;
    BooleanOperation operation = BooleanOperation::Union;
    int first = -1, second = -1;
    // world_from_node for this node's space relative to its parent's (identity if none).
    RealMatrix linear = RealMatrix::Identity();
    RealMatrix inverse_linear = RealMatrix::Identity();
    RealVector translation = RealVector::Zero();
    const Shape* surface = nullptr;  // the library leaf a hit on this ball must name
};

struct Model {
    std::vector<ModelNode> nodes;
    int root = -1;

    bool contains(int index, const RealVector& p) const {
        const ModelNode& node = nodes[index];
        const RealVector local = node.inverse_linear * (p - node.translation);
        if (node.leaf) return local.squaredNorm() < 1;
        const bool a = contains(node.first, local), b = contains(node.second, local);
        return test::combine_membership(node.operation, a, b);
    }
    bool contains(const RealVector& p) const { return contains(root, p); }
};

struct Crossing {
    Real t;
    const Shape* surface;
};

Transform random_placement(test::Random& random, double spread) {
    return Transform::translate(Vector3(random.uniform(-spread, spread),
                                        random.uniform(-spread, spread),
                                        random.uniform(-spread, spread))) *
           Transform::rotate(random.unit_vector(), random.uniform(0, kTwoPi)) *
           Transform::scale(Vector3(random.uniform(0.4, 1.4), random.uniform(0.4, 1.4),
                                    random.uniform(0.4, 1.4)));
}

void set_transform(ModelNode& node, const Transform& transform) {
    node.linear = transform.linear().cast<Real>();
    node.inverse_linear = node.linear.inverse();
    node.translation = transform.translation().cast<Real>();
}

// Builds a random tree of depth <= max_depth and its model: leaves are plain spheres, instanced
// unit spheres (ellipsoids) or doubly instanced ones; now and then a whole subtree is instanced.
std::shared_ptr<const Shape> random_tree(test::Random& random, Model& model, int depth,
                                         int max_depth, int& index) {
    index = static_cast<int>(model.nodes.size());
    model.nodes.emplace_back();
    if (depth == max_depth || random.uniform() < 0.25) {
        const int kind = random.integer(0, 2);
        if (kind == 0) {
            const Point3 center(random.uniform(-1.5, 1.5), random.uniform(-1.5, 1.5),
                                random.uniform(-1.5, 1.5));
            const double radius = random.uniform(0.4, 1.5);
            auto ball = std::make_shared<Sphere>(center, radius);
            set_transform(model.nodes[index],
                          Transform::translate(center) * Transform::scale(radius));
            model.nodes[index].surface = ball.get();
            return ball;
        }
        auto unit = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
        model.nodes[index].surface = unit.get();
        Transform placement = random_placement(random, 1.5);
        std::shared_ptr<const Shape> shape = std::make_shared<Instance>(unit, placement);
        if (kind == 2) {
            const Transform outer = Transform::translate(random.unit_vector() * 0.3) *
                                    Transform::rotate(random.unit_vector(), random.uniform(0, 1));
            shape = std::make_shared<Instance>(shape, outer);
            placement = outer * placement;
        }
        set_transform(model.nodes[index], placement);
        return shape;
    }
    const auto operation = static_cast<BooleanOperation>(random.integer(0, 2));
    int first = -1, second = -1;
    auto a = random_tree(random, model, depth + 1, max_depth, first);
    auto b = random_tree(random, model, depth + 1, max_depth, second);
    model.nodes[index].leaf = false;
    model.nodes[index].operation = operation;
    model.nodes[index].first = first;
    model.nodes[index].second = second;
    std::shared_ptr<const Shape> node = std::make_shared<Boolean>(operation, a, b);
    if (random.uniform() < 0.15) {
        const Transform placement =
            Transform::translate(random.unit_vector() * 0.5) *
            Transform::rotate(random.unit_vector(), random.uniform(0, kPi)) *
            Transform::scale(random.uniform(0.7, 1.3));
        set_transform(model.nodes[index], placement);
        node = std::make_shared<Instance>(node, placement);
    }
    return node;
}

// Every crossing of the ray's line with a leaf ball, in long double. Returns false when a leaf
// is nearly tangent (roots closer than kTangentGap in distance), where double roots lose half
// their digits and the reference cannot say which end comes first.
constexpr Real kTangentGap = 1e-4;
bool leaf_crossings(const Model& model, int index, const RealMatrix& linear,
                    const RealVector& translation, const Ray& ray,
                    std::vector<Crossing>& crossings) {
    const ModelNode& node = model.nodes[index];
    const RealMatrix world_linear = linear * node.linear;
    const RealVector world_translation = linear * node.translation + translation;
    if (!node.leaf) {
        return leaf_crossings(model, node.first, world_linear, world_translation, ray, crossings) &&
               leaf_crossings(model, node.second, world_linear, world_translation, ray, crossings);
    }
    const RealMatrix inverse = world_linear.inverse();
    const RealVector o = inverse * (ray.origin.cast<Real>() - world_translation);
    const RealVector d = inverse * ray.direction.cast<Real>();
    const Real a = d.squaredNorm(), b = o.dot(d), c = o.squaredNorm() - 1;
    const Real discriminant = b * b - a * c;
    if (discriminant < 0) return true;
    const Real root = std::sqrt(discriminant);
    const Real t0 = (-b - root) / a, t1 = (-b + root) / a;
    if ((t1 - t0) * ray.direction.norm() < kTangentGap) return false;
    crossings.push_back({t0, node.surface});
    crossings.push_back({t1, node.surface});
    return true;
}

RealVector at(const Ray& ray, Real t) {
    return ray.origin.cast<Real>() + t * ray.direction.cast<Real>();
}

// A ray toward the solid's box (or the leaves' region when that box is empty).
Ray random_ray(test::Random& random, const Aabb& bounds, int i) {
    const Aabb target =
        bounds.is_empty() ? Aabb(Point3(-1.5, -1.5, -1.5), Point3(1.5, 1.5, 1.5)) : bounds;
    Ray ray = random.ray_between(test::enlarged(target, 1.0), target);
    if (i % 5 == 0) ray.origin = random.in_box(target);  // often inside the solid
    if (i % 4 == 1) {  // a random interval, sometimes starting behind the origin
        const double length = ray.direction.norm();
        ray.t_min = random.uniform(-2.0, 6.0) / length;
        ray.t_max = ray.t_min + random.uniform(0.0, 6.0) / length;
    }
    return ray;
}

// Tolerances, in distance along the ray (|t| |d|) for a scene of size ~5: double roots of
// quadratics whose roots are >= kTangentGap apart are accurate to ~1e-12 (u times the
// conditioning 1 / gap), so a hit within kHitTolerance of a reference crossing is that crossing;
// crossings closer than kAmbiguous to each other or to the interval's ends make a ray whose
// answer depends on rounding, and it is skipped (and counted).
constexpr Real kHitTolerance = 1e-9;
constexpr Real kAmbiguous = 1e-6;
// How far off the surface the normal's side is probed: far above the hit's error, far below
// the distance to any other surface except within 1e-7 of a crease.
constexpr Real kNormalProbe = 1e-7;

TEST(BooleanProperties, RandomTreesAgreeWithPointMembership) {
    test::Random random(61);
    long rays = 0, hits = 0, skipped = 0, stretches = 0, flipped = 0, from_inside = 0;
    int failures = 0;
    std::vector<Crossing> crossings;
    for (int tree = 0; tree < 750 && failures < 10; ++tree) {
        Model model;
        const std::shared_ptr<const Shape> solid =
            random_tree(random, model, 0, random.integer(1, 4), model.root);
        for (int i = 0; i < 200 && failures < 10; ++i) {
            const Ray ray = random_ray(random, solid->bounds(), i);
            ++rays;
            crossings.clear();
            const bool clear = leaf_crossings(model, model.root, RealMatrix::Identity(),
                                              RealVector::Zero(), ray, crossings);
            std::sort(crossings.begin(), crossings.end(),
                      [](const Crossing& a, const Crossing& b) { return a.t < b.t; });
            // The stretches between consecutive crossings and the interval's ends; membership
            // is constant on each.
            std::vector<Real> cuts{static_cast<Real>(ray.t_min), static_cast<Real>(ray.t_max)};
            for (const Crossing& crossing : crossings) cuts.push_back(crossing.t);
            std::sort(cuts.begin(), cuts.end());
            bool ambiguous = !clear;
            const Real length = ray.direction.norm();
            for (std::size_t k = 1; k < cuts.size(); ++k) {
                if (std::isfinite(cuts[k]) && (cuts[k] - cuts[k - 1]) * length < kAmbiguous)
                    ambiguous = true;
            }
            if (ambiguous) {
                ++skipped;
                continue;
            }
            SCOPED_TRACE(::testing::Message() << "tree " << tree << " ray " << i);
            auto inside_at = [&](Real t) { return model.contains(at(ray, t)); };
            // The reference first boundary: the first crossing in the interval where membership
            // changes, from the stretches on either side.
            const Crossing* expected = nullptr;
            bool inside_before_expected = false;
            for (std::size_t k = 0; k < crossings.size() && expected == nullptr; ++k) {
                const Real t = crossings[k].t;
                if (t < ray.t_min || t > ray.t_max) continue;
                const Real before = k > 0 ? (crossings[k - 1].t + t) / 2 : t - 1;
                const Real after = k + 1 < crossings.size() ? (t + crossings[k + 1].t) / 2 : t + 1;
                if (inside_at(before) != inside_at(after)) {
                    expected = &crossings[k];
                    inside_before_expected = inside_at(before);
                }
            }
            const std::optional<Hit> hit = solid->intersect(ray);
            const bool occluded = solid->occluded(ray);
            EXPECT_EQ(hit.has_value(), expected != nullptr);
            EXPECT_EQ(occluded, hit.has_value());
            if (hit && expected) {
                ++hits;
                EXPECT_LE(std::abs(hit->t - expected->t) * length, kHitTolerance);
                EXPECT_EQ(hit->shape, expected->surface) << "the hit names the wrong leaf";
                // The normal points out of the result, and the ray enters exactly when it was
                // outside before the hit.
                const RealVector point = at(ray, expected->t);
                const RealVector normal = hit->geometric_normal.cast<Real>();
                EXPECT_FALSE(model.contains(point + kNormalProbe * normal)) << "normal points in";
                EXPECT_TRUE(model.contains(point - kNormalProbe * normal)) << "normal points in";
                EXPECT_EQ(hit->front_face, !inside_before_expected);
                flipped += hit->front_face == (hit->geometric_normal.dot(ray.direction) > 0);
                from_inside += inside_before_expected;
            }
            if (hit.has_value() != (expected != nullptr) || occluded != hit.has_value()) ++failures;
            // Spans: membership on every stretch inside the interval, the first end in the
            // interval is the hit, and contains agrees.
            const SpanList spans = solid->spans(ray);
            double first_end = kInfinity;
            for (const Span& span : spans) {
                for (const HitRecord* end : {&span.enter, &span.exit})
                    if (end->shape != nullptr && ray.in_range(end->t))
                        first_end = std::min(first_end, end->t);
            }
            EXPECT_EQ(first_end, hit ? hit->t : kInfinity);
            for (std::size_t k = 1; k < cuts.size(); ++k) {
                if (cuts[k - 1] < ray.t_min || cuts[k] > ray.t_max) continue;
                if (!std::isfinite(cuts[k - 1]) || !std::isfinite(cuts[k])) continue;
                const Real t = (cuts[k - 1] + cuts[k]) / 2;
                const bool expected_inside = inside_at(t);
                bool in_spans = false;
                for (const Span& span : spans) in_spans |= span.enter.t < t && t < span.exit.t;
                ++stretches;
                EXPECT_EQ(in_spans, expected_inside) << "stretch at t = " << static_cast<double>(t);
                EXPECT_EQ(solid->contains(ray.at(static_cast<double>(t))), expected_inside);
                if (in_spans != expected_inside) ++failures;
            }
        }
    }
    // Enough rays and hits of every kind, and few rays set aside as ambiguous.
    EXPECT_GE(rays, 150000);
    EXPECT_GT(hits, 30000);
    EXPECT_GT(stretches, 200000);
    EXPECT_GT(from_inside, 2000);
    EXPECT_LT(skipped, rays / 50);
    EXPECT_EQ(flipped, 0);
    std::cout << "rays " << rays << " hits " << hits << " from inside " << from_inside
              << " stretches " << stretches << " skipped " << skipped << "\n";
}

TEST(BooleanProperties, NoAllocationPerRayOnceWarm) {
    test::Random random(67);
    Model model;
    int root = -1;
    // A deep tree: depth 4 with every inner level present, so span lists nest four deep.
    std::shared_ptr<const Shape> solid;
    do {
        model = Model{};
        solid = random_tree(random, model, 0, 4, root);
    } while (model.nodes.size() < 20);
    std::vector<Ray> rays;
    for (int i = 0; i < 11000; ++i) rays.push_back(random_ray(random, solid->bounds(), i));
    QueryScratch scratch;
    SpanList spans;
    long hits = 0;
    auto query = [&](const Ray& ray) {
        scratch.reset();
        HitRecord record;
        if (solid->nearest_hit(ray, record, scratch)) {
            ++hits;
            finish_hit(ray, record, scratch);
        }
        scratch.reset();
        hits += solid->any_hit(ray, scratch);
        scratch.reset();
        solid->find_spans(ray, spans, scratch);
    };
    // Warm up on the first 1,000 rays, then count over 10,000 others.
    for (int i = 0; i < 1000; ++i) query(rays[i]);
    allocations = 0;
    counting = true;
    for (int i = 1000; i < 11000; ++i) query(rays[i]);
    counting = false;
    EXPECT_EQ(allocations, 0);
    EXPECT_GT(hits, 500);
}

}  // namespace
}  // namespace csgrt
