// The report files of a full run: report.md (its sections: meshes, threads, build, scaling,
// targets, accuracy, CSG) and report.json, the tables the plots are drawn from.

#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "csgrt/bench/statistics.h"
#include "report_format.h"

namespace csgrt::bench {

namespace {

using Json = nlohmann::json;

/// A Markdown table: a header row, then rows of cells.
class Table {
public:
    explicit Table(std::vector<std::string> header) : header_(std::move(header)) {}
    void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
    bool empty() const { return rows_.empty(); }
    std::string markdown() const {
        std::ostringstream out;
        auto line = [&](const std::vector<std::string>& cells) {
            out << "|";
            for (const std::string& cell : cells) out << " " << cell << " |";
            out << "\n";
        };
        line(header_);
        out << "|";
        for (std::size_t i = 0; i < header_.size(); ++i) out << (i == 0 ? "---|" : "---:|");
        out << "\n";
        for (const auto& row : rows_) line(row);
        return out.str();
    }

private:
    std::vector<std::string> header_;
    std::vector<std::vector<std::string>> rows_;
};

std::vector<std::string> subjects(const std::vector<Result>& results, const std::string& section) {
    std::vector<std::string> names;
    for (const Result& result : results) {
        if (result.info.section == section &&
            std::find(names.begin(), names.end(), result.info.subject) == names.end()) {
            names.push_back(result.info.subject);
        }
    }
    return names;
}

/// Triangles of a generated armadillo level ("armadillo-208000"), or of a traced real mesh.
double triangles_of(const std::vector<Result>& results, const std::string& mesh) {
    for (const Result& result : results) {
        if (result.info.subject == mesh && !std::isnan(result.counter("triangles"))) {
            return result.counter("triangles");
        }
    }
    return std::numeric_limits<double>::quiet_NaN();
}

/// The armadillo family by size: the generated levels and the armadillo itself.
std::vector<std::pair<double, std::string>> scaling_meshes(const std::vector<Result>& results) {
    std::vector<std::pair<double, std::string>> meshes;
    for (const std::string& mesh : subjects(results, "trace")) {
        if (mesh == "armadillo" || mesh.rfind("armadillo-", 0) == 0) {
            const double triangles = triangles_of(results, mesh);
            if (std::isfinite(triangles)) meshes.emplace_back(triangles, mesh);
        }
    }
    std::sort(meshes.begin(), meshes.end());
    return meshes;
}

double build_milliseconds(const std::vector<Result>& results, const std::string& mesh,
                          const std::string& variant, int threads) {
    const Result* result = find_result(results, "build", mesh, variant, "", threads);
    return result != nullptr ? result->seconds * 1e3 : std::numeric_limits<double>::quiet_NaN();
}

std::string header(const RunContext& context) {
    std::ostringstream out;
    out << "# csgrt_bench report\n\n"
        << "| | |\n|---|---|\n"
        << "| date | " << context.date << " |\n"
        << "| machine | " << context.machine << ", " << context.cores << " hardware threads |\n"
        << "| commit | " << context.commit << " |\n"
        << "| mode | " << context.mode << " (" << context.settings << ") |\n"
        << "| threads | 1 and " << context.threads << " (\"all\") |\n"
        << "| peers in this run | CGAL 5.5 AABB tree (Epick), " << context.embree << " |\n"
        << "| load average | before " << context.load_before << "; after " << context.load_after
        << " |\n\n"
        << "One-thread figures are the thread's CPU time (other processes on a shared machine "
           "barely disturb them); several-thread figures are wall time. Ratios compare numbers "
           "of this run only. csgrt is compiled without -march=native (SSE2); Embree picks its "
           "own vector ISA at run time.\n\n";
    return out.str();
}

void mesh_section(std::ostream& out, Json& json, const std::vector<Result>& results) {
    out << "## Structures on the real meshes (one thread)\n\n"
        << "Mrays/s of the nearest-hit query (camera, incoherent) and the occlusion query "
           "(shadow); brute force traces an evenly spread subset. Speedups are over brute force, "
           "CGAL and Embree on the same rays in this run. Bytes: the structure alone, then with "
           "the triangles it needs. Nodes and primitives per ray: counted queries on a sample "
           "of the camera rays.\n\n";
    for (const std::string& mesh : subjects(results, "trace")) {
        if (mesh.rfind("armadillo-", 0) == 0) continue;
        out << "### " << mesh << " (" << format_number(triangles_of(results, mesh))
            << " triangles)\n\n";
        Table table({"variant", "camera", "incoherent", "shadow", "x brute (cam / inc)",
                     "x CGAL (cam / inc)", "x Embree (cam / inc)", "build ms", "bytes/tri",
                     "with triangles", "nodes/ray", "prims/ray"});
        for (const std::string& variant : traced_variants(results, mesh, true)) {
            auto rate = [&](const std::string& rays) {
                return trace_rate(results, mesh, variant, rays, 1);
            };
            auto ratio = [&](const std::string& peer) {
                return format_ratio(rate("camera") / trace_rate(results, mesh, peer, "camera", 1)) +
                       " / " +
                       format_ratio(rate("incoherent") /
                                    trace_rate(results, mesh, peer, "incoherent", 1));
            };
            const Result* camera = find_result(results, "trace", mesh, variant, "camera", 1);
            auto counter = [&](const char* key) {
                return camera != nullptr ? format_number(camera->counter(key)) : "–";
            };
            table.add({variant, format_number(rate("camera") * 1e-6),
                       format_number(rate("incoherent") * 1e-6),
                       format_number(rate("shadow") * 1e-6), ratio("brute"), ratio("cgal"),
                       ratio("embree"), counter("build_ms"), counter("bytes_per_tri"),
                       counter("total_bytes_per_tri"), counter("nodes_per_ray"),
                       counter("prims_per_ray")});
            Json row = {{"mesh", mesh}, {"variant", variant}};
            for (const char* rays : {"camera", "incoherent", "shadow"}) {
                const double r = rate(rays);
                row[std::string(rays) + "_mrays"] = std::isfinite(r) ? Json(r * 1e-6) : Json();
            }
            json["meshes"].push_back(row);
        }
        out << table.markdown() << "\n";
    }
}

/// The wall-time speedup of `result` (at several threads) over the same benchmark on one
/// thread. CSG frames are manual time, so their one-thread wall time is the "wall_ms" counter.
double thread_scaling(const std::vector<Result>& results, const Result& result) {
    const BenchmarkInfo& info = result.info;
    const Result* one =
        find_result(results, info.section, info.subject, info.variant, info.rays, 1);
    if (one == nullptr) return std::numeric_limits<double>::quiet_NaN();
    const double one_wall =
        info.section == "csg" ? one->counter("wall_ms") * 1e-3 : one->wall_seconds;
    return one_wall / result.wall_seconds;
}

void threads_section(std::ostream& out, const std::vector<Result>& results, int threads) {
    if (threads <= 1) return;
    Table table({"mesh", "variant", "rays", "1 thread Mrays/s (CPU)",
                 std::to_string(threads) + " threads Mrays/s (wall)", "scaling (wall / wall)",
                 ">= 1.8x"});
    for (const Result& result : results) {
        const BenchmarkInfo& info = result.info;
        if (info.section != "trace" || info.threads != threads) continue;
        const double one = trace_rate(results, info.subject, info.variant, info.rays, 1);
        const double all = result.counter("rays");
        const double scaling = thread_scaling(results, result);
        table.add({info.subject, info.variant, info.rays, format_number(one * 1e-6),
                   format_number(all * 1e-6), format_ratio(scaling),
                   scaling >= 1.8 ? "yes" : "no"});
    }
    if (table.empty()) return;
    out << "## Threads\n\nThe ray set split over " << threads
        << " std::threads (blocks of 256 rays from a shared counter). The scaling is wall time "
           "of one thread over wall time of "
        << threads
        << ", both measured in this run; on a machine shared with other work (see the load "
           "average above) both suffer and the scaling shown is a lower bound.\n\n"
        << table.markdown() << "\n";
}

void build_section(std::ostream& out, const std::vector<Result>& results, int threads) {
    Table table({"mesh", "variant", "triangles", "1 thread ms",
                 std::to_string(threads) + " threads ms", "bytes/tri", "with triangles"});
    for (const std::string& mesh : subjects(results, "build")) {
        std::vector<std::string> variants;
        for (const Result& result : results) {
            if (result.info.section == "build" && result.info.subject == mesh &&
                std::find(variants.begin(), variants.end(), result.info.variant) ==
                    variants.end()) {
                variants.push_back(result.info.variant);
            }
        }
        for (const std::string& variant : variants) {
            const Result* one = find_result(results, "build", mesh, variant, "", 1);
            table.add({mesh, variant, format_number(triangles_of(results, mesh)),
                       format_number(build_milliseconds(results, mesh, variant, 1)),
                       format_number(build_milliseconds(results, mesh, variant, threads)),
                       one != nullptr ? format_number(one->counter("bytes_per_tri")) : "–",
                       one != nullptr ? format_number(one->counter("total_bytes_per_tri")) : "–"});
        }
    }
    if (table.empty()) return;
    out << "## Builds\n\nBuild time measured by rebuilding (one thread: process CPU time, "
           "so work on TBB or Embree threads counts; all threads: wall time). rayclass "
           "subdivides lazily while tracing, so its build is only the root.\n\n"
        << table.markdown() << "\n";
}

void scaling_section(std::ostream& out, Json& json, const std::vector<Result>& results) {
    const auto meshes = scaling_meshes(results);
    if (meshes.size() < 2) return;
    out << "## Scaling with the number of triangles\n\nThe armadillo decimated and Loop "
           "subdivided (data/generate-meshes), the same camera and incoherent rays, one thread. "
           "k is the exponent of time ~ N^k fitted by least squares on log-log (query time per "
           "ray, build time).\n\n![scaling](scaling.png)\n\n";
    std::vector<std::string> variants;
    for (const auto& [n, mesh] : meshes) {
        for (const std::string& variant : traced_variants(results, mesh, false)) {
            if (variant == "brute-boxes") continue;
            if (std::find(variants.begin(), variants.end(), variant) == variants.end()) {
                variants.push_back(variant);
            }
        }
    }
    std::vector<std::string> head = {"variant", "quantity"};
    for (const auto& [n, mesh] : meshes) head.push_back(format_number(n));
    head.push_back("k");
    Table table(head);
    for (const std::string& variant : variants) {
        Json series = {{"variant", variant}};
        for (const std::string quantity : {"camera", "incoherent", "build"}) {
            std::vector<double> n, value;
            std::vector<std::string> row = {
                variant, quantity == "build" ? "build ms" : quantity + " ns/ray"};
            for (const auto& [triangles, mesh] : meshes) {
                const double v = quantity == "build"
                                     ? build_milliseconds(results, mesh, variant, 1)
                                     : 1e9 / trace_rate(results, mesh, variant, quantity, 1);
                row.push_back(format_number(v));
                if (std::isfinite(v)) {
                    n.push_back(triangles);
                    value.push_back(v);
                    series[quantity].push_back({triangles, v});
                }
            }
            const PowerFit fit = fit_power_law(n, value);
            row.push_back(fit.valid ? format_number(fit.exponent) : "–");
            if (fit.valid) {
                series["fit"][quantity] = {{"exponent", fit.exponent},
                                           {"coefficient", fit.coefficient},
                                           {"r_squared", fit.r_squared}};
            }
            if (!n.empty()) table.add(row);
        }
        json["scaling"].push_back(series);
    }
    out << table.markdown() << "\n";
}

/// A floor as the issues write it: 5, 0.5, 100.
std::string format_floor(double floor) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", floor);
    return text;
}

/// One floor from the issues: the worst measured value against it.
struct Target {
    Target(std::string text_, double floor_, bool ceiling_ = false)
        : text(std::move(text_)), floor(floor_), ceiling(ceiling_) {}

