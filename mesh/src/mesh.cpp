#include "csgrt/mesh/mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "csgrt/core/error.h"
#include "csgrt/mesh/mesh_tools.h"

namespace csgrt {

std::string default_mesh_accelerator() {
    // The factory lists what is registered; a mesh built before the BVH lands still works with
    // the brute-force loop, and every mesh switches to the BVH once it is registered.
    for (std::string_view name : accelerator_names()) {
        if (name == "bvh") return "bvh";
    }
    return "brute";
}

namespace {

// While crossings are classified and paired, each record's `object` field holds these flags;
// it is reset before a record leaves the mesh.
constexpr std::uint32_t kEntering = 1;  // the ray crosses from outside to inside
constexpr std::uint32_t kCounted = 2;   // this report counts (not a duplicate at an edge)
constexpr std::uint32_t kOnEdge = 4;    // the ray passes exactly through an edge or vertex

/// The tie rule for a ray exactly on the directed edge p -> q of the sheared 2D frame: the
/// edge owns the point when its direction lies in the half-open upper half-plane. Reversing
/// the edge reverses the answer, so of two triangles on either side of a shared edge exactly
/// one owns it, and of a fan around a vertex exactly one owns the vertex (the top-left rule of
/// rasterisers, Pineda, "A Parallel Algorithm for Polygon Rasterization", SIGGRAPH 1988).
template <class Real>
bool owns_edge(Real px, Real py, Real qx, Real qy) {
    const Real dy = qy - py;
    const Real dx = qx - px;
    return dy > Real(0) || (dy == Real(0) && dx < Real(0));
}

/// Classifies the crossing of triangle i that the set reported for `ray`: recomputes the
/// edge functions exactly as TriangleSet::hit does (Woop, Benthin and Wald, "Watertight
/// Ray/Triangle Intersection", JCGT 2(1) 2013), so the winding sign is the one the test saw
/// and the ties are the test's exact zeros.
template <class Real>
std::uint32_t classify(const TriangleSet<Real>& set, std::size_t i,
                       const typename TriangleSet<Real>::PreparedRay& ray) {
    using Vector = typename TriangleSet<Real>::Vector;
    const int kx = ray.axis_x, ky = ray.axis_y, kz = ray.axis_z;
    const Vector a = set.corner(i, 0) - ray.origin;
    const Vector b = set.corner(i, 1) - ray.origin;
    const Vector d = set.corner(i, 2) - ray.origin;
    const Real ax = a[kx] - ray.shear_x * a[kz], ay = a[ky] - ray.shear_y * a[kz];
    const Real bx = b[kx] - ray.shear_x * b[kz], by = b[ky] - ray.shear_y * b[kz];
    const Real cx = d[kx] - ray.shear_x * d[kz], cy = d[ky] - ray.shear_y * d[kz];
    Real u = cx * by - cy * bx;  // edge c -> b
    Real v = ax * cy - ay * cx;  // edge a -> c
    Real w = bx * ay - by * ax;  // edge b -> a
    if constexpr (std::is_same_v<Real, float>) {
        if (u == 0.0f || v == 0.0f || w == 0.0f) {
            u = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
            v = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
            w = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
        }
    }
    const Real determinant = u + v + w;
    // The sheared frame maps the direction to +z scaled by 1/d_z, so the 2D winding seen from
    // the ray, corrected by the sign of d_z, tells entering (d . n < 0) from leaving.
    const bool entering = (determinant > Real(0)) == (ray.shear_z > 0.0);
    std::uint32_t flags = entering ? kEntering : 0;
    bool counted = true;
    auto tie = [&](Real edge, Real px, Real py, Real qx, Real qy) {
        if (edge != Real(0)) return;
        flags |= kOnEdge;
        // A clockwise (negative) triangle owns the opposite half of its edges.
        if (owns_edge(px, py, qx, qy) == (determinant < Real(0))) counted = false;
    };
    tie(u, cx, cy, bx, by);
    tie(v, ax, ay, cx, cy);
    tie(w, bx, by, ax, ay);
    return flags | (counted ? kCounted : 0);
}

/// Directions for point membership, chosen to be unlikely to run along the edges or faces of
/// modelled meshes (which favour axis and diagonal directions).
const std::array<Vector3, 5>& membership_directions() {
    static const std::array<Vector3, 5> directions = {
        Vector3(0.5773, 0.6391, 0.5082).normalized(), Vector3(-0.7213, 0.3319, 0.6079).normalized(),
        Vector3(0.2262, -0.8917, 0.3921).normalized(),
        Vector3(-0.4407, -0.5127, -0.7369).normalized(),
        Vector3(0.8816, 0.0741, -0.4662).normalized()};
    return directions;
}

/// Incident triangles per vertex above which creased corner normals are not computed (the
/// corner takes its face's normal): the pairwise comparison costs the square of the count.
constexpr std::size_t kMaxCreaseFan = 1024;

/// Per-corner normals split at creases (MeshConfig::crease_angle): for corner k of triangle i
/// at vertex v, the sum over the triangles at v whose normal is within the angle of triangle
/// i's, of their unit normal times their angle at v (the weights of validate_mesh's vertex
/// normals, Thuermer and Wuethrich 1998), normalised.
std::vector<std::array<Eigen::Vector3f, 3>> crease_normals(
    const std::vector<Eigen::Vector3d>& vertices,
    const std::vector<std::array<std::uint32_t, 3>>& triangles, double crease_angle) {
    const std::size_t n = triangles.size();
    std::vector<Eigen::Vector3d> face(n);
    std::vector<std::array<double, 3>> angle(n);
    std::vector<std::uint32_t> start(vertices.size() + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const auto& t = triangles[i];
        face[i] = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
        face[i].normalize();
        for (int k = 0; k < 3; ++k) {
            const Eigen::Vector3d to_next = vertices[t[(k + 1) % 3]] - vertices[t[k]];
            const Eigen::Vector3d to_previous = vertices[t[(k + 2) % 3]] - vertices[t[k]];
            angle[i][k] = std::atan2(to_next.cross(to_previous).norm(), to_next.dot(to_previous));
            ++start[t[k] + 1];
        }
    }
    for (std::size_t v = 0; v < vertices.size(); ++v) start[v + 1] += start[v];
    // The corners at each vertex, as 3 i + k.
    std::vector<std::uint32_t> corners(3 * n);
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) corners[fill[triangles[i][k]]++] = std::uint32_t(3 * i + k);
    }
    const double cos_crease = std::cos(crease_angle);
    std::vector<std::array<Eigen::Vector3f, 3>> normals(n);
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = triangles[i][k];
            Eigen::Vector3d sum = Eigen::Vector3d::Zero();
            if (start[v + 1] - start[v] > kMaxCreaseFan) {
                sum = face[i];
            } else {
                for (std::uint32_t c = start[v]; c < start[v + 1]; ++c) {
                    const std::uint32_t other = corners[c] / 3, at = corners[c] % 3;
                    if (face[other].dot(face[i]) >= cos_crease)
                        sum += angle[other][at] * face[other];
                }
            }
            const double length = sum.norm();
            normals[i][k] = (length > 0.0 ? Eigen::Vector3d(sum / length) : face[i]).cast<float>();
        }
    }
    return normals;
}

}  // namespace

