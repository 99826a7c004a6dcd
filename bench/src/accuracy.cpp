// Run time against error: each variant that trades accuracy for speed, timed and judged
// against an exact or higher-precision reference on the same rays.
//   triangles:  watertight (the library's) against Moeller-Trumbore, each in float and double,
//               by brute force over every triangle, against CGAL's exact predicates;
//   quartic:    the torus quartic solved by bracketing and by the closed form, and the Torus
//               shape (shifted quartic, tangencies decided, roots polished), against long
//               double;
//   decimation: the armadillo at 1/10 and 1/100 of its triangles against the full mesh's
//               exact nearest hits, with image errors of depth and of a shaded grey.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "benchmarks.h"
#include "csgrt/accel/factory.h"
#include "csgrt/mesh/mesh_tools.h"
#include "csgrt/bench/moller_trumbore.h"
#include "csgrt/bench/statistics.h"
#include "csgrt/core/polynomial.h"
#include "csgrt/core/torus.h"
#include "peers.h"
#include "report.h"

namespace csgrt::bench {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A variant's answer for one ray: hit or not, and t.
struct Answer {
    bool hit = false;
    double t = 0.0;
};

/// How a variant's answers differ from the reference's.
struct ErrorSummary {
    /// Fraction of rays answered wrongly: hit where the reference misses or the reverse, or a
    /// hit on another surface (relative t error above the group's surface threshold).
    double wrong = 0.0;
    /// |t - t_ref| / |t_ref| over the rays both hit on the same surface.
    Quantiles t_error;
    /// Image errors (decimation only).
    double depth_rmse = kNaN;
    double colour_rmse = kNaN;
};

/// Compares answers with the reference's; a relative t error above `other_surface` means the
/// variant hit another surface (a crack let the ray through, a tiny triangle was rejected).
ErrorSummary compare(std::span<const Answer> answers, std::span<const Answer> reference,
                     double other_surface) {
    ErrorSummary summary;
    std::vector<double> errors;
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < answers.size(); ++i) {
        if (answers[i].hit != reference[i].hit) {
            ++wrong;
        } else if (answers[i].hit) {
            const double error = std::abs(answers[i].t - reference[i].t) / std::abs(reference[i].t);
            if (error > other_surface) {
                ++wrong;
            } else {
                errors.push_back(error);
            }
        }
    }
    summary.wrong =
        answers.empty() ? 0.0 : static_cast<double>(wrong) / static_cast<double>(answers.size());
    summary.t_error = quantiles(std::move(errors));
    return summary;
}

// Float triangles put hits within about 1e-6 (relative) of the exact point even at grazing
// incidence; a hit 1e-4 away is on another surface.
constexpr double kOtherSurface = 1e-4;

void set_error_counters(benchmark::State& state, const ErrorSummary& summary) {
    state.counters["wrong"] = summary.wrong;
    state.counters["t_err_median"] = summary.t_error.median;
    state.counters["t_err_p99"] = summary.t_error.p99;
    state.counters["t_err_max"] = summary.t_error.max;
    if (!std::isnan(summary.depth_rmse)) state.counters["depth_rmse"] = summary.depth_rmse;
    if (!std::isnan(summary.colour_rmse)) state.counters["colour_rmse"] = summary.colour_rmse;
}

void register_accuracy(const std::string& group, const std::string& variant,
                       std::function<void(benchmark::State&)> body) {
    const std::string name = "accuracy/" + group + "/" + variant;
    register_info(name, {"accuracy", group, variant, group, 1});
    benchmark::RegisterBenchmark(name.c_str(), std::move(body))->Unit(benchmark::kMicrosecond);
}

// ---------------------------------------------------------------------------------------------
// Triangles: the watertight test against Moeller-Trumbore, float and double.

/// The decimated armadillo at 1/divisor of its triangles, made once.
class DecimatedMeshes {
public:
    explicit DecimatedMeshes(Workloads& workloads) : workloads_(workloads) {}

    const TriangleMeshData& full() { return workloads_.get("armadillo").data(); }
    const TriangleMeshData& at(int divisor) {
        auto found = meshes_.find(divisor);
        if (found == meshes_.end()) {
            const TriangleMeshData& source = full();
            found =
                meshes_.emplace(divisor, decimate(source, source.triangles.size() / divisor)).first;
        }
        return found->second;
    }

private:
    Workloads& workloads_;
    std::map<int, TriangleMeshData> meshes_;
};