    std::string text;
    double floor = 0.0;
    /// True when smaller is better (memory, build time): the floor is then a ceiling.
    bool ceiling = false;
    double worst = std::numeric_limits<double>::quiet_NaN();
    std::string where;

    void measure(double value, const std::string& place) {
        if (!std::isfinite(value)) return;
        const bool worse = !std::isfinite(worst) || (ceiling ? value > worst : value < worst);
        if (worse) {
            worst = value;
            where = place;
        }
    }
    std::string verdict() const {
        if (!std::isfinite(worst)) return "not measured in this run";
        const bool met = ceiling ? worst <= floor : worst >= floor;
        if (met) return "met";
        const double shortfall = ceiling ? worst / floor - 1.0 : 1.0 - worst / floor;
        return "short by " + format_number(100.0 * shortfall) + "%";
    }
};

void targets_section(std::ostream& out, Json& json, const std::vector<Result>& results,
                     int threads) {
    std::vector<Target> targets;
    const auto meshes = scaling_meshes(results);
    for (const auto& [peer, floor] :
         std::vector<std::pair<std::string, double>>{{"cgal", 5.0}, {"embree", 0.5}}) {
        Target target{"bvh >= " + format_floor(floor) + "x " + peer +
                          ", one thread, camera and incoherent, 10^4 to 10^7 triangles",
                      floor};
        for (const auto& [n, mesh] : meshes) {
            if (n < 9000) continue;
            for (const std::string rays : {"camera", "incoherent"}) {
                target.measure(trace_rate(results, mesh, "bvh", rays, 1) /
                                   trace_rate(results, mesh, peer, rays, 1),
                               mesh + " " + rays);
            }
        }
        targets.push_back(target);
    }
    for (const std::string structure : {"grid", "hgrid", "rayclass"}) {
        for (const auto& [peer, floor] :
             std::vector<std::pair<std::string, double>>{{"cgal", 2.0}, {"brute", 100.0}}) {
            Target target{structure + " >= " + format_floor(floor) + "x " + peer +
                              " on the armadillo (camera, incoherent)",
                          floor};
            for (const std::string rays : {"camera", "incoherent"}) {
                target.measure(trace_rate(results, "armadillo", structure, rays, 1) /
                                   trace_rate(results, "armadillo", peer, rays, 1),
                               rays);
            }
            targets.push_back(target);
        }
    }
    Target memory{"bvh memory <= 80 bytes/triangle (the structure; the float triangles add 36)",
                  80.0, true};
    // The build floor names no thread count: it is judged on the run's "all threads" build
    // (wall time); the one-thread build is in the Builds table.
    Target build{"bvh build of 3.3M triangles < 1 s (" + std::to_string(threads) + " thread" +
                     (threads > 1 ? "s" : "") + ")",
                 1000.0, true};
    for (const Result& result : results) {
        if (result.info.variant != "bvh") continue;
        if (result.info.section == "trace" && result.info.threads == 1) {
            memory.measure(result.counter("bytes_per_tri"), result.info.subject);
        }
        const double n = result.counter("triangles");
        if (result.info.section == "build" && result.info.threads == threads && n > 3e6 &&
            n < 4e6) {
            build.measure(result.seconds * 1e3, std::to_string(result.info.threads) + " thread" +
                                                    (result.info.threads > 1 ? "s" : ""));
        }
    }
    targets.push_back(memory);
    targets.push_back(build);
    if (threads > 1) {
        Target scaling{std::to_string(threads) + " threads >= 1.8x one thread", 1.8};
        for (const Result& result : results) {
            const BenchmarkInfo& info = result.info;
            if (info.section != "trace" || info.threads != threads) continue;
            scaling.measure(thread_scaling(results, result),
                            info.subject + " " + info.variant + " " + info.rays);
        }
        targets.push_back(scaling);
    }
    Table table({"target", "worst measured", "where", "verdict"});
    for (const Target& target : targets) {
        const bool ratio = !target.ceiling;
        table.add({target.text, ratio ? format_ratio(target.worst) : format_number(target.worst),
                   target.where.empty() ? "–" : target.where, target.verdict()});
        json["targets"].push_back(
            {{"target", target.text},
             {"worst", std::isfinite(target.worst) ? Json(target.worst) : Json()},
             {"where", target.where},
             {"verdict", target.verdict()}});
    }
    out << "## Targets\n\nThe floors the issues set, each with the worst case measured in this "
           "run.\n\n"
        << table.markdown() << "\n";
}

/// The accuracy groups' error metrics: the two each group's Pareto fronts are drawn for.
const std::map<std::string, std::vector<std::string>>& accuracy_metrics() {
    static const std::map<std::string, std::vector<std::string>> metrics = {
        {"triangles", {"wrong", "t_err_p99"}},
        {"quartic", {"wrong", "t_err_p99"}},
        {"decimation", {"colour_rmse", "depth_rmse"}}};
    return metrics;
}

void accuracy_section(std::ostream& out, Json& json, const std::vector<Result>& results) {
    const std::vector<std::string> groups = subjects(results, "accuracy");
    if (groups.empty()) return;
    out << "## Run time against error\n\nEach variant timed on one thread and judged against "
           "the exact or higher-precision reference on the same rays. wrong: the fraction of "
           "rays answered hit where the reference misses or the reverse, or a hit on another "
           "surface (relative t error above 1e-4: a crack or a rejected triangle let the ray "
           "through). t error: |t - t_ref| / t_ref over the rays answered right. * marks the "
           "Pareto front (no variant both faster and at most as wrong) of time against each "
           "error.\n\n"
        << "- triangles: brute force over the armadillo decimated to 1/10 with the library's "
           "watertight test (Woop et al. 2013) and with Moeller-Trumbore (1997, as published, "
           "in bench/), each in float and double; camera rays and rays aimed at vertices and "
           "edge points whose triangles all face the camera; reference: CGAL's exact "
           "predicates.\n"
        << "- quartic: a torus (R = 1, r = 0.25), rays from ten radii away and grazing rays "
           "offset 1e-14 to 1e-4 r from tangency; the quartic around the line's point nearest "
           "the centre solved by bracketing and by the closed form, the closed form on the "
           "quartic at the ray's origin (textbook), and the Torus shape; reference: the same "
           "quartic in long double.\n"
        << "- decimation: the armadillo and its decimations (mesh_tools' decimate) traced with "
           "the default structure; reference: the full mesh's exact nearest hits; depth RMSE in "
           "units of the mesh's diagonal over pixels both hit, colour RMSE of a grey "
           "|cos(angle)| shade over all pixels.\n\n![time against error](accuracy.png)\n\n";
    for (const std::string& group : groups) {
        std::vector<const Result*> rows;
        for (const Result& result : results) {
            if (result.info.section == "accuracy" && result.info.subject == group &&
                !result.failed) {
                rows.push_back(&result);
            }
        }
        const auto& metrics = accuracy_metrics().at(group);
        std::vector<std::vector<bool>> fronts;
        for (const std::string& metric : metrics) {
            std::vector<CostError> points;
            for (const Result* row : rows) {
                points.push_back({1e9 / row->counter("rays"), row->counter(metric)});
            }
            fronts.push_back(pareto_front(points));
        }
        std::vector<std::string> head = {"variant", "ns/ray"};
        if (group == "decimation")
            head.insert(head.end(), {"triangles", "colour RMSE", "depth RMSE"});
        head.insert(head.end(), {"wrong", "t err median", "t err p99", "t err max"});
        for (const std::string& metric : metrics) head.push_back("front: " + metric);
        Table table(head);
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Result& row = *rows[i];
            const double time = 1e9 / row.counter("rays");
            std::vector<std::string> cells = {row.info.variant, format_number(time)};
            if (group == "decimation") {
                cells.insert(cells.end(), {format_number(row.counter("triangles")),
                                           format_number(row.counter("colour_rmse")),
                                           format_number(row.counter("depth_rmse"))});
            }
            cells.insert(
                cells.end(),
                {format_number(row.counter("wrong")), format_number(row.counter("t_err_median")),
                 format_number(row.counter("t_err_p99")), format_number(row.counter("t_err_max"))});
            Json point = {{"group", group}, {"variant", row.info.variant}, {"ns_per_ray", time}};
            for (const auto& [key, value] : row.counters) point[key] = value;
            for (std::size_t m = 0; m < metrics.size(); ++m) {
                cells.push_back(fronts[m][i] ? "*" : "");
                point["pareto"][metrics[m]] = static_cast<bool>(fronts[m][i]);
            }
            table.add(cells);
            json["accuracy"].push_back(point);
        }
        out << "### " << group << "\n\n" << table.markdown() << "\n";
    }
}