Mesh::Mesh(TriangleMeshData mesh, const MeshConfig& config) {
    const std::size_t welded = config.weld_vertices ? weld_vertices(mesh) : 0;
    MeshReport report = validate_mesh(mesh);
    report.welded_vertices = welded;
    build(std::move(mesh), std::move(report), config);
}

Mesh::Mesh(TriangleMeshData mesh, MeshReport report, const MeshConfig& config, Validated) {
    build(std::move(mesh), std::move(report), config);
}

Mesh::~Mesh() = default;

std::shared_ptr<Mesh> Mesh::load(const std::filesystem::path& path, const MeshConfig& config) {
    MeshReport report;
    TriangleMeshData mesh = load_mesh(path, &report);
    if (config.weld_vertices) {
        // Validated again on the welded mesh: its topology (closed or not) is what changes.
        const std::size_t welded = weld_vertices(mesh);
        MeshReport topology = validate_mesh(mesh, report);
        topology.welded_vertices = welded;
        report = std::move(topology);
    }
    return std::shared_ptr<Mesh>(new Mesh(std::move(mesh), std::move(report), config, Validated{}));
}

void Mesh::build(TriangleMeshData mesh, MeshReport report, const MeshConfig& config) {
    double_precision_ = config.double_precision;
    report_ = std::move(report);
    triangles_ = std::move(mesh.triangles);
    normals_.reserve(mesh.normals.size());
    for (const Eigen::Vector3d& normal : mesh.normals) normals_.push_back(normal.cast<float>());
    flat_shading_ = config.flat_shading;
    if (!flat_shading_ && config.file_normals && mesh.corner_normals.size() == triangles_.size()) {
        corner_normals_ = std::move(mesh.corner_normals);
    } else if (!flat_shading_ && config.crease_angle < kPi) {
        corner_normals_ = crease_normals(mesh.vertices, triangles_, config.crease_angle);
    }
    if (double_precision_) {
        double_set_ = TriangleSet<double>(mesh.vertices, triangles_);
        double_structure_ =
            make_accelerator(config.accelerator, double_set_, config.accelerator_config);
    } else {
        float_set_ = TriangleSet<float>(mesh.vertices, triangles_);
        float_structure_ =
            make_accelerator(config.accelerator, float_set_, config.accelerator_config);
    }
    // The box of the stored corners, which is what the triangle test intersects.
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
        for (int k = 0; k < 3; ++k) bounds_.extend(corner(i, k));
    }
}

