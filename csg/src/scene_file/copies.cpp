// Grids and arrays: nodes that stand for copies of one item, each moved into place (a grid's
// cells, an array's listed transforms), each with its material: at the top level the object's,
// inside a shape painted on the copy.

#include <algorithm>

#include "csgrt/core/hit.h"
#include "limits.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

namespace {

/// `material` blended toward `other` by `weight` in [0, 1]: the colour terms and the exponent
/// linearly; both must have the same index of refraction (glass does not blend into paint).
Material blend(const Material& material, const Material& other, double weight) {
    Material blended = material;
    blended.albedo = (1.0 - weight) * material.albedo + weight * other.albedo;
    blended.specular = (1.0 - weight) * material.specular + weight * other.specular;
    blended.mirror = (1.0 - weight) * material.mirror + weight * other.mirror;
    blended.shininess = (1.0 - weight) * material.shininess + weight * other.shininess;
    return blended;
}

/// The offset of grid cell (i, j, k): cells `spacing` apart, centred on the origin.
Vector3 cell_offset(const std::size_t counts[3], const std::size_t cell[3],
                    const Vector3& spacing) {
    Vector3 offset;
    for (int axis = 0; axis < 3; ++axis) {
        offset[axis] =
            (static_cast<double>(cell[axis]) - 0.5 * static_cast<double>(counts[axis] - 1)) *
            spacing[axis];
    }
    return offset;
}

}  // namespace

bool is_copies_node(const Json& value) {
    if (!value.is_object()) return false;
    const auto type = value.find("type");
    return type != value.end() && (*type == "grid" || *type == "array");
}

std::uint32_t Loader::material_named(Fields& fields, std::string_view key,
                                     const std::string& name) {
    const auto found = material_index_.find(name);
    if (found == material_index_.end()) {
        std::string known;
        std::size_t listed = 0;
        for (const auto& [known_name, index] : material_index_) {
            if (++listed > 20) {
                known += ", ...";
                break;
            }
            known += (known.empty() ? "" : ", ") + shown(known_name);
        }
        fields.fail(key, "no material named " + quote_name(name) + "; defined: " + known);
    }
    return found->second;
}

std::vector<Copy> Loader::copies(Fields& fields, bool top_level) {
    const std::string type = fields.string("type");
    fields.set_what(with_article(type));
    // The node's materials are read before its copies are built (docs/scene-format.md,
    // "Grids and arrays"): one for all, a palette cycled, or a ramp blended across the copies.
    std::vector<std::uint32_t> palette;
    std::string_view given;
    for (const std::string_view key : {"material", "materials", "material_ramp"}) {
        if (!fields.has(key)) continue;
        if (!given.empty()) {
            std::string message = "expected one of \"material\", \"materials\" or ";
            message.append("\"material_ramp\", not both \"").append(given);
            fields.fail(given, message.append("\" and \"").append(key).append("\""));
        }
        given = key;
    }
    const bool ramp = given == "material_ramp";
    if (given == "material" || (given.empty() && top_level)) {
        // A top-level node that names none gives its copies the default material; a nested
        // one leaves them to the materials around them.
        palette.push_back(material_named(fields, "material", fields.string("material", "default")));
    } else if (!given.empty()) {
        const JsonPointer at = fields.pointer(given);
        const Json& names = fields.array(given, ramp ? 2 : 1, "material names");
        for (std::size_t m = 0; m < names.size(); ++m) {
            if (!names[m].is_string()) {
                source_.fail(at.child(m), "expected a material name, got " + describe(names[m]));
            }
            palette.push_back(material_named(fields, given, names[m].get<std::string>()));
            if (ramp && scene_->materials()[palette.back()].ior !=
                            scene_->materials()[palette.front()].ior) {
                source_.fail(at.child(m),
                             "expected materials of one index of refraction (\"ior\") in a "
                             "ramp: glass does not blend into paint");
            }
        }
    }
    std::vector<Copy> made = type == "grid" ? grid(fields) : array(fields);
    if (ramp && !top_level &&
        scene_->materials().size() + made.size() > std::size_t{kMaxPaintedMaterial} + 1) {
        // Refused before the materials are made: a ramp makes one per copy.
        fields.fail("material_ramp",
                    "a ramp inside a shape makes one material per copy, and " +
                        std::to_string(made.size()) + " copies after the scene's " +
                        std::to_string(scene_->materials().size()) + " materials pass the " +
                        std::to_string(kMaxPaintedMaterial + 1) +
                        " a surface inside a shape may name (a hit keeps it in 16 bits); "
                        "put the grid at the top level, where copies are objects");
    }
    // Copy c of a ramp sits at c / (n - 1) along it, between two of its materials.
    const auto ramp_material = [&](std::size_t c) {
        const double position = made.size() == 1 ? 0.0
                                                 : static_cast<double>(c) /
                                                       static_cast<double>(made.size() - 1) *
                                                       static_cast<double>(palette.size() - 1);
        const std::size_t below = std::min(static_cast<std::size_t>(position), palette.size() - 2);
        Material blended =
            blend(scene_->materials()[palette[below]], scene_->materials()[palette[below + 1]],
                  position - static_cast<double>(below));
        blended.name = scene_->materials()[palette.front()].name + ".." +
                       scene_->materials()[palette.back()].name + "[" + std::to_string(c) + "]";
        return scene_->add_material(std::move(blended));
    };
    for (std::size_t c = 0; c < made.size(); ++c) {
        if (!made[c].has_own_material) {
            if (palette.empty()) continue;  // nested and no material named: left unpainted
            made[c].material = ramp ? ramp_material(c) : palette[c % palette.size()];
        }
        if (!top_level) {
            made[c].shape = painted(std::move(made[c].shape), made[c].material, fields,
                                    made[c].has_own_material ? "copies" : given);
        }
    }
    return made;
}

