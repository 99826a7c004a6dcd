#pragma once

// The loader: from a parsed scene file to a Scene, node by node, with the shape table, the
// transforms, the settings (camera, materials, lights) and the limits each in a file of its own.

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "csgrt/core/error.h"
#include "csgrt/core/transform.h"
#include "csgrt/csg/scene.h"
#include "fields.h"

namespace csgrt::detail::scene_file {

class Loader;

/// The definitions by name (views of the keys in the parsed tree), so a ref costs a hash
/// look-up, not a scan of the object (ordered_json finds a key by a linear search).
using DefinitionIndex = std::unordered_map<std::string_view, const Json*>;

/// Each distinct composite shape's overlapping_leaves.
using OverlapMemo = std::unordered_map<const Shape*, std::uint64_t>;

/// One entry of the shape table: the "type" keyword and how to build it from its fields.
/// Adding a shape to the format is one entry here.
struct ShapeEntry {
    std::string_view type;
    ShapePointer (*build)(Fields& fields, Loader& loader);
    /// Whether the entry reads angles (in degrees; the shapes take radians).
    bool angles = false;
};

/// A place in a list (objects, children, operands) after grids are expanded: the shape and
/// the pointer of the node it came from.
struct ListItem {
    ShapePointer shape;
    JsonPointer pointer;
};

/// One copy made by a grid or an array node: the shape, moved into place, and at the top
/// level the scene material it gets (inside a shape, a material is painted on the shape).
struct Copy {
    ShapePointer shape;
    std::uint32_t material = 0;
    /// Whether the copy named its own material (an array's copy), over the node's.
    bool has_own_material = false;
};

/// Whether `value` is a grid or an array node, which in a list stands for its copies.
bool is_copies_node(const Json& value);

class Loader {
public:
    Loader(const Json& root, const Source& source) : root_(root), source_(source) {}

    Scene load();

    /// Builds the shape described by the node at `pointer`; `fields` may already have had
    /// top-level keys read from it.
    ShapePointer shape(Fields& fields);
    ShapePointer shape(const Json& value, JsonPointer pointer, std::string_view what) {
        Fields fields(value, std::move(pointer), source_, what);
        ShapePointer built = shape(fields);
        fields.finish();
        return built;
    }

    /// The shapes of an array of nodes, with every grid replaced by its copies.
    std::vector<ListItem> list(Fields& fields, std::string_view key, std::size_t minimum,
                               std::string_view of);

    /// The copies of a grid or array node (copies.cpp), each its item moved into place, each
    /// with its material: the node's "material", its "materials" cycled, its "material_ramp"
    /// blended, or an array copy's own "material". At the top level (`top_level`) that is the
    /// scene object's material (default: "default"); inside a shape the copy is painted with
    /// it (csg/painted.h), and a node that names none leaves its copies unpainted.
    std::vector<Copy> copies(Fields& fields, bool top_level);

    /// `shape` painted with `material` (csg/painted.h); fails at `key` when the index is past
    /// what a hit record holds (kMaxPaintedMaterial).
    ShapePointer painted(ShapePointer shape, std::uint32_t material, Fields& fields,
                         std::string_view key);

    ShapePointer definition(const std::string& name, const JsonPointer& pointer);

    /// A mesh node: the file at "path", relative to the scene file's folder, loaded once per
    /// path and settings however often it is named.
    ShapePointer mesh(Fields& fields);

    const Source& source() const { return source_; }

    Transform transform(const Json& list, const JsonPointer& pointer) const;

private:
    std::vector<Copy> grid(Fields& fields);
    std::vector<Copy> array(Fields& fields);
    /// Fails at `key` when `count` copies of `item` pass kMaxExpandedLeaves.
    void require_copies_fit(Fields& fields, std::string_view key, std::size_t count,
                            const Shape& item);
    /// The index of the material called `name`, or a message at `key` listing the known ones.
    std::uint32_t material_named(Fields& fields, std::string_view key, const std::string& name);

    void camera(Scene& scene);
    void materials(Scene& scene, std::map<std::string, std::uint32_t>& by_name);
    void lights(Scene& scene);
    void ambient_and_background(Scene& scene);

    /// Counts `shape`'s expanded leaves into the scene's total and fails at `pointer` once the
    /// total passes kMaxExpandedLeaves.
    void count_leaves(const Shape& shape, const JsonPointer& pointer);

