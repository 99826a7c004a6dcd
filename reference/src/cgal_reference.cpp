#include "csgrt/reference/cgal_reference.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace csgrt {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<Kernel::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>;
using Traits = CGAL::AABB_traits<Kernel, Primitive>;
using Tree = CGAL::AABB_tree<Traits>;

Kernel::Point_3 to_cgal(const Eigen::Vector3d& p) {
    return {p.x(), p.y(), p.z()};
}

/// Exact constructions, for the rays that lie in a triangle's plane: there the hit is a
/// segment, and its near end is a constructed point.
using ExactKernel = CGAL::Exact_predicates_exact_constructions_kernel;

ExactKernel::Point_3 to_exact(const Eigen::Vector3d& p) {
    return {p.x(), p.y(), p.z()};
}
}  // namespace

struct CgalReference::Tree {
    Triangles triangles;
    csgrt::Tree tree;
};

template <class Real>
CgalReference::CgalReference(const TriangleSet<Real>& set) : tree_(std::make_unique<Tree>()) {
    corners_.reserve(set.size());
    tree_->triangles.reserve(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) {
        const std::array<Eigen::Vector3d, 3> c = {set.corner(i, 0).template cast<double>(),
                                                  set.corner(i, 1).template cast<double>(),
                                                  set.corner(i, 2).template cast<double>()};
        corners_.push_back(c);
        tree_->triangles.emplace_back(to_cgal(c[0]), to_cgal(c[1]), to_cgal(c[2]));
    }
    tree_->tree.insert(tree_->triangles.begin(), tree_->triangles.end());
    tree_->tree.build();
}

CgalReference::~CgalReference() = default;
CgalReference::CgalReference(CgalReference&&) noexcept = default;
CgalReference& CgalReference::operator=(CgalReference&&) noexcept = default;

std::size_t CgalReference::size() const {
    return corners_.size();
}

double CgalReference::distance(const Point3& point) const {
    if (corners_.empty()) return kInfinity;
    return std::sqrt(CGAL::to_double(tree_->tree.squared_distance(to_cgal(point))));
}

namespace {
// Calls `query` with the CGAL object for the ray's interval: a ray when it is [0, inf),
// otherwise a segment (or a ray from t_min) between end points rounded to double.
template <class Query>
auto with_cgal_query(const Ray& ray, Query&& query) {
    const Kernel::Vector_3 direction(ray.direction.x(), ray.direction.y(), ray.direction.z());
    const Point3 start = ray.t_min == 0.0 ? ray.origin : ray.at(ray.t_min);
    if (ray.t_max == std::numeric_limits<double>::infinity()) {
        return query(Kernel::Ray_3(to_cgal(start), direction));
    }
    return query(Kernel::Segment_3(to_cgal(start), to_cgal(ray.at(ray.t_max))));
}
}  // namespace

bool CgalReference::do_intersect(const Ray& ray) const {
    if (!is_valid(ray)) return false;
    return with_cgal_query(ray, [&](const auto& query) { return tree_->tree.do_intersect(query); });
}

std::vector<std::uint32_t> CgalReference::intersected_primitives(const Ray& ray) const {
    std::vector<std::uint32_t> indices;
    if (!is_valid(ray)) return indices;
    std::vector<Primitive::Id> hits;
    with_cgal_query(ray, [&](const auto& query) {
        tree_->tree.all_intersected_primitives(query, std::back_inserter(hits));
        return 0;
    });
    indices.reserve(hits.size());
    for (const Primitive::Id& id : hits) {
        indices.push_back(static_cast<std::uint32_t>(id - tree_->triangles.cbegin()));
    }
    std::sort(indices.begin(), indices.end());
    return indices;
}

