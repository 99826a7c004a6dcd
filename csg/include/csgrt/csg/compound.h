#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/accel/built_at_commit.h"
#include "csgrt/accel/factory.h"
#include "csgrt/core/shape.h"
#include "csgrt/csg/shape_group.h"
#include "csgrt/csg/span_combine.h"

namespace csgrt {

/// How a Compound organises its children.
struct CompoundConfig {
    /// "auto" (choose_accelerator, accel/factory.h) or a name make_accelerator knows.
    std::string accelerator = "auto";
    AcceleratorConfig accelerator_config;
    /// Leave the structure to the scene (BuiltAtCommit): the first Scene::commit that reaches
    /// the compound builds it with that scene's configuration (its structure name where
    /// `accelerator` is "auto", its AcceleratorConfig) instead of the constructor with this
    /// one. A compound queried before any commit builds it then, with this configuration.
    bool build_at_commit = false;
};

/// A plain group of shapes (Suffern, "Ray Tracing from the Ground Up", 2007, ch. 19): the
/// nearest hit among the children, no boolean. The children form a ShapeGroup (csg/shape_group.h):
/// the bounded ones sit in an acceleration structure built through make_accelerator; unbounded
/// ones (planes) are kept apart and asked on every ray. A compound is itself a shape with a box, so
/// compounds of compounds form a hierarchy of bounding boxes: a ray that misses a compound's box
/// costs one box test, whatever is inside.
///
/// Hits carry `object` = the index of the child they belong to (an enclosing set overwrites it
/// with its own member index); at equal t the lower child index wins.
///
/// A compound whose children are all solids is a solid: its spans are the union of the
/// children's spans and `contains` is true inside any child. Its `nearest_hit` is still the
/// nearest surface of any child, so the two agree only when the children do not overlap or
/// touch (a ray starting inside one child would otherwise stop at another child's surface
/// inside the material). For overlapping solids use make_union (csg/boolean.h), which removes
/// internal surfaces.
class Compound final : public Shape, public BuiltAtCommit {
public:
    /// Throws InvalidParameter for a null child or an unknown structure name.
    explicit Compound(std::vector<std::shared_ptr<const Shape>> children,
                      const CompoundConfig& config = {});
    Compound(const Compound&) = delete;
    Compound& operator=(const Compound&) = delete;

    std::string_view kind() const override { return "compound"; }
    /// The join of the children's boxes (infinite when a child is unbounded).
    Aabb bounds() const override { return bounds_; }
    /// True when there is at least one child and every child is a solid.
    bool is_solid() const override { return solid_; }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    /// The union of the children's spans (combine_spans, so touching spans merge; within float
    /// ulps when a child holds a float mesh).
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    /// Whether any child contains p.
    bool contains(const Point3& p) const override;

    std::size_t size() const { return children_.size(); }
    const Shape& child(std::size_t i) const { return *children_[i]; }
    /// The children, in the order given.
    std::vector<const Shape*> children() const override {
        std::vector<const Shape*> shapes;
        shapes.reserve(children_.size());
        for (const auto& child : children_) shapes.push_back(child.get());
        return shapes;
    }
    /// The structure over the bounded children ("" when there are none), why it was chosen,
    /// and its figures.
    std::string_view accelerator_name() const;
    const std::string& accelerator_reason() const { return group().accelerator_reason(); }
    AcceleratorStats accelerator_stats() const;
    /// Whether the structure is built (false only for a build_at_commit compound before its
    /// first commit or query).
    bool is_built() const { return group_.load(std::memory_order_acquire) != nullptr; }

    void build_at_commit(std::string_view accelerator,
                         const AcceleratorConfig& config) const override;

private:
    /// The children's spans, unioned into `spans`: the candidates are children whose line has a
    /// crossing at some t <= t_max (found through the structure) and unbounded solids.
    void union_of_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const;

    /// The children as a group (member index = child index), built on first use when the
    /// constructor left it to the scene.
    const ShapeGroup& group() const {
        const ShapeGroup* built = group_.load(std::memory_order_acquire);
        return built != nullptr ? *built
                                : build_group(config_.accelerator, config_.accelerator_config);
    }
    const ShapeGroup& build_group(std::string_view accelerator,
                                  const AcceleratorConfig& config) const;

    std::vector<std::shared_ptr<const Shape>> children_;
    CompoundConfig config_;
    mutable std::mutex build_mutex_;
    mutable std::unique_ptr<const ShapeGroup> owned_group_;
    mutable std::atomic<const ShapeGroup*> group_{nullptr};
    Aabb bounds_;
    bool solid_ = false;
    /// The children's span coincidence tolerance (span_coincidence_relative), chosen once:
    /// float-sized when a child holds a float mesh, so a float mesh and a child touching it
    /// unite without an internal surface, as they do under a Boolean.
    double coincidence_ = kDoubleSpanCoincidence;
};

/// Groups `shapes` into a tree of nested compounds of at most `max_children` children each,
/// splitting at the median of the box centres along the longest axis: hierarchical bounding
/// boxes built by hand, as Suffern's compound objects do, independent of the structures in
/// accel/. Unbounded shapes stay at the top. One shape is returned as it is. Throws
/// InvalidParameter for an empty list, a null shape or max_children < 2.
std::shared_ptr<const Shape> make_hierarchy(std::vector<std::shared_ptr<const Shape>> shapes,
                                            std::size_t max_children = 4,
                                            const CompoundConfig& config = {});

}  // namespace csgrt