void csg_section(std::ostream& out, Json& json, const std::vector<Result>& results, int threads) {
    Table table({"scene", "structure", "threads", "objects", "ms/frame", "Mrays/s", "x brute",
                 "x 1 thread (wall)", "objects/ray", "boxes/ray", "nodes/ray", "rendered"});
    for (const Result& result : results) {
        const BenchmarkInfo& info = result.info;
        if (info.section != "csg" || result.failed) continue;
        const Result* brute = find_result(results, "csg", info.subject, "brute", "frame", 1);
        const Result* one = find_result(results, "csg", info.subject, info.variant, "frame", 1);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const double over_brute =
            info.threads == 1 && brute != nullptr ? brute->seconds / result.seconds : nan;
        const double over_one =
            info.threads > 1 && one != nullptr ? thread_scaling(results, result) : nan;
        const double rendered = result.counter("rendered_width");
        table.add({info.subject, info.variant, std::to_string(info.threads),
                   std::to_string(std::llround(result.counter("objects"))),
                   format_number(result.seconds * 1e3),
                   format_number(result.counter("rays") * 1e-6), format_ratio(over_brute),
                   format_ratio(over_one), format_number(result.counter("objects_per_ray")),
                   format_number(result.counter("boxes_per_ray")),
                   format_number(result.counter("nodes_per_ray")),
                   std::to_string(std::llround(rendered)) + "x" +
                       std::to_string(std::llround(rendered))});
        json["csg"].push_back({{"scene", info.subject},
                               {"structure", info.variant},
                               {"threads", info.threads},
                               {"frame_ms", result.seconds * 1e3},
                               {"objects_per_ray", result.counter("objects_per_ray")},
                               {"boxes_per_ray", result.counter("boxes_per_ray")},
                               {"rendered_width", rendered}});
    }
    if (table.empty()) return;
    out << "## CSG scenes\n\nEach scene of data/scenes/ rendered by the library's renderer "
           "(one sample a pixel, Lambert, one hard shadow ray a light), its top-level objects "
           "under each structure: brute is the scene without hierarchical bounding boxes (every "
           "object on every ray), the others a hierarchy of boxes or cells over them. ms/frame "
           "is for the full square frame (one thread: process CPU time; "
        << threads
        << " threads: wall time); where brute force would exceed the run's budget of object "
           "tests it renders a smaller frame of the same view (\"rendered\") and its time is "
           "scaled by the ratio of pixels. objects/ray, boxes/ray, nodes/ray: the top-level "
           "structure's work on a sample of camera rays (Scene::intersect_counted); the work "
           "inside a CSG object or a mesh is not counted there.\n\n"
        << table.markdown() << "\n";
}

}  // namespace

