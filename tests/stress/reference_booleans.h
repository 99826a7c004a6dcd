#pragma once

// Long double models of CSG booleans and of the ready-made compounds (csg/ready_made.h), for
// the tests that judge shapes against the long double reference (reference_judge.h). Like
// reference_shapes.h they are written from the documented geometry (docs/csg.md,
// docs/shapes.md), not from csgrt's code: a boolean's surface is where the ray's line crosses
// one operand's surface with the other operand's membership saying the result changes there,
// and the ready-made compounds are the surfaces their documentation describes (the points
// within a radius of a box, a tube between two radii, a shell below a rim), built as patches
// without any boolean.

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "csgrt/core/math.h"
#include "stress/reference_shapes.h"

namespace csgrt::test {

enum class ReferenceOperation { kUnion, kIntersection, kDifference };

/// The boolean of two bounded solids' models. A crossing of one operand's surface is one of
/// the result's where the other operand's membership makes it so (union: outside the other;
/// intersection: inside it; difference A - B: A's outside B, B's inside A). Membership at a
/// point of the line is the parity of the other operand's kept crossings before it: the line
/// comes from infinity, outside every bounded solid.
///
/// Where the two operands' crossings lie close together along the line, a double computation
/// may order them either way: each crossing's t is known to kRootUlps point scales / cos
/// (reference_judge.h), and spans closer than the coincidence tolerance, 256 u (|t| + |o|/|d|)
/// (docs/csg.md), are merged. So a crossing's trim distance becomes the smaller of its own and
/// its separation from the nearest kept crossing of the other operand, measured so that the
/// judge's trim band (kTrimBand point scales / cos a) holds exactly when the separation
/// |t_a - t_b| |d| is within kTrimBand point scales (1 / cos a + 1 / cos b) plus twice the
/// coincidence tolerance: separation' = max(0, |t_a - t_b| |d| - 512 u (|t| |d| + |o|)) *
/// cos b / (cos a + cos b). Both operands' near tangencies stay near tangencies of the result
/// (conservative: some are inside the other operand and could not change the answer).
class BooleanReference final : public ReferenceShape {
public:
    BooleanReference(ReferenceOperation operation, std::shared_ptr<const ReferenceShape> a,
                     std::shared_ptr<const ReferenceShape> b)
        : operation_(operation), a_(std::move(a)), b_(std::move(b)) {}

    void crossings(const LongRay& ray, LineCrossings& out) const override {
        LineCrossings a, b;
        a_->crossings(ray, a);
        b_->crossings(ray, b);
        const std::vector<Crossing> kept_a = kept(a), kept_b = kept(b);
        const Long length = ray.direction.norm();
        const Long origin = ray.origin.norm();
        // On the surface of the result: for A's crossings, whether B holds them; for B's,
        // whether A does.
        const bool a_wants_inside_b = operation_ == ReferenceOperation::kIntersection;
        const bool b_wants_inside_a = operation_ != ReferenceOperation::kUnion;
        for (Crossing crossing : a.crossings) {
            combine(crossing, kept_b, a_wants_inside_b, length, origin);
            out.crossings.push_back(crossing);
        }
        for (Crossing crossing : b.crossings) {
            combine(crossing, kept_a, b_wants_inside_a, length, origin);
            out.crossings.push_back(crossing);
        }
        out.tangencies.insert(out.tangencies.end(), a.tangencies.begin(), a.tangencies.end());
        out.tangencies.insert(out.tangencies.end(), b.tangencies.begin(), b.tangencies.end());
    }

private:
    static std::vector<Crossing> kept(const LineCrossings& line) {
        std::vector<Crossing> list;
        for (const Crossing& crossing : line.crossings) {
            if (crossing.trim_distance >= 0) list.push_back(crossing);
        }
        std::sort(list.begin(), list.end(),
                  [](const Crossing& x, const Crossing& y) { return x.t < y.t; });
        return list;
    }

    static void combine(Crossing& crossing, const std::vector<Crossing>& other, bool wants_inside,
                        Long length, Long origin) {
        std::size_t before = 0;
        Long separation = kLongInfinity;
        const Long tolerance = 512 * Long(kUnitRoundoff) * (std::abs(crossing.t) * length + origin);
        const Long cosine = std::max(crossing.cosine, Long(1e-300));
        for (const Crossing& boundary : other) {
            if (boundary.t < crossing.t) ++before;
            const Long apart =
                std::max(Long(0), std::abs(boundary.t - crossing.t) * length - tolerance);
            const Long other_cosine = std::max(boundary.cosine, Long(1e-300));
            separation = std::min(separation, apart * other_cosine / (cosine + other_cosine));
        }
        const bool inside = before % 2 == 1;
        crossing.trim_distance =
            std::min(crossing.trim_distance, inside == wants_inside ? separation : -separation);
    }