/// The rays the triangle tests are judged on: camera rays, and rays from the camera aimed
/// exactly at vertices and at points of edges where every triangle around faces the camera, so
/// the exact answer is a hit on that point or on something nearer: a miss, or a hit farther
/// on, is a crack between triangles.
struct TriangleRays {
    std::vector<Ray> camera;
    std::vector<Ray> edges;
};

TriangleRays triangle_rays(const TriangleMeshData& mesh, const Settings& settings) {
    Aabb box;
    for (const auto& v : mesh.vertices) box.extend(v);
    const Camera camera = framing_camera(box);
    TriangleRays rays;
    const RaySet image = camera_rays(camera, settings.accuracy_width, settings.accuracy_width);
    rays.camera = spread_subset(image.rays, settings.accuracy_rays);

    const std::size_t count = mesh.triangles.size();
    std::vector<bool> facing(count);
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edge_triangles;
    std::vector<std::vector<std::uint32_t>> vertex_triangles(mesh.vertices.size());
    for (std::uint32_t i = 0; i < count; ++i) {
        const auto& t = mesh.triangles[i];
        const Vector3 normal = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                   .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
        facing[i] = normal.dot(camera.position - mesh.vertices[t[0]]) > 0.0;
        for (int k = 0; k < 3; ++k) {
            edge_triangles[std::minmax(t[k], t[(k + 1) % 3])].push_back(i);
            vertex_triangles[t[k]].push_back(i);
        }
    }
    auto all_facing = [&](const std::vector<std::uint32_t>& triangles) {
        return !triangles.empty() &&
               std::all_of(triangles.begin(), triangles.end(), [&](auto i) { return facing[i]; });
    };
    SplitMix random(0xed9e5);
    for (std::size_t attempt = 0;
         rays.edges.size() < settings.accuracy_rays && attempt < 1000 * settings.accuracy_rays;
         ++attempt) {
        const auto& triangle = mesh.triangles[random.next_bits() % count];
        const int corner = static_cast<int>(random.next_bits() % 3);
        const std::uint32_t a = triangle[corner], b = triangle[(corner + 1) % 3];
        // Every other ray through a vertex, the rest through a point of an edge.
        const bool vertex = rays.edges.size() % 2 == 0;
        if (!all_facing(vertex ? vertex_triangles[a] : edge_triangles[std::minmax(a, b)])) {
            continue;
        }
        const Point3 target =
            vertex ? mesh.vertices[a]
                   : mesh.vertices[a] + random.uniform() * (mesh.vertices[b] - mesh.vertices[a]);
        Ray ray;
        ray.origin = camera.position;
        ray.direction = target - camera.position;
        rays.edges.push_back(ray);
    }
    return rays;
}

/// Nearest hit by brute force with the library's watertight test (TriangleSet<Real>).
template <class Real>
Answer watertight_nearest(const TriangleSet<Real>& set, const Ray& ray, QueryScratch& scratch) {
    const auto prepared = set.prepare(ray, scratch);
    HitRecord record;
    record.t = ray.t_max;
    bool found = false;
    for (std::size_t i = 0; i < set.size(); ++i) found |= set.intersect(i, prepared, record);
    return {found, record.t};
}

/// Corners in Real, laid out as TriangleSet stores them, for the Moeller-Trumbore loop.
template <class Real>
using Corners = std::vector<std::array<Eigen::Matrix<Real, 3, 1>, 3>>;

template <class Real>
Corners<Real> corners_of(const TriangleMeshData& mesh) {
    Corners<Real> corners;
    corners.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles) {
        corners.push_back({mesh.vertices[t[0]].cast<Real>(), mesh.vertices[t[1]].cast<Real>(),
                           mesh.vertices[t[2]].cast<Real>()});
    }
    return corners;
}

template <class Real>
Answer moller_trumbore_nearest(const Corners<Real>& corners, const Ray& ray) {
    using Test = MollerTrumbore<Real>;
    auto prepared = Test::prepare(ray);
    Answer best;
    for (const auto& c : corners) {
        double t, u, v;
        if (Test::hit(c[0], c[1], c[2], prepared, t, u, v)) {
            best = {true, t};
            prepared.t_max = t;  // only nearer hits from here on
        }
    }
    return best;
}