long double CgalReference::plane_t(const Ray& ray, std::uint32_t primitive) const {
    using LongVector = Eigen::Matrix<long double, 3, 1>;
    const auto& c = corners_[primitive];
    const LongVector a = c[0].cast<long double>();
    const LongVector normal = (c[1].cast<long double>() - a).cross(c[2].cast<long double>() - a);
    return normal.dot(a - ray.origin.cast<long double>()) /
           normal.dot(ray.direction.cast<long double>());
}

std::optional<double> CgalReference::in_plane_t(const Ray& ray, std::uint32_t primitive) const {
    using Exact = ExactKernel;
    const auto& c = corners_[primitive];
    const Exact::Triangle_3 triangle(to_exact(c[0]), to_exact(c[1]), to_exact(c[2]));
    const Exact::Point_3 origin = to_exact(ray.origin);
    const Exact::Vector_3 direction(ray.direction.x(), ray.direction.y(), ray.direction.z());
    // The same query as with_cgal_query, built exactly from the same doubles.
    const Point3 start_point = ray.t_min == 0.0 ? ray.origin : ray.at(ray.t_min);
    const Exact::Point_3 start = to_exact(start_point);
    const bool unbounded = ray.t_max == std::numeric_limits<double>::infinity();
    const Exact::Point_3 second = unbounded ? start + direction : to_exact(ray.at(ray.t_max));
    if (triangle.is_degenerate() || !CGAL::coplanar(triangle[0], triangle[1], triangle[2], start) ||
        !CGAL::coplanar(triangle[0], triangle[1], triangle[2], second)) {
        return std::nullopt;
    }
    // t of a point of the overlap: (p - o) . d / (d . d), exactly, rounded once.
    auto t_of = [&](const Exact::Point_3& p) {
        return ((p - origin) * direction) / direction.squared_length();
    };
    std::optional<Exact::FT> nearest;
    auto consider = [&](const Exact::Point_3& p) {
        const Exact::FT t = t_of(p);
        if (!nearest || t < *nearest) nearest = t;
    };
    auto take = [&](const auto& overlap) {
        if (!overlap) return;
        if (const auto* point = boost::get<Exact::Point_3>(&*overlap)) {
            consider(*point);
        } else if (const auto* segment = boost::get<Exact::Segment_3>(&*overlap)) {
            consider(segment->source());
            consider(segment->target());
        }
    };
    if (unbounded) {
        take(CGAL::intersection(Exact::Ray_3(start, direction), triangle));
    } else {
        take(CGAL::intersection(Exact::Segment_3(start, second), triangle));
    }
    if (!nearest) return std::nullopt;
    return std::clamp(CGAL::to_double(*nearest), ray.t_min, ray.t_max);
}

std::optional<CgalReference::Answer> CgalReference::nearest(const Ray& ray) const {
    std::optional<Answer> best;
    for (std::uint32_t primitive : intersected_primitives(ray)) {
        // A ray in the triangle's plane meets it in a segment: the near end, constructed
        // exactly. Otherwise the plane's t in long double.
        const std::optional<double> in_plane = in_plane_t(ray, primitive);
        const double rounded = in_plane ? *in_plane : static_cast<double>(plane_t(ray, primitive));
        if (!best || rounded < best->t) best = Answer{rounded, primitive};
    }
    return best;
}

std::optional<std::uint32_t> CgalReference::first_intersected_primitive(const Ray& ray) const {
    if (!is_valid(ray) || ray.t_min != 0.0 || ray.t_max != std::numeric_limits<double>::infinity())
        return std::nullopt;
    const auto hit = tree_->tree.first_intersected_primitive(
        Kernel::Ray_3(to_cgal(ray.origin),
                      Kernel::Vector_3(ray.direction.x(), ray.direction.y(), ray.direction.z())));
    if (!hit) return std::nullopt;
    return static_cast<std::uint32_t>(*hit - tree_->triangles.cbegin());
}

template CgalReference::CgalReference(const TriangleSet<float>&);
template CgalReference::CgalReference(const TriangleSet<double>&);

}  // namespace csgrt
