// `csgrt info`'s counts of a loaded scene, memoised so shared subtrees cost nothing to count
// again.

#include <map>
#include <unordered_map>

#include "csgrt/csg/scene_file.h"
#include "csgrt/mesh/mesh.h"
#include "limits.h"

namespace csgrt {

namespace {

using detail::scene_file::saturating_add;

/// One distinct shape's counts over its expansion.
struct NodeCounts {
    std::map<std::string_view, std::uint64_t> kinds;
    std::uint64_t leaves = 0;
    std::uint64_t triangles = 0;
    std::uint64_t closed_meshes = 0;
};

void add_counts(NodeCounts& into, const NodeCounts& from) {
    for (const auto& [kind, count] : from.kinds) {
        into.kinds[kind] = saturating_add(into.kinds[kind], count);
    }
    into.leaves = saturating_add(into.leaves, from.leaves);
    into.triangles = saturating_add(into.triangles, from.triangles);
    into.closed_meshes = saturating_add(into.closed_meshes, from.closed_meshes);
}

/// Memoised for every composite but instances (which the loader folds into one per use, so
/// there are as many as uses): a leaf costs nothing to count again.
NodeCounts count_node(const Shape& shape, std::unordered_map<const Shape*, NodeCounts>& memo) {
    if (const auto found = memo.find(&shape); found != memo.end()) return found->second;
    NodeCounts counts;
    counts.kinds[shape.kind()] = 1;
    const std::vector<const Shape*> children = shape.children();
    if (children.empty()) {
        counts.leaves = 1;
        // The one leaf kind with parts of its own.
        if (const auto* mesh = dynamic_cast<const Mesh*>(&shape)) {
            counts.triangles = mesh->triangle_count();
            counts.closed_meshes = mesh->report().is_closed ? 1 : 0;
        }
        return counts;
    }
    for (const Shape* child : children) add_counts(counts, count_node(*child, memo));
    if (shape.kind() != "instance") memo.emplace(&shape, counts);
    return counts;
}

}  // namespace

SceneShapeCounts count_scene_shapes(const Scene& scene) {
    std::unordered_map<const Shape*, NodeCounts> memo;
    NodeCounts total;
    for (const SceneObject& object : scene.objects()) {
        add_counts(total, count_node(*object.shape, memo));
    }
    SceneShapeCounts counts;
    for (const auto& [kind, count] : total.kinds) {
        counts.by_kind.emplace(std::string(kind), count);
        counts.shapes = saturating_add(counts.shapes, count);
    }
    counts.leaves = total.leaves;
    counts.triangles = total.triangles;
    counts.closed_meshes = total.closed_meshes;
    return counts;
}

}  // namespace csgrt