    const Json& root_;
    const Source& source_;
    /// The scene being loaded, and its materials by name.
    Scene* scene_ = nullptr;
    std::map<std::string, std::uint32_t> material_index_;
    const Json* definitions_ = nullptr;
    DefinitionIndex definition_index_;
    std::map<std::string, ShapePointer> built_;
    /// Shapes being built, one per nesting level (refs included), against kMaxShapeDepth.
    std::size_t depth_ = 0;
    /// Each distinct shape's count of expanded leaves, so shared subtrees are counted once.
    std::unordered_map<const Shape*, std::uint64_t> leaves_;
    std::uint64_t total_leaves_ = 0;
    OverlapMemo overlaps_;
    std::map<std::string, ShapePointer> meshes_;
    /// Definitions being built, outermost first: a name met again here is a cycle.
    std::vector<std::string> building_;
};

/// The entry of the shape table for `type`, or null (shape_table.cpp).
const ShapeEntry* find_entry(std::string_view type);

/// Every type of the shape table, comma-separated, for a message.
std::string known_types();

/// Turns a shape's InvalidParameter ("Sphere: radius must be > 0 ...") into a SceneError at the
/// key the message names, when the node has that key, else at the node.
[[noreturn]] void rethrow_invalid(const InvalidParameter& error, const Fields& fields,
                                  const Json& node, bool angles);

/// Fails at `at` unless `transform` and its inverse are finite (transforms.cpp): a product of
/// finite steps can overflow (scale 1e200 twice) or underflow, whose inverse then overflows
/// (scale 1e-320). `product` says whether `transform` is a product of steps, for the message.
void require_representable(const Transform& transform, const Source& source, const JsonPointer& at,
                           bool product);

/// `shape` placed by `world_from_object`; nested instances are folded into one.
ShapePointer place(ShapePointer shape, const Transform& world_from_object);

/// The leaves of the tree under `shape` with every shared subtree counted once per use,
/// memoised per distinct shape: linear in the distinct shapes, whatever the expansion.
std::uint64_t expanded_leaves(const Shape& shape,
                              std::unordered_map<const Shape*, std::uint64_t>& memo);

/// Counts the expanded leaves the parsed file `root` describes before anything is built, and
/// fails (SceneError) where they pass kMaxExpandedLeaves (leaf_limits.cpp). `definitions`
/// indexes root's "definitions" (empty when it has none or they are not an object).
void prescan_leaves(const Json& root, const DefinitionIndex& definitions, const Source& source);

/// The most leaf shapes a ray may have to test at one point of `shape`: 1 for a leaf, the
/// shape's for an instance, the estimate below over the children of a composite
/// (overlap_estimate.cpp). Memoised per distinct composite.
std::uint64_t overlapping_leaves(const Shape& shape, OverlapMemo& memo);

/// The largest overlap found in a list, and the member at whose box's centre it was found.
struct Overlap {
    std::uint64_t leaves = 0;
    std::size_t member = 0;
};

/// An estimate for a list of members (a compound's children, a boolean's operands, the scene's
/// objects): the largest sum of the members' overlapping_leaves over the members whose boxes
/// hold one sample point, the sample points being the centres of every member's box. A
/// member whose box encloses the sample's, or is enclosed by it, with a margin is not counted
/// (nested shapes are met in turn, not all at once); members with an infinite box are counted
/// at every point. Exact repeats count once when `drops_repeats` (compounds and the scene).
/// Long lists are counted through a k-d tree over the boxes, which takes or skips whole
/// groups of members at once: about n log n for members side by side or nested, never more
/// box tests than the n^2 of counting each member at each sample.
Overlap overlapping_leaves(std::span<const Shape* const> members, bool drops_repeats,
                           OverlapMemo& memo);

/// The copies of a grid (`counts` along x, y, z, `spacing` apart) whose copies of a box like
/// `item` meet at one point; copies along an axis of zero spacing are exact repeats.
std::uint64_t grid_overlap(const std::size_t counts[3], const Vector3& spacing, const Aabb& item);

/// "about N leaf shapes overlap at one point ...; at most kMaxOverlappingLeaves may".
std::string overlap_message(std::uint64_t leaves);

/// The parsed JSON tree of `text`; a SceneError for invalid JSON, a duplicate key or nesting
/// deeper than kMaxJsonDepth (json_tree.cpp).
Json parse_scene_json(std::string_view text, const Source& source);

}  // namespace csgrt::detail::scene_file
