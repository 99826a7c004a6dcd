// The loader's walk: the top level, shape nodes, lists with their grids expanded, grids and
// definitions. What each shape type reads is in shape_table.cpp.

#include <algorithm>

#include "csgrt/core/error.h"
#include "csgrt/csg/compound.h"
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
    fields.set_what("a " + type);
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
    return built;
}

std::vector<ListItem> Loader::list(Fields& fields, std::string_view key, std::size_t minimum,
                                   std::string_view of) {
    const Json& array = fields.array(key, 1, of);
    const std::string pointer = fields.pointer(key);
    std::vector<ListItem> items;
    for (std::size_t i = 0; i < array.size(); ++i) {
        const std::string at = child_pointer(pointer, i);
        Fields element(array[i], at, source_, "an element of \"" + std::string(key) + "\"");
        if (element.has("type") && array[i].at("type") == "grid") {
            element.string("type");
            element.set_what("a grid");
            for (ShapePointer& copy : grid(element)) items.push_back({std::move(copy), at});
        } else {
            items.push_back({shape(element), at});
        }
        element.finish();
    }
    if (items.size() < minimum) {
        fields.fail(key, "expected at least " + std::to_string(minimum) + " " + std::string(of) +
                             " (after expanding grids), got " + std::to_string(items.size()));
    }
    return items;
}

std::vector<ShapePointer> Loader::grid(Fields& fields) {
    const Json& count = fields.required("count", "an array of 3 whole numbers >= 1");
    if (!count.is_array() || count.size() != 3) {
        fields.fail("count", "expected an array of 3 whole numbers >= 1, got " + describe(count));
    }
    std::size_t counts[3];
    std::size_t total = 1;
    for (int axis = 0; axis < 3; ++axis) {
        counts[axis] = fields.to_count(count[axis], child_pointer(fields.pointer("count"), axis));
        if (counts[axis] == 0) {
            fields.fail("count",
                        "expected every count >= 1, got 0 at index " + std::to_string(axis));
        }
        // Both factors stay <= kMaxGridCopies + 1, so the product cannot overflow.
        total = counts[axis] > kMaxGridCopies ? kMaxGridCopies + 1
                                              : std::min(total * counts[axis], kMaxGridCopies + 1);
    }
    if (total > kMaxGridCopies) {
        fields.fail("count",
                    "expected at most " + std::to_string(kMaxGridCopies) + " copies in one grid");
    }
    const Vector3 spacing = fields.vector("spacing");
    const ShapePointer item =
        shape(fields.required("item", "a shape node"), fields.pointer("item"), "a grid item");
    // Refused before the copies are made: a grid of grids is a product.
    const std::uint64_t item_leaves = expanded_leaves(*item, leaves_);
    if (item_leaves > kMaxExpandedLeaves / total) {
        fields.fail("count", std::to_string(total) + " copies of an item of " +
                                 std::to_string(item_leaves) + " leaf shapes are more than the " +
                                 std::to_string(kMaxExpandedLeaves) +
                                 " leaves a scene may expand to (docs/scene-format.md, Limits)");
    }
    // Refused before the copies are made too: copies piled closer than their size.
    const std::uint64_t piled = grid_overlap(counts, spacing, item->bounds());
    if (const std::uint64_t overlap = piled * overlapping_leaves(*item, overlaps_);
        overlap > kMaxOverlappingLeaves) {
        std::string message = std::to_string(piled);
        message.append(" copies meet at one point (\"spacing\" ")
            .append(detail::describe(spacing))
            .append(" against the item's size ")
            .append(detail::describe(Vector3(item->bounds().diagonal())))
            .append("): ")
            .append(overlap_message(overlap));
        fields.fail("count", message);
    }
    Transform placement;
    if (fields.has("transform")) {
        placement =
            transform(fields.array("transform", 0, "transforms"), fields.pointer("transform"));
    }
    // Copies in x-fastest order, centred on the origin, then the grid's own transform.
    std::vector<ShapePointer> copies;
    copies.reserve(total);
    for (std::size_t k = 0; k < counts[2]; ++k) {
        for (std::size_t j = 0; j < counts[1]; ++j) {
            for (std::size_t i = 0; i < counts[0]; ++i) {
                const Vector3 offset(
                    (static_cast<double>(i) - 0.5 * static_cast<double>(counts[0] - 1)) *
                        spacing.x(),
                    (static_cast<double>(j) - 0.5 * static_cast<double>(counts[1] - 1)) *
                        spacing.y(),
                    (static_cast<double>(k) - 0.5 * static_cast<double>(counts[2] - 1)) *
                        spacing.z());
                copies.push_back(place(item, placement * Transform::translate(offset)));
            }
        }
    }
    return copies;
}