struct TriangleCase {
    const TriangleMeshData* mesh = nullptr;
    TriangleRays rays;
    std::vector<Answer> exact_camera, exact_edges;
    std::unique_ptr<TriangleSet<float>> float_set;
    std::unique_ptr<TriangleSet<double>> double_set;
    Corners<float> float_corners;
    Corners<double> double_corners;
};

void register_triangle_variants(const std::shared_ptr<DecimatedMeshes>& meshes,
                                const Settings& settings) {
    auto shared = std::make_shared<std::optional<TriangleCase>>();
    // Made on first use: the tenth of the armadillo (brute force must stay affordable), its
    // rays, and the exact answers.
    auto prepare = [meshes, shared, settings]() -> TriangleCase& {
        if (!*shared) {
            TriangleCase& c = shared->emplace();
            c.mesh = &meshes->at(10);
            c.rays = triangle_rays(*c.mesh, settings);
            c.float_set = std::make_unique<TriangleSet<float>>(c.mesh->vertices, c.mesh->triangles);
            c.double_set =
                std::make_unique<TriangleSet<double>>(c.mesh->vertices, c.mesh->triangles);
            c.float_corners = corners_of<float>(*c.mesh);
            c.double_corners = corners_of<double>(*c.mesh);
            // The vertices were floats in the file, so both sets hold the same triangles and
            // one exact reference judges all four variants.
            const CgalReference reference(*c.double_set);
            for (const auto* list : {&c.rays.camera, &c.rays.edges}) {
                auto& exact = list == &c.rays.camera ? c.exact_camera : c.exact_edges;
                for (const Ray& ray : *list) {
                    const auto nearest = reference.nearest(ray);
                    exact.push_back(nearest ? Answer{true, nearest->t} : Answer{});
                }
            }
        }
        return **shared;
    };
    using Nearest = std::function<Answer(TriangleCase&, const Ray&, QueryScratch&)>;
    const std::vector<std::pair<std::string, Nearest>> variants = {
        {"watertight-float",
         [](TriangleCase& c, const Ray& ray, QueryScratch& scratch) {
             return watertight_nearest(*c.float_set, ray, scratch);
         }},
        {"watertight-double",
         [](TriangleCase& c, const Ray& ray, QueryScratch& scratch) {
             return watertight_nearest(*c.double_set, ray, scratch);
         }},
        {"mt-float", [](TriangleCase& c, const Ray& ray,
                        QueryScratch&) { return moller_trumbore_nearest(c.float_corners, ray); }},
        {"mt-double", [](TriangleCase& c, const Ray& ray, QueryScratch&) {
             return moller_trumbore_nearest(c.double_corners, ray);
         }}};
    for (const auto& [name, nearest] : variants) {
        register_accuracy("triangles", name, [prepare, nearest](benchmark::State& state) {
            TriangleCase& c = prepare();
            QueryScratch scratch;
            // Timed on a slice of the camera rays: every ray tests every triangle.
            const std::vector<Ray> timed = spread_subset(c.rays.camera, 256);
            for (auto _ : state) {
                std::size_t hits = 0;
                for (const Ray& ray : timed) hits += nearest(c, ray, scratch).hit ? 1 : 0;
                benchmark::DoNotOptimize(hits);
            }
            const auto tests = static_cast<double>(timed.size() * c.mesh->triangles.size());
            state.counters["rays"] = benchmark::Counter(
                static_cast<double>(timed.size()), benchmark::Counter::kIsIterationInvariantRate);
            state.counters["tests"] =
                benchmark::Counter(tests, benchmark::Counter::kIsIterationInvariantRate);
            state.counters["triangles"] = static_cast<double>(c.mesh->triangles.size());
            std::vector<Answer> camera, edges;
            for (const Ray& ray : c.rays.camera) camera.push_back(nearest(c, ray, scratch));
            for (const Ray& ray : c.rays.edges) edges.push_back(nearest(c, ray, scratch));
            std::vector<Answer> all = camera, exact = c.exact_camera;
            all.insert(all.end(), edges.begin(), edges.end());
            exact.insert(exact.end(), c.exact_edges.begin(), c.exact_edges.end());
            set_error_counters(state, compare(all, exact, kOtherSurface));
            state.counters["wrong_camera"] = compare(camera, c.exact_camera, kOtherSurface).wrong;
            state.counters["wrong_edges"] = compare(edges, c.exact_edges, kOtherSurface).wrong;
        });
    }
}

