// The loader's walk: the top level, shape nodes, lists with their grids expanded, grids and
// definitions. What each shape type reads is in shape_table.cpp.

#include <algorithm>

#include "csgrt/core/error.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/painted.h"
#include "limits.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

ShapePointer Loader::shape(Fields& fields) {
    if (depth_ >= kMaxShapeDepth) {
        fields.fail("", "shapes nested deeper than " + std::to_string(kMaxShapeDepth) +
                            " levels (booleans, compounds, grids and refs each count; "
                            "docs/scene-format.md, Limits)");
    }
    struct Level {
        std::size_t& depth;
        explicit Level(std::size_t& d) : depth(++d) {}
        ~Level() { --depth; }
    } level(depth_);
    const std::string type = fields.string("type");
    const ShapeEntry* entry = find_entry(type);
    if (entry == nullptr) {
        fields.fail("type", "unknown shape type " + quote_name(type) +
                                "; expected one of: " + known_types());
    }
    fields.set_what(with_article(type));
    ShapePointer built;
    try {
        built = entry->build(fields, *this);
    } catch (const InvalidParameter& error) {
        rethrow_invalid(error, fields, fields.value(), entry->angles);
    }
    if (const std::uint64_t overlap = overlapping_leaves(*built, overlaps_);
        overlap > kMaxOverlappingLeaves) {
        fields.fail("", overlap_message(overlap));
    }
    if (fields.has("transform")) {
        const bool bounded = built->bounds().is_finite();
        built = place(std::move(built), transform(fields.array("transform", 0, "transforms"),
                                                  fields.pointer("transform")));
        if (bounded && !built->bounds().is_finite()) {
            fields.fail("transform",
                        "the transformed shape's bounds overflow a double (1.8e308); the shape "
                        "would vanish");
        }
    }
    // Below a top-level object (whose "material" was read as the object's), a node may name a
    // material of its own; its surfaces keep it through the CSG tree (csg/painted.h).
    if (!fields.asked("material") && fields.has("material")) {
        built =
            painted(std::move(built), material_named(fields, "material", fields.string("material")),
                    fields, "material");
    }
    return built;
}

ShapePointer Loader::painted(ShapePointer shape, std::uint32_t material, Fields& fields,
                             std::string_view key) {
    if (material > kMaxPaintedMaterial) {
        fields.fail(key, "material " + std::to_string(material) + " of the scene is past the " +
                             std::to_string(kMaxPaintedMaterial + 1) +
                             " a surface inside a shape may name (a hit keeps it in 16 bits); "
                             "the scene's first materials can be named anywhere");
    }
    return std::make_shared<Painted>(std::move(shape), material);
}

std::vector<ListItem> Loader::list(Fields& fields, std::string_view key, std::size_t minimum,
                                   std::string_view of) {
    const Json& array = fields.array(key, 1, of);
    const JsonPointer pointer = fields.pointer(key);
    std::vector<ListItem> items;
    for (std::size_t i = 0; i < array.size(); ++i) {
        const JsonPointer at = pointer.child(i);
        Fields element(array[i], at, source_, "an element of \"" + std::string(key) + "\"");
        if (is_copies_node(array[i])) {
            for (Copy& copy : copies(element, false)) items.push_back({std::move(copy.shape), at});
        } else {
            items.push_back({shape(element), at});
        }
        element.finish();
    }
    if (items.size() < minimum) {
        fields.fail(key, "expected at least " + std::to_string(minimum) + " " + std::string(of) +
                             " (after expanding grids and arrays), got " +
                             std::to_string(items.size()));
    }
    return items;
}

