#include <cstdio>
#include <map>
#include <ostream>
#include <string>
#include <utility>

#include "command_line_internal.h"
#include "csgrt/render/cost_layers.h"

namespace csgrt::command_line {

void print_statistics(std::ostream& out, const Scene& scene, const RenderStats& stats,
                      const StageSeconds& stage_seconds, std::span<const CostLayer> layers) {
    auto row = [&out](const char* label, std::uint64_t count, const std::string& note = {}) {
        char line[160];
        std::snprintf(line, sizeof(line), "  %-28s %14llu  %s", label,
                      static_cast<unsigned long long>(count), note.c_str());
        std::string text = line;
        while (!text.empty() && text.back() == ' ') text.pop_back();
        out << text << '\n';
    };
    auto percent = [](std::uint64_t part, std::uint64_t whole) {
        char text[32];
        std::snprintf(text, sizeof(text), "%.1f%%", whole ? 100.0 * part / whole : 0.0);
        return std::string(text);
    };
    out << "Rays\n";
    row("camera", stats.primary_rays, percent(stats.primary_hits, stats.primary_rays) + " hit");
    row("shadow", stats.shadow_rays,
        percent(stats.shadow_rays_blocked, stats.shadow_rays) + " blocked");
    row("mirror and glass", stats.secondary_rays);
    row("total", stats.primary_rays + stats.shadow_rays + stats.secondary_rays);
    out << "Camera-ray hits by the top-level object's shape\n";
    std::map<std::string, std::pair<std::size_t, std::uint64_t>> kinds;  // objects, hits
    for (std::size_t i = 0; i < scene.objects().size(); ++i) {
        auto& kind = kinds[std::string(scene.objects()[i].shape->kind())];
        ++kind.first;
        if (i < stats.hits_per_object.size()) kind.second += stats.hits_per_object[i];
    }
    for (const auto& [kind, count] : kinds) {
        row(kind.c_str(), count.second,
            std::to_string(count.first) + (count.first == 1 ? " object" : " objects"));
    }
    out << "Top-level structure (" << scene.accelerator_name() << "), centre rays\n";
    row("nodes or cells visited", stats.centre_ray_work.nodes_visited);
    row("primitives tested", stats.centre_ray_work.primitives_tested);
    row("boxes tested", stats.centre_ray_work.boxes_tested);
    out << "Leaf shapes by kind: root solves (centre rays), camera-ray hits\n";
    std::map<std::string, std::pair<std::uint64_t, std::uint64_t>> leaves;  // solves, hits
    for (const auto& [kind, solves] : stats.solves_by_kind) leaves[kind].first = solves;
    for (const auto& [kind, hits] : stats.hits_by_leaf_kind) leaves[kind].second = hits;
    for (const auto& [kind, counts] : leaves) {
        row(kind.c_str(), counts.first, std::to_string(counts.second) + " hits");
    }
    out << "Every level (structures in meshes and compounds, CSG nodes, leaves), centre rays\n";
    row("box tests", stats.centre_ray_cost.nodes);
    row("primitive tests", stats.centre_ray_cost.primitives);
    row("root solves", stats.centre_ray_cost.solves);
    row("total", stats.centre_ray_cost.total());
    if (!layers.empty()) {
        out << "Every structure at every level (--cost-all), centre rays\n";
        for (const CostLayer& layer : layers) {
            char note[96];
            std::snprintf(note, sizeof(note), "built in %.3f ms, traced in %.3f s",
                          layer.build_milliseconds, layer.trace_milliseconds / 1000.0);
            row(layer.structure.c_str(), cost_sum(layer), note);
        }
    }
    out << "Time\n";
    for (const auto& [stage, seconds] : stage_seconds) {
        char line[96];
        std::snprintf(line, sizeof(line), "  %-28s %14.3f s\n", stage, seconds);
        out << line;
    }
}

}  // namespace csgrt::command_line
