#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/accel/factory.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/shape.h"
#include "csgrt/mesh/mesh_io.h"

namespace csgrt {

/// "bvh" once that structure is registered with the factory, "brute" until then: a mesh must
/// be usable before the fast structures exist, and must pick the BVH up as soon as it does.
std::string default_mesh_accelerator();

/// How a Mesh stores and accelerates its triangles.
struct MeshConfig {
    /// Triangles in double instead of float (72 instead of 36 bytes a triangle).
    bool double_precision = false;
    /// The factory name of the structure over the triangles (accel/factory.h).
    std::string accelerator = default_mesh_accelerator();
    AcceleratorConfig accelerator_config;
    /// Merge vertices at equal positions before validation (weld_vertices, mesh_tools.h), so
    /// that a soup written one vertex per corner is recognised as the closed solid it is.
    bool weld_vertices = false;
    /// Shade with each triangle's own normal instead of interpolated vertex normals.
    bool flat_shading = false;
    /// Smooth shading joins faces meeting at a vertex only when their normals differ by at most
    /// this angle (radians): a corner's normal is the angle-weighted sum of the normals of the
    /// faces at its vertex within the angle of its own face, so edges sharper than the angle
    /// stay sharp. Pi (the default) joins every face (plain vertex normals).
    double crease_angle = kPi;
    /// Shade with the normals the file stores (OBJ `vn`, PLY `nx ny nz`, NOFF's vertex normals;
    /// TriangleMeshData::corner_normals) when it has one for every corner, interpolated by the
    /// barycentrics like computed ones; they take the place of the crease angle. False
    /// computes normals as for a file without them.
    bool file_normals = true;
};

/// A triangle mesh as one shape: its triangles in a TriangleSet (float by default, double on
/// request), an acceleration structure over them, and angle-weighted vertex normals for smooth
/// shading. A closed mesh (MeshReport::is_closed, oriented outward by validation) is a solid:
/// spans pair the surface crossings along the ray, and `contains` counts them.
///
/// Crossings are classified by the winding of the crossed triangle as the watertight test sees
/// it, and a ray through a shared edge or vertex, which the test reports on every triangle
/// there, is counted once by a top-left tie rule (docs/meshes.md). Queries are const and
/// thread-safe; the hit lists spans need are borrowed from the QueryScratch.
class Mesh final : public Shape {
public:
    /// Validates `mesh` (validate_mesh: drops degenerate triangles, orients closed shells
    /// outward, computes normals) and builds the structure. Throws InvalidParameter for a
    /// non-finite vertex, an out-of-range index, no triangle, or an unknown structure name.
    explicit Mesh(TriangleMeshData mesh, const MeshConfig& config = {});

    /// Loads a mesh file (load_mesh) and builds a Mesh from it without validating it twice.
    /// Throws MeshError for a file that cannot be used.
    static std::shared_ptr<Mesh> load(const std::filesystem::path& path,
                                      const MeshConfig& config = {});

    Mesh(const Mesh&) = delete;
    Mesh& operator=(const Mesh&) = delete;
    ~Mesh() override;

    std::string_view kind() const override { return "mesh"; }
    Aabb bounds() const override { return bounds_; }
    bool is_solid() const override { return report_.is_closed; }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    Hit finish(const Ray& ray, const HitRecord& record) const override;

    /// What validation found and repaired.
    const MeshReport& report() const { return report_; }
    std::size_t triangle_count() const { return triangles_.size(); }
    /// The vertex indices of triangle i (after validation's reorientation).
    const std::array<std::uint32_t, 3>& triangle(std::size_t i) const { return triangles_[i]; }
    /// Corner k of triangle i as stored for intersection (rounded to float by default).
    Point3 corner(std::size_t i, int k) const;
    bool double_precision() const { return double_precision_; }
    /// The structure's figures (name, build time, bytes...).
    AcceleratorStats accelerator_stats() const;

private:
    struct Validated {};
    Mesh(TriangleMeshData mesh, MeshReport report, const MeshConfig& config, Validated);
    void build(TriangleMeshData mesh, MeshReport report, const MeshConfig& config);

    /// The crossings of `ray` with the surface in [t_min, t_max] into `hits`, classified
    /// (entering or leaving, counted or a duplicate at an edge: flags in `object`) and sorted
    /// by t. Returns the sum of the counted crossings' signs (+1 entering, -1 leaving);
    /// `on_edge` tells whether the ray passed exactly through an edge or vertex.
    int crossings(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch,
                  bool& on_edge) const;
    template <class Real>
    int crossings(const TriangleSet<Real>& set, const Accelerator<TriangleSet<Real>>& structure,
                  const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch,
                  bool& on_edge) const;

    bool double_precision_ = false;
    std::vector<std::array<std::uint32_t, 3>> triangles_;
    std::vector<Eigen::Vector3f> normals_;
    /// Per-corner normals when a crease angle splits vertex normals (else empty).
    std::vector<std::array<Eigen::Vector3f, 3>> corner_normals_;
    bool flat_shading_ = false;
    MeshReport report_;
    Aabb bounds_;
    TriangleSet<float> float_set_;
    TriangleSet<double> double_set_;
    std::unique_ptr<Accelerator<TriangleSet<float>>> float_structure_;
    std::unique_ptr<Accelerator<TriangleSet<double>>> double_structure_;
};

}  // namespace csgrt