std::vector<Copy> Loader::grid(Fields& fields) {
    const Json& count = fields.required("count", "an array of 3 whole numbers >= 1");
    if (!count.is_array() || count.size() != 3) {
        fields.fail("count", "expected an array of 3 whole numbers >= 1, got " + describe(count));
    }
    std::size_t counts[3];
    std::size_t total = 1;
    for (int axis = 0; axis < 3; ++axis) {
        counts[axis] = fields.to_count(count[axis], [&] {
            return fields.pointer("count").child(static_cast<std::size_t>(axis));
        });
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
    require_copies_fit(fields, "count", total, *item);
    // Refused before the copies are made too: copies piled closer than their size. (A copy
    // transform may turn them; the lists they go into are estimated again once built.)
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
    // Copy n is turned by the copy transform n times, in the item's own frame.
    Transform step;
    const bool stepped = fields.has("copy_transform");
    if (stepped) {
        step = transform(fields.array("copy_transform", 1, "transforms"),
                         fields.pointer("copy_transform"));
    }
    Transform placement;
    if (fields.has("transform")) {
        placement =
            transform(fields.array("transform", 0, "transforms"), fields.pointer("transform"));
    }
    // Copies in x-fastest order, centred on the origin, then the grid's own transform.
    const JsonPointer stepped_at = fields.pointer("copy_transform");
    const JsonPointer placed_at = stepped ? stepped_at : fields.pointer("transform");
    std::vector<Copy> made;
    made.reserve(total);
    Transform turned;
    std::size_t cell[3];
    for (cell[2] = 0; cell[2] < counts[2]; ++cell[2]) {
        for (cell[1] = 0; cell[1] < counts[1]; ++cell[1]) {
            for (cell[0] = 0; cell[0] < counts[0]; ++cell[0]) {
                if (stepped && !made.empty()) {
                    turned = step * turned;
                    require_representable(turned, source_, stepped_at, true);
                }
                const Vector3 offset = cell_offset(counts, cell, spacing);
                if (!offset.allFinite()) {
                    fields.fail("spacing",
                                "the offset of the copy at " +
                                    detail::describe(Vector3(static_cast<double>(cell[0]),
                                                             static_cast<double>(cell[1]),
                                                             static_cast<double>(cell[2]))) +
                                    " overflows a double (1.8e308)");
                }
                const Transform world_from_copy = placement * Transform::translate(offset) * turned;
                if (stepped || !placement.is_identity()) {
                    require_representable(world_from_copy, source_, placed_at, true);
                }
                made.push_back(Copy{place(item, world_from_copy)});
            }
        }
    }
    return made;
}

std::vector<Copy> Loader::array(Fields& fields) {
    const Json& list = fields.array("copies", 1, "copies (objects with a \"transform\")");
    if (list.size() > kMaxGridCopies) {
        fields.fail("copies", "expected at most " + std::to_string(kMaxGridCopies) +
                                  " copies in one array, got " + std::to_string(list.size()));
    }
    const ShapePointer item =
        shape(fields.required("item", "a shape node"), fields.pointer("item"), "an array item");
    require_copies_fit(fields, "copies", list.size(), *item);
    Transform placement;
    if (fields.has("transform")) {
        placement =
            transform(fields.array("transform", 0, "transforms"), fields.pointer("transform"));
    }
    std::vector<Copy> made;
    made.reserve(list.size());
    const JsonPointer copies_at = fields.pointer("copies");
    for (std::size_t c = 0; c < list.size(); ++c) {
        Fields entry(list[c], copies_at.child(c), source_, "a copy");
        Transform world_from_copy = placement;
        if (entry.has("transform")) {
            world_from_copy = placement * transform(entry.array("transform", 0, "transforms"),
                                                    entry.pointer("transform"));
            require_representable(world_from_copy, source_, entry.pointer("transform"), true);
        }
        Copy copy{place(item, world_from_copy)};
        if (entry.has("material")) {
            copy.material = material_named(entry, "material", entry.string("material"));
            copy.has_own_material = true;
        }
        entry.finish();
        made.push_back(std::move(copy));
    }
    return made;
}

void Loader::require_copies_fit(Fields& fields, std::string_view key, std::size_t count,
                                const Shape& item) {
    // Refused before the copies are made: a grid of grids is a product.
    const std::uint64_t item_leaves = expanded_leaves(item, leaves_);
    if (item_leaves > kMaxExpandedLeaves / count) {
        fields.fail(key, std::to_string(count) + " copies of an item of " +
                             std::to_string(item_leaves) + " leaf shapes are more than the " +
                             std::to_string(kMaxExpandedLeaves) +
                             " leaves a scene may expand to (docs/scene-format.md, Limits)");
    }
}

}  // namespace csgrt::detail::scene_file