// ---------------------------------------------------------------------------------------------
// Quartic: the torus's quartic by each QuarticMethod, and the Torus shape.

constexpr double kMajor = 1.0;
constexpr double kMinor = 0.25;

/// The torus quartic along `ray`, in the distance s from the point of the line nearest the
/// centre (so its coefficients are of the torus's size), in Real; the nearest root with t >= 0
/// mapped back to t. `at_origin` builds it at the ray's origin instead (the textbook way).
template <class Real, class Solve>
Answer torus_quartic(const Ray& ray, bool at_origin, const Solve& solve) {
    using Vector = Eigen::Matrix<Real, 3, 1>;
    const Vector origin = ray.origin.cast<Real>();
    const Vector direction = ray.direction.cast<Real>();
    const Real length = direction.norm();
    const Vector unit = direction / length;
    const Real t_shift = at_origin ? Real(0) : -origin.dot(direction) / direction.squaredNorm();
    const Vector p = origin + t_shift * direction;
    const Real major2 = Real(kMajor * kMajor);
    const Real a = unit.squaredNorm();
    const Real b = p.dot(unit);
    const Real c = p.squaredNorm() + major2 - Real(kMinor * kMinor);
    const Real dxz = unit.x() * unit.x() + unit.z() * unit.z();
    const Real exz = p.x() * unit.x() + p.z() * unit.z();
    const Real fxz = p.x() * p.x() + p.z() * p.z();
    const Real coeffs[5] = {c * c - 4 * major2 * fxz, 4 * b * c - 8 * major2 * exz,
                            4 * b * b + 2 * a * c - 4 * major2 * dxz, 4 * a * b, a * a};
    // Surface points have |x| <= R + r, so |s| <= |p| + R + r; roots behind the origin
    // (t < 0) are of no interest.
    const Real reach = p.norm() + Real(kMajor + kMinor);
    const Real behind = -t_shift * length;
    Real roots[4];
    const int count = solve(coeffs, std::max(-reach, behind), reach, roots);
    for (int i = 0; i < count; ++i) {
        if (roots[i] >= behind) return {true, static_cast<double>(t_shift + roots[i] / length)};
    }
    return {};
}

std::vector<Ray> torus_rays(std::size_t count) {
    // Half from ten outer radii away, aimed at points within 1.5 minor radii of the core
    // circle (most hit, some pass through the hole); half grazing: tangent to the surface at a
    // random point, moved off it along the normal by 1e-14 to 1e-4 minor radii (log-uniform),
    // to either side, where a quartic's double root decides hit or miss.
    SplitMix random(0x7043);
    std::vector<Ray> rays;
    while (rays.size() < count) {
        const double phi = random.uniform(0.0, 2.0 * kPi);
        const Vector3 radial(std::sin(phi), 0.0, std::cos(phi));
        Ray ray;
        if (rays.size() % 2 == 0) {
            const Point3 target =
                kMajor * radial + 1.5 * kMinor * random.uniform() * random.unit_vector();
            ray.origin = 10.0 * (kMajor + kMinor) * random.unit_vector();
            ray.direction = target - ray.origin;
        } else {
            const double theta = random.uniform(0.0, 2.0 * kPi);
            const Vector3 normal = std::cos(theta) * radial + std::sin(theta) * Vector3::UnitY();
            const Point3 surface = kMajor * radial + kMinor * normal;
            // A random direction in the tangent plane.
            Vector3 tangent = random.unit_vector();
            tangent -= tangent.dot(normal) * normal;
            if (tangent.squaredNorm() < 1e-6) continue;
            tangent.normalize();
            const double offset = kMinor * std::pow(10.0, random.uniform(-14.0, -4.0)) *
                                  (random.uniform() < 0.5 ? -1.0 : 1.0);
            const double back = 3.0 * (kMajor + kMinor);
            ray.origin = surface + offset * normal - back * tangent;
            ray.direction = tangent;
        }
        rays.push_back(ray);
    }
    return rays;
}