    ReferenceOperation operation_;
    std::shared_ptr<const ReferenceShape> a_, b_;
};

inline std::shared_ptr<const ReferenceShape> reference_boolean(
    ReferenceOperation operation, std::shared_ptr<const ReferenceShape> a,
    std::shared_ptr<const ReferenceShape> b) {
    return std::make_shared<BooleanReference>(operation, std::move(a), std::move(b));
}

/// The thick ring about the y axis (make_thick_ring): inner <= sqrt(x^2 + z^2) <= outer,
/// y_min <= y <= y_max. Two cylinder sides and two annular ends.
inline std::shared_ptr<PatchShape> reference_thick_ring(double y_min, double y_max, double inner,
                                                        double outer) {
    auto shape = std::make_shared<PatchShape>();
    const Long lo = y_min, hi = y_max, r_in = inner, r_out = outer;
    const Trim height = [=](const LongVector& x) { return std::min(x.y() - lo, hi - x.y()); };
    shape->quadrics.push_back(cylinder_side(outer, height));
    shape->quadrics.push_back(cylinder_side(inner, height));
    const Trim annulus = [=](const LongVector& local) {
        const Long rho = local.norm();
        return std::min(r_out - rho, rho - r_in);
    };
    shape->planes.push_back({LongVector(0, lo, 0), LongVector(0, -1, 0), annulus});
    shape->planes.push_back({LongVector(0, hi, 0), LongVector(0, 1, 0), annulus});
    return shape;
}

/// The flat-rimmed bowl around the origin (make_bowl): inner <= |p| <= outer, y <= 0. The
/// outer and inner spheres below y = 0 and the rim, the annulus between them in y = 0.
inline std::shared_ptr<PatchShape> reference_bowl(double outer, double inner) {
    auto shape = std::make_shared<PatchShape>();
    const Trim below = [](const LongVector& x) { return -x.y(); };
    shape->quadrics.push_back(sphere_patch(Point3(0, 0, 0), outer, below));
    shape->quadrics.push_back(sphere_patch(Point3(0, 0, 0), inner, below));
    const Long r_in = inner, r_out = outer;
    shape->planes.push_back(
        {LongVector(0, 0, 0), LongVector(0, 1, 0), [=](const LongVector& local) {
             const Long rho = local.norm();
             return std::min(r_out - rho, rho - r_in);
         }});
    return shape;
}

/// The rounded box (make_rounded_box): the points within `radius` of the inner box
/// [lower + radius, upper - radius]. Its surface: six faces, each the inner box's face moved
/// out by the radius; twelve quarter cylinders around the inner box's edges; eight sphere
/// octants around its corners. Each patch is trimmed to the region the inner box's nearest
/// feature gives it.
inline std::shared_ptr<PatchShape> reference_rounded_box(const Point3& lower, const Point3& upper,
                                                         double radius) {
    const LongVector in_lo = to_long(lower) + LongVector::Constant(Long(radius));
    const LongVector in_hi = to_long(upper) - LongVector::Constant(Long(radius));
    auto shape = std::make_shared<PatchShape>();
    // Beyond the inner box on `side` of `axis`: >= 0 there. Within its extent on `axis`.
    auto beyond = [=](const LongVector& p, int axis, int side) {
        return side ? p[axis] - in_hi[axis] : in_lo[axis] - p[axis];
    };
    auto within = [=](const LongVector& p, int axis) {
        return std::min(p[axis] - in_lo[axis], in_hi[axis] - p[axis]);
    };
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            LongVector point = in_lo;
            point[axis] = side ? Long(upper[axis]) : Long(lower[axis]);
            LongVector normal = LongVector::Zero();
            normal[axis] = side ? 1 : -1;
            shape->planes.push_back({point, normal, [=](const LongVector& local) {
                                         const LongVector p = point + local;
                                         return std::min(within(p, (axis + 1) % 3),
                                                         within(p, (axis + 2) % 3));
                                     }});
        }
    }
    // Edges along `axis`, around the inner box's edge on sides (sb, sc) of the other two.
    for (int axis = 0; axis < 3; ++axis) {
        const int b = (axis + 1) % 3, c = (axis + 2) % 3;
        for (int sb = 0; sb < 2; ++sb) {
            for (int sc = 0; sc < 2; ++sc) {
                LongVector centre = LongVector::Zero();
                centre[b] = sb ? in_hi[b] : in_lo[b];
                centre[c] = sc ? in_hi[c] : in_lo[c];
                LongVector diagonal = LongVector::Ones();
                diagonal[axis] = 0;
                const Long r = radius;
                shape->quadrics.push_back(
                    {centre, diagonal, LongVector::Zero(), -r * r, [=](const LongVector& x) {
                         const LongVector p = centre + x;
                         return std::min({beyond(p, b, sb), beyond(p, c, sc), within(p, axis)});
                     }});
            }
        }
    }
    for (int corner = 0; corner < 8; ++corner) {
        LongVector centre;
        for (int axis = 0; axis < 3; ++axis)
            centre[axis] = ((corner >> axis) & 1) ? in_hi[axis] : in_lo[axis];
        const Point3 at(double(centre.x()), double(centre.y()), double(centre.z()));
        shape->quadrics.push_back(sphere_patch(at, radius, [=](const LongVector& x) {
            const LongVector p = centre + x;
            Long trim = kLongInfinity;
            for (int axis = 0; axis < 3; ++axis)
                trim = std::min(trim, beyond(p, axis, (corner >> axis) & 1));
            return trim;
        }));
    }
    return shape;
}

}  // namespace csgrt::test