Point3 Mesh::corner(std::size_t i, int k) const {
    return double_precision_ ? Point3(double_set_.corner(i, k))
                             : Point3(float_set_.corner(i, k).cast<double>());
}

AcceleratorStats Mesh::accelerator_stats() const {
    return double_precision_ ? double_structure_->stats() : float_structure_->stats();
}

bool Mesh::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    HitRecord found;
    const bool hit = double_precision_ ? double_structure_->intersect(ray, found, scratch)
                                       : float_structure_->intersect(ray, found, scratch);
    if (!hit) return false;
    // The structure wrote t, primitive and the barycentrics u, v; the rest is the mesh's.
    found.shape = this;
    found.instance_path = kNoIndex;
    found.object = kNoIndex;
    found.flip_normal = false;
    record = found;
    return true;
}

bool Mesh::any_hit(const Ray& ray, QueryScratch& scratch) const {
    return double_precision_ ? double_structure_->occluded(ray, scratch)
                             : float_structure_->occluded(ray, scratch);
}

template <class Real>
int Mesh::crossings(const TriangleSet<Real>& set, const Accelerator<TriangleSet<Real>>& structure,
                    const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch,
                    bool& on_edge) const {
    hits.clear();
    structure.all_hits(ray, hits, scratch);
    const auto prepared = set.prepare(ray, scratch);
    int total = 0;
    on_edge = false;
    for (HitRecord& hit : hits) {
        hit.object = classify(set, hit.primitive, prepared);
        if (hit.object & kCounted) total += (hit.object & kEntering) ? 1 : -1;
        on_edge = on_edge || (hit.object & kOnEdge);
    }
    // By t; at equal t entering first (so a ray touching a ridge gives a zero-length span),
    // then by triangle, the tie rule of nearest_hit.
    std::sort(hits.begin(), hits.end(), [](const HitRecord& a, const HitRecord& b) {
        if (a.t != b.t) return a.t < b.t;
        const bool a_enters = a.object & kEntering, b_enters = b.object & kEntering;
        if (a_enters != b_enters) return a_enters;
        return a.primitive < b.primitive;
    });
    return total;
}

int Mesh::crossings(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch,
                    bool& on_edge) const {
    return double_precision_
               ? crossings(double_set_, *double_structure_, ray, hits, scratch, on_edge)
               : crossings(float_set_, *float_structure_, ray, hits, scratch, on_edge);
}

void Mesh::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    spans.clear();
    if (!is_solid()) return;
    BorrowedHits borrowed(scratch);
    std::vector<HitRecord>& hits = borrowed.list();
    // Every crossing from t_min on: the surface is closed, so the winding number is 0 at
    // +infinity, and the crossings after t_min tell the winding number at t_min.
    Ray line = ray;
    line.t_max = kInfinity;
    bool on_edge;
    const int total = crossings(line, hits, scratch, on_edge);
    // On a closed, outward-oriented surface the winding number is 0 or 1 everywhere. A ray
    // lying in the plane of some triangles (which the test never reports) can unbalance the
    // count; then it is clamped to [0, 1] at every step so the error stays local.
    const bool balanced = total == 0 || total == -1;
    int winding = std::clamp(-total, 0, 1);

    const double magnitude =
        (bounds_.diagonal().norm() + (ray.origin - bounds_.center()).norm()) / ray.direction.norm();
    const double epsilon = double_precision_ ? std::numeric_limits<double>::epsilon()
                                             : double(std::numeric_limits<float>::epsilon());
    // Reports of one surface point by several triangles differ in t by a few roundings.
    const double same_point = 256.0 * epsilon * magnitude;
    // The record of the boundary at hits[k]: the earliest report of the same point, so the
    // first boundary is the hit nearest_hit returns (which takes the lowest t of them all).
    auto boundary = [&](std::size_t k) {
        std::size_t first = k;
        const std::uint32_t direction = hits[k].object & kEntering;
        while (first > 0) {
            const HitRecord& previous = hits[first - 1];
            if ((previous.object & kCounted) || (previous.object & kEntering) != direction ||
                hits[k].t - previous.t > same_point * (1.0 + std::abs(hits[k].t))) {
                break;
            }
            --first;
        }
        HitRecord record = hits[first];
        record.shape = this;
        record.instance_path = kNoIndex;
        record.object = kNoIndex;
        record.flip_normal = false;
        return record;
    };
    HitRecord enter;
    if (winding > 0) enter = HitRecord{.t = -kInfinity};
    for (std::size_t k = 0; k < hits.size(); ++k) {
        if (!(hits[k].object & kCounted)) continue;
        if (winding <= 0 && hits[k].t > ray.t_max) break;  // outside, and past the interval
        const int next = winding + ((hits[k].object & kEntering) ? 1 : -1);
        const int clamped = balanced ? next : std::clamp(next, 0, 1);
        if (winding <= 0 && clamped > 0) enter = boundary(k);
        if (winding > 0 && clamped <= 0) spans.push_back(Span{enter, boundary(k)});
        winding = clamped;
    }
    if (winding > 0 && enter.t <= ray.t_max)
        spans.push_back(Span{enter, HitRecord{.t = kInfinity}});
}

