#pragma once

#include <cstdint>

#include "csgrt/core/math.h"

namespace csgrt {

class Shape;

/// HitRecord::material of a hit no Painted shape (csg/painted.h) has given a material; painted
/// materials are indices below it.
inline constexpr std::uint16_t kNoPaintedMaterial = 0xFFFF;
inline constexpr std::uint32_t kMaxPaintedMaterial = kNoPaintedMaterial - 1;

/// What a query knows about a hit before it is shaded: the parameter t, the leaf surface, and
/// what that surface needs to finish the hit later (a primitive index and a local parameter
/// such as a triangle's barycentrics). Queries keep only these 40 bytes while they search;
/// normals, uv and the hit point are computed once, for the hit that wins (`finish_hit`).
struct HitRecord {
    double t = kInfinity;
    /// The leaf that was hit (never an Instance, compound or boolean). Null for an unbounded
    /// span end (a ray that starts inside a solid has a span that begins at -infinity).
    const Shape* shape = nullptr;
    /// The leaf's own sub-primitive (triangle index, box face, cylinder cap...).
    std::uint32_t primitive = kNoIndex;
    /// The instances between the query's root and the leaf, as an index into the query's
    /// QueryScratch (kNoIndex: none).
    std::uint32_t instance_path = kNoIndex;
    /// Which member of a shape set (a compound's child, a scene's object) the hit belongs to;
    /// the outermost set writes it last, so at the top it is the scene object.
    std::uint32_t object = kNoIndex;
    /// Surface parameters the leaf chose to keep (barycentrics for triangles); leaf-defined.
    float u = 0.0f;
    float v = 0.0f;
    /// Set by CSG difference on surfaces of a subtracted solid: their outward normal is the
    /// result's inward normal.
    bool flip_normal = false;
    /// The material the innermost Painted shape on the hit's path gave it (an index into the
    /// scene's materials), or kNoPaintedMaterial. Fits the record's padding: still 40 bytes.
    std::uint16_t material = kNoPaintedMaterial;
};
static_assert(sizeof(HitRecord) == 40, "the material fits the record's padding");

/// The point error `finish_hit` gives a hit on a double-precision leaf, in units of the unit
/// roundoff times the largest coordinate magnitude the leaf's computation saw (the point, the
/// ray's origin and the leaf's bounds). A hit point reprojected onto the surface is good to a
/// few ulps; the rest covers the leaf's own test on a ray starting next to the surface, whose
/// near root is off by a few ulps of the same magnitudes divided by the ray's cosine with the
/// surface (tests/render/secondary_ray_test.cpp, on every kind of shape at distances up to
/// 10^6 from the origin and cosines down to 0.02, finds the first self hits at 2^5 and none at
/// 2^6: 2^9 keeps a factor 8 in hand).
inline constexpr double kDoubleHitErrorUlps = 0x1.0p9;

/// The point error of a hit on a float triangle, relative to the largest corner coordinate:
/// the triangle test rounds the ray's origin to float (half a float ulp per coordinate) and
/// works in float from there. 2^-19, 16 float ulps, is 8 times the 2^-22 that
/// tests/render/shadow_offset_test.cpp measures as enough and 1/8 of Waechter and Binder's
/// 2^-16 (their int_scale of 256 ulps).
inline constexpr double kFloatHitErrorRelative = 0x1.0p-19;

/// A finished hit, in the space of the ray that was queried.
struct Hit {
    double t = kInfinity;
    Point3 point{0.0, 0.0, 0.0};
    /// A bound on how far `point` may lie from the surface as the shape's own queries see it,
    /// in this hit's space: the distance a ray leaving the point must clear not to meet that
    /// surface again (pbrt-v4's pError box, kept as one length; render/shadow_offset.h). Leaves
    /// of double shapes get a few ulps of their coordinates, float triangles the float margin
    /// of Waechter and Binder (2019); instances carry it through their transform.
    double point_error = 0.0;
    /// Unit normal of the surface as defined (outward for solids), not turned toward the ray.
    Normal3 geometric_normal{0.0, 0.0, 1.0};
    /// Unit normal for shading (interpolated on smooth meshes; else the geometric normal).
    Normal3 shading_normal{0.0, 0.0, 1.0};
    /// Surface parameterisation in [0,1]^2 where the shape defines one.
    Vector2 uv{0.0, 0.0};
    /// The leaf shape that was hit, and its sub-primitive.
    const Shape* shape = nullptr;
    std::uint32_t primitive_id = kNoIndex;
    /// The scene object the hit belongs to (set by the scene; kNoIndex for a bare shape).
    std::uint32_t object_id = kNoIndex;
    /// The material a Painted shape gave the surface (HitRecord::material), or kNoIndex: the
    /// scene object's.
    std::uint32_t material = kNoIndex;
    /// True when the ray arrives on the side the geometric normal points to.
    bool front_face = true;
};

}  // namespace csgrt