ShapePointer Loader::definition(const std::string& name, const std::string& pointer) {
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
    if (std::find(building_.begin(), building_.end(), name) != building_.end()) {
        std::string cycle;
        for (auto it = std::find(building_.begin(), building_.end(), name); it != building_.end();
             ++it) {
            cycle += *it + " -> ";
        }
        source_.fail(pointer, "reference cycle: " + cycle + name);
    }
    building_.push_back(name);
    ShapePointer built = shape(*indexed->second, child_pointer("/definitions", name),
                               "the definition " + quote_name(name));
    building_.pop_back();
    built_[name] = built;
    return built;
}

Scene Loader::load() {
    Fields top(root_, "", source_, "the scene");
    Scene scene;
    // Asked for so finish() accepts them; each is read below.
    for (const char* key :
         {"description", "camera", "materials", "lights", "definitions", "ambient", "background"})
        top.has(key);
    if (top.has("description")) top.string("description");
    camera(scene);
    std::map<std::string, std::uint32_t> material_index;
    materials(scene, material_index);
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
            source_.fail("/definitions",
                         "expected an object of named shapes, got " + describe(*definitions_));
        }
        // Every definition is built, used or not, so its errors are reported.
        for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
            definition(it.key(), child_pointer("/definitions", it.key()));
        }
    }
    const Json& objects = top.array("objects", 0, "objects");
    top.finish();
    auto material_of = [&](Fields& fields, const std::string& name) {
        const auto found = material_index.find(name);
        if (found == material_index.end()) {
            std::string known;
            std::size_t listed = 0;
            for (const auto& [known_name, index] : material_index) {
                if (++listed > 20) {
                    known += ", ...";
                    break;
                }
                known += (known.empty() ? "" : ", ") + shown(known_name);
            }
            fields.fail("material",
                        "no material named " + quote_name(name) + "; defined: " + known);
        }
        return found->second;
    };
    // The file's object each scene object came from (a grid gives several).
    std::vector<std::size_t> object_of;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        Fields fields(objects[i], child_pointer("/objects", i), source_, "a scene object");
        const std::string name = fields.string("name", "");
        const bool is_grid = fields.has("type") && objects[i].at("type") == "grid";
        std::vector<std::uint32_t> palette;
        if (is_grid && fields.has("materials")) {
            const Json& names = fields.array("materials", 1, "material names");
            for (std::size_t m = 0; m < names.size(); ++m) {
                if (!names[m].is_string()) {
                    source_.fail(child_pointer(fields.pointer("materials"), m),
                                 "expected a material name, got " + describe(names[m]));
                }
                palette.push_back(material_of(fields, names[m].get<std::string>()));
            }
            if (fields.has("material")) {
                fields.fail("material", "expected either \"material\" or \"materials\", not both");
            }
        } else {
            palette.push_back(material_of(fields, fields.string("material", "default")));
        }
        if (is_grid) {
            fields.string("type");
            fields.set_what("a grid");
            const auto copies = grid(fields);
            fields.finish();
            for (const ShapePointer& copy : copies) count_leaves(*copy, fields.pointer());
            for (std::size_t c = 0; c < copies.size(); ++c) {
                scene.add_object(copies[c], palette[c % palette.size()],
                                 name.empty() ? name : name + "[" + std::to_string(c) + "]");
            }
            object_of.insert(object_of.end(), copies.size(), i);
        } else {
            ShapePointer built = shape(fields);
            fields.finish();
            count_leaves(*built, fields.pointer());
            scene.add_object(std::move(built), palette.front(), name);
            object_of.push_back(i);
        }
    }
    // The objects share the scene's structure: a pile of them is one pile.
    std::vector<const Shape*> shapes;
    shapes.reserve(scene.objects().size());
    for (const SceneObject& object : scene.objects()) shapes.push_back(object.shape.get());
    if (const Overlap overlap = overlapping_leaves(shapes, true, overlaps_);
        overlap.leaves > kMaxOverlappingLeaves) {
        source_.fail(child_pointer("/objects", object_of[overlap.member]),
                     "with the objects around it, " + overlap_message(overlap.leaves));
    }
    return scene;
}

}  // namespace csgrt::detail::scene_file