void register_quartic_variants(const Settings& settings) {
    struct QuarticCase {
        std::vector<Ray> rays;
        std::vector<Answer> reference;
    };
    auto shared = std::make_shared<std::optional<QuarticCase>>();
    const std::size_t count = settings.accuracy_rays;
    auto prepare = [shared, count]() -> QuarticCase& {
        if (!*shared) {
            QuarticCase& c = shared->emplace();
            c.rays = torus_rays(count);
            for (const Ray& ray : c.rays) {
                c.reference.push_back(torus_quartic<long double>(
                    ray, false,
                    [](const long double* k, long double lo, long double hi, long double* r) {
                        return solve_quartic(k, lo, hi, r);
                    }));
            }
        }
        return **shared;
    };
    auto with = [](QuarticMethod method, bool at_origin) {
        return [method, at_origin](const Ray& ray) {
            return torus_quartic<double>(
                ray, at_origin, [method](const double* k, double lo, double hi, double* r) {
                    return solve_quartic(k, lo, hi, r, method);
                });
        };
    };
    const auto torus = std::make_shared<Torus>(kMajor, kMinor);
    using Solve = std::function<Answer(const Ray&)>;
    const std::vector<std::pair<std::string, Solve>> variants = {
        {"bracketing", with(QuarticMethod::kBracketing, false)},
        {"closed-form", with(QuarticMethod::kClosedForm, false)},
        {"closed-form-at-origin", with(QuarticMethod::kClosedForm, true)},
        {"torus-shape", [torus](const Ray& ray) {
             QueryScratch scratch;
             HitRecord record;
             return torus->nearest_hit(ray, record, scratch) ? Answer{true, record.t} : Answer{};
         }}};
    for (const auto& [name, solve] : variants) {
        register_accuracy("quartic", name, [prepare, solve](benchmark::State& state) {
            QuarticCase& c = prepare();
            for (auto _ : state) {
                std::size_t hits = 0;
                for (const Ray& ray : c.rays) hits += solve(ray).hit ? 1 : 0;
                benchmark::DoNotOptimize(hits);
            }
            state.counters["rays"] = benchmark::Counter(
                static_cast<double>(c.rays.size()), benchmark::Counter::kIsIterationInvariantRate);
            std::vector<Answer> answers;
            for (const Ray& ray : c.rays) answers.push_back(solve(ray));
            set_error_counters(state, compare(answers, c.reference, kOtherSurface));
        });
    }
}

// ---------------------------------------------------------------------------------------------
// Decimation: "why use so many polygons?"

struct Shaded {
    Answer answer;
    /// |cos| of the angle between the ray and the surface: a grey shade with a headlight.
    double grey = 0.0;
};

double shade(const Vector3& direction, const Vector3& normal) {
    return std::abs(direction.normalized().dot(normal.normalized()));
}

