#pragma once

#include <cstdint>

#include "csgrt/core/math.h"

namespace csgrt {

class Shape;

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
};

/// A finished hit, in the space of the ray that was queried.
struct Hit {
    double t = kInfinity;
    Point3 point{0.0, 0.0, 0.0};
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
    /// True when the ray arrives on the side the geometric normal points to.
    bool front_face = true;
};

}  // namespace csgrt