bool Mesh::contains(const Point3& p) const {
    if (!is_solid() || !bounds_.contains(p)) return false;
    QueryScratch& scratch = thread_query_scratch();
    BorrowedHits borrowed(scratch);
    // The winding number of the surface around p, from the crossings of one ray: exact with
    // the tie rule, but a ray through an edge or vertex is retried in another direction all
    // the same, since the answer must not depend on a tie.
    bool inside = false;
    for (const Vector3& direction : membership_directions()) {
        bool on_edge;
        const int winding = -crossings(Ray{p, direction}, borrowed.list(), scratch, on_edge);
        inside = winding > 0;
        if (!on_edge && (winding == 0 || winding == 1)) break;
    }
    return inside;
}

Hit Mesh::finish(const Ray& ray, const HitRecord& record) const {
    const std::size_t i = record.primitive;
    const Point3 a = corner(i, 0), b = corner(i, 1), c = corner(i, 2);
    // Barycentrics from the test (float); a rounding may leave them a hair outside the
    // triangle, so they are projected back into it.
    double u = std::max(0.0, double(record.u));
    double v = std::max(0.0, double(record.v));
    if (u + v > 1.0) {
        const double sum = u + v;
        u /= sum;
        v /= sum;
    }
    const double w = 1.0 - u - v;
    Hit hit;
    hit.t = record.t;
    // From the barycentrics rather than o + t d: the point lies on the triangle.
    hit.point = w * a + u * b + v * c;
    // Float triangles test a ray whose origin they round to float: the float margin, relative
    // to the corners (the point lies in their hull). Double ones get the double rule later.
    if (!double_precision_) {
        hit.point_error =
            kFloatHitErrorRelative *
            std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff()});
    }
    const Normal3 face = (b - a).cross(c - a);
    const std::array<std::uint32_t, 3>& t = triangles_[i];
    // The vertex normals (or the creased corner normals) interpolated by the barycentrics.
    const Normal3 smooth =
        corner_normals_.empty()
            ? Normal3(w * normals_[t[0]].cast<double>() + u * normals_[t[1]].cast<double>() +
                      v * normals_[t[2]].cast<double>())
            : Normal3(w * corner_normals_[i][0].cast<double>() +
                      u * corner_normals_[i][1].cast<double>() +
                      v * corner_normals_[i][2].cast<double>());
    const double face_length = face.norm();
    const double smooth_length = smooth.norm();
    // A triangle that rounding to float made degenerate has no normal of its own; it borrows
    // the interpolated one (and, failing that, faces the ray).
    if (face_length > 0.0 && std::isfinite(face_length)) {
        hit.geometric_normal = face / face_length;
    } else if (smooth_length > 0.0) {
        hit.geometric_normal = smooth / smooth_length;
    } else {
        hit.geometric_normal = -ray.direction.normalized();
    }
    hit.shading_normal = !flat_shading_ && smooth_length > 0.0 && std::isfinite(smooth_length)
                             ? Normal3(smooth / smooth_length)
                             : hit.geometric_normal;
    hit.uv = Vector2(u, v);
    hit.shape = this;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(hit.geometric_normal) < 0.0;
    return hit;
}

}  // namespace csgrt