void write_report(const std::filesystem::path& directory, const std::vector<Result>& results,
                  const RunContext& context) {
    std::filesystem::create_directories(directory);
    Json json;
    json["context"] = {{"date", context.date},
                       {"machine", context.machine},
                       {"cores", context.cores},
                       {"threads", context.threads},
                       {"commit", context.commit},
                       {"mode", context.mode},
                       {"embree", context.embree},
                       {"load_before", context.load_before},
                       {"load_after", context.load_after}};
    std::ostringstream out;
    out << header(context);
    out << "## Summary\n\nArmadillo, one thread, camera and incoherent rays.\n\n```\n"
        << summary_table(results, "armadillo") << "```\n\n";
    for (const std::string& variant : traced_variants(results, "armadillo", false)) {
        json["summary"].push_back(
            {{"variant", variant},
             {"camera", trace_rate(results, "armadillo", variant, "camera", 1)},
             {"incoherent", trace_rate(results, "armadillo", variant, "incoherent", 1)}});
    }
    mesh_section(out, json, results);
    threads_section(out, results, context.threads);
    build_section(out, results, context.threads);
    scaling_section(out, json, results);
    csg_section(out, json, results, context.threads);
    targets_section(out, json, results, context.threads);
    accuracy_section(out, json, results);
    std::ofstream(directory / "report.md") << out.str();
    std::ofstream(directory / "report.json") << json.dump(1) << "\n";
}

}  // namespace csgrt::bench