void register_decimation_variants(const std::shared_ptr<DecimatedMeshes>& meshes,
                                  Workloads& workloads, const Settings& settings) {
    struct DecimationCase {
        RaySet rays;
        std::vector<Shaded> reference;
        double diagonal = 1.0;
    };
    auto shared = std::make_shared<std::optional<DecimationCase>>();
    auto prepare = [shared, meshes, &workloads, settings]() -> DecimationCase& {
        if (!*shared) {
            DecimationCase& c = shared->emplace();
            MeshWorkload& full = workloads.get("armadillo");
            c.diagonal = full.box().diagonal().norm();
            c.rays = camera_rays(full.camera(), settings.accuracy_width, settings.accuracy_width);
            const CgalReference& reference = full.cgal();
            const TriangleSet<float>& set = full.float_set();
            for (const Ray& ray : c.rays.rays) {
                Shaded pixel;
                if (const auto nearest = reference.nearest(ray)) {
                    const Vector3 a = set.corner(nearest->primitive, 0).cast<double>();
                    const Vector3 b = set.corner(nearest->primitive, 1).cast<double>();
                    const Vector3 d = set.corner(nearest->primitive, 2).cast<double>();
                    pixel = {{true, nearest->t}, shade(ray.direction, (b - a).cross(d - a))};
                }
                c.reference.push_back(pixel);
            }
        }
        return **shared;
    };
    const std::string structure = fastest_structure();
    for (const int divisor : {1, 10, 100}) {
        const std::string name = divisor == 1 ? "full" : "1/" + std::to_string(divisor);
        register_accuracy(
            "decimation", name,
            [prepare, meshes, divisor, structure, settings](benchmark::State& state) {
                DecimationCase& c = prepare();
                const TriangleMeshData& mesh = divisor == 1 ? meshes->full() : meshes->at(divisor);
                const TriangleSet<float> set(mesh.vertices, mesh.triangles);
                // The fastest structure, or brute force on a bounded slice when none but brute
                // force is registered.
                const auto accelerator = make_accelerator(structure.empty() ? "brute" : structure,
                                                          set, AcceleratorConfig{});
                std::vector<Ray> timed = c.rays.rays;
                if (structure.empty()) {
                    timed = spread_subset(
                        c.rays.rays,
                        static_cast<std::size_t>(std::max(
                            16.0, settings.brute_budget / static_cast<double>(set.size()))));
                }
                const AcceleratorTracer<TriangleSet<float>> tracer(*accelerator);
                for (auto _ : state) {
                    benchmark::DoNotOptimize(trace_all(tracer, timed, false, 1));
                }
                state.counters["rays"] =
                    benchmark::Counter(static_cast<double>(timed.size()),
                                       benchmark::Counter::kIsIterationInvariantRate);
                state.counters["triangles"] = static_cast<double>(set.size());
                std::vector<Answer> answers, reference;
                double depth_sum = 0.0, colour_sum = 0.0;
                std::size_t depth_count = 0;
                QueryScratch scratch;
                // Without a fast structure the answers come from CGAL's exact nearest hit on
                // the same triangles (brute force over every pixel would take minutes).
                std::unique_ptr<CgalReference> exact;
                if (structure.empty()) exact = std::make_unique<CgalReference>(set);
                for (std::size_t i = 0; i < c.rays.rays.size(); ++i) {
                    const Ray& ray = c.rays.rays[i];
                    HitRecord record;
                    Shaded pixel;
                    bool hit = false;
                    if (exact) {
                        if (const auto nearest = exact->nearest(ray)) {
                            hit = true;
                            record.t = nearest->t;
                            record.primitive = nearest->primitive;
                        }
                    } else {
                        hit = accelerator->intersect(ray, record, scratch);
                    }
                    if (hit) {
                        const Vector3 a = set.corner(record.primitive, 0).cast<double>();
                        const Vector3 b = set.corner(record.primitive, 1).cast<double>();
                        const Vector3 d = set.corner(record.primitive, 2).cast<double>();
                        pixel = {{true, record.t}, shade(ray.direction, (b - a).cross(d - a))};
                    }
                    const Shaded& truth = c.reference[i];
                    answers.push_back(pixel.answer);
                    reference.push_back(truth.answer);
                    colour_sum += square(pixel.grey - truth.grey);
                    if (pixel.answer.hit && truth.answer.hit) {
                        // Depth in units of the mesh's size (unit camera directions).
                        depth_sum += square((pixel.answer.t - truth.answer.t) / c.diagonal);
                        ++depth_count;
                    }
                }
                // A coarser mesh is another surface by design: every hit counts in the t error.
                ErrorSummary summary = compare(answers, reference, kInfinity);
                summary.depth_rmse =
                    depth_count > 0 ? std::sqrt(depth_sum / static_cast<double>(depth_count)) : 0.0;
                summary.colour_rmse =
                    std::sqrt(colour_sum / static_cast<double>(c.rays.rays.size()));
                set_error_counters(state, summary);
            });
    }
}

}  // namespace

void register_accuracy_benchmarks(Workloads& workloads, const Settings& settings) {
    if (!workloads.has("armadillo")) return;
    auto meshes = std::make_shared<DecimatedMeshes>(workloads);
    register_triangle_variants(meshes, settings);
    register_quartic_variants(settings);
    register_decimation_variants(meshes, workloads, settings);
}

}  // namespace csgrt::bench