ShapePointer Loader::definition(const std::string& name, const JsonPointer& pointer) {
    if (const auto found = built_.find(name); found != built_.end()) return found->second;
    const auto indexed = definition_index_.find(name);
    if (indexed == definition_index_.end()) {
        std::string known;
        std::size_t listed = 0;
        if (definitions_ != nullptr) {
            for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
                if (++listed > 20) {
                    known += ", ...";
                    break;
                }
                known += (known.empty() ? "" : ", ") + shown(it.key());
            }
        }
        source_.fail(pointer, "no definition named " + quote_name(name) +
                                  (known.empty() ? " (the file has no \"definitions\")"
                                                 : "; defined: " + known));
    }
    if (const auto first = std::find(building_.begin(), building_.end(), name);
        first != building_.end()) {
        // Up to 256 names (the depth limit) of any length: the first and last few, each cut.
        constexpr std::ptrdiff_t kShownEnds = 4;
        const std::ptrdiff_t length = building_.end() - first;
        std::string cycle;
        for (auto it = first; it != building_.end(); ++it) {
            const std::ptrdiff_t at = it - first;
            if (at == kShownEnds && length > 2 * kShownEnds) {
                cycle.append("... (").append(std::to_string(length - 2 * kShownEnds));
                cycle.append(" more) -> ");
                it = building_.end() - kShownEnds - 1;
                continue;
            }
            cycle.append(shown(*it)).append(" -> ");
        }
        source_.fail(pointer, "reference cycle: " + cycle + shown(name));
    }
    building_.push_back(name);
    ShapePointer built = shape(*indexed->second, JsonPointer().child("definitions").child(name),
                               "the definition " + quote_name(name));
    building_.pop_back();
    built_[name] = built;
    return built;
}

Scene Loader::load() {
    Fields top(root_, JsonPointer(), source_, "the scene");
    Scene scene;
    // Asked for so finish() accepts them; each is read below.
    for (const char* key :
         {"description", "camera", "materials", "lights", "definitions", "ambient", "background"})
        top.has(key);
    if (top.has("description")) top.string("description");
    scene_ = &scene;
    camera(scene);
    materials(scene, material_index_);
    lights(scene);
    ambient_and_background(scene);
    if (top.has("definitions")) {
        definitions_ = &root_.at("definitions");
        if (definitions_->is_object()) {
            definition_index_.reserve(definitions_->size());
            for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
                definition_index_.emplace(it.key(), &it.value());
            }
        }
    }
    prescan_leaves(root_, definition_index_, source_);
    if (definitions_ != nullptr) {
        if (!definitions_->is_object()) {
            source_.fail(std::string("/definitions"),
                         "expected an object of named shapes, got " + describe(*definitions_));
        }
        // Every definition is built, used or not, so its errors are reported.
        for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
            definition(it.key(), JsonPointer().child("definitions").child(it.key()));
        }
    }
    const Json& objects = top.array("objects", 0, "objects");
    const JsonPointer objects_at = top.pointer("objects");
    top.finish();
    // The file's object each scene object came from (a grid or an array gives several).
    std::vector<std::size_t> object_of;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        Fields fields(objects[i], objects_at.child(i), source_, "a scene object");
        const std::string name = fields.string("name", "");
        fields.has("type");  // asked first, for the order of keys a message lists
        if (is_copies_node(objects[i])) {
            const std::vector<Copy> made = copies(fields, true);
            fields.finish();
            for (const Copy& copy : made) count_leaves(*copy.shape, fields.pointer());
            for (std::size_t c = 0; c < made.size(); ++c) {
                scene.add_object(made[c].shape, made[c].material,
                                 name.empty() ? name : name + "[" + std::to_string(c) + "]");
            }
            object_of.insert(object_of.end(), made.size(), i);
        } else {
            const std::uint32_t material =
                material_named(fields, "material", fields.string("material", "default"));
            ShapePointer built = shape(fields);
            fields.finish();
            count_leaves(*built, fields.pointer());
            scene.add_object(std::move(built), material, name);
            object_of.push_back(i);
        }
    }
    // The objects share the scene's structure: a pile of them is one pile.
    std::vector<const Shape*> shapes;
    shapes.reserve(scene.objects().size());
    for (const SceneObject& object : scene.objects()) shapes.push_back(object.shape.get());
    if (const Overlap overlap = overlapping_leaves(shapes, true, overlaps_);
        overlap.leaves > kMaxOverlappingLeaves) {
        source_.fail(objects_at.child(object_of[overlap.member]),
                     "with the objects around it, " + overlap_message(overlap.leaves));
    }
    return scene;
}

}  // namespace csgrt::detail::scene_file
