#include "csgrt/csg/scene_file.h"

#include <algorithm>
#include <cfloat>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "csgrt/mesh/mesh.h"
#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/ready_made.h"

namespace csgrt {

namespace {

// ordered_json keeps the file's order, so materials get indices in the order they are written.
using Json = nlohmann::ordered_json;
using ShapePointer = std::shared_ptr<const Shape>;

/// At most this many copies from one grid: a typo in a count must not exhaust memory.
constexpr std::size_t kMaxGridCopies = 1'000'000;

/// The limits docs/scene-format.md ("Limits") documents. Nesting: JSON arrays and objects, and
/// shapes inside shapes (booleans, compounds, grids, refs), so that a hostile file gives an
/// error instead of overflowing the stack in the loader or, later, in the queries.
constexpr std::size_t kMaxJsonDepth = 1000;
constexpr std::size_t kMaxShapeDepth = 256;
/// Leaf shapes in the expanded scene (every grid copy and every use of a definition counted):
/// shared definitions and nested grids describe 2^64 leaves in 5 KB, and a ray may have to
/// visit every one of them.
constexpr std::uint64_t kMaxExpandedLeaves = 10'000'000;
/// The file is parsed into memory whole; its tree takes about ten times its size.
constexpr std::uintmax_t kMaxSceneFileBytes = 256u << 20;
/// Keys and names longer than this are cut in messages.
constexpr std::size_t kLongestShownName = 64;
/// Lights, positions and distances: their squares must stay finite in the shading.
constexpr double kMaxLength = 1e150;
/// Light intensities and radiances: far below float's 3.4e38, where the image's pixels live.
constexpr double kMaxIntensity = 1e30;

/// A name from the file for a message: control characters escaped, cut after
/// kLongestShownName bytes.
std::string shown(std::string_view name) {
    std::string text;
    const std::string_view kept = name.substr(0, kLongestShownName);
    for (const char c : kept) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte < 0x20 || byte == 0x7f) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", byte);
            text += escaped;
        } else {
            text += c;
        }
    }
    if (name.size() > kept.size()) {
        text += "... (" + std::to_string(name.size()) + " bytes)";
    }
    return text;
}

/// `shown`, in double quotes.
std::string quote_name(std::string_view name) {
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "\"" + string + "\"".
    std::string text = "\"";
    text.append(shown(name)).append("\"");
    return text;
}

std::string escape_pointer_token(std::string_view token) {
    std::string escaped;
    for (const char c : shown(token)) {
        if (c == '~') {
            escaped += "~0";
        } else if (c == '/') {
            escaped += "~1";
        } else {
            escaped += c;
        }
    }
    return escaped;
}

std::string child_pointer(const std::string& pointer, std::string_view key) {
    return pointer + "/" + escape_pointer_token(key);
}

std::string child_pointer(const std::string& pointer, std::size_t index) {
    return pointer + "/" + std::to_string(index);
}

/// A JSON value in a few words, for "expected ..., got ..." messages.
std::string describe(const Json& value) {
    switch (value.type()) {
        case Json::value_t::null:
            return "null";
        case Json::value_t::boolean:
            return value.get<bool>() ? "true" : "false";
        case Json::value_t::string:
            return "the string " + quote_name(value.get_ref<const std::string&>());
        case Json::value_t::array:
            return "an array of " + std::to_string(value.size());
        case Json::value_t::object:
            return "an object";
        default:
            return "the number " + value.dump();
    }
}

/// A pointer for a message: a very deep one (the nesting limits are met 500 levels down)
/// keeps its first and last 120 characters around the count of the levels left out.
std::string shown_pointer(const std::string& pointer) {
    if (pointer.empty()) return "(top level)";
    constexpr std::size_t kKept = 120;
    if (pointer.size() <= 3 * kKept) return pointer;
    const std::size_t head = pointer.find('/', kKept);
    const std::size_t tail = pointer.rfind('/', pointer.size() - kKept);
    if (head == std::string::npos || tail == std::string::npos || tail <= head) return pointer;
    const auto levels = std::count(pointer.begin() + static_cast<std::ptrdiff_t>(head),
                                   pointer.begin() + static_cast<std::ptrdiff_t>(tail), '/');
    std::string text = pointer.substr(0, head);
    text.append("/...(").append(std::to_string(levels)).append(" levels)...");
    text.append(pointer.substr(tail));
    return text;
}

/// Where in which file: everything a message needs besides what went wrong.
struct Source {
    std::string name;
    std::filesystem::path directory;

    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        std::string text = message;
        // Whatever of the file's text got into the message stays on one line.
        for (char& c : text) {
            if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
        }
        throw SceneError(name + ": " + shown_pointer(pointer) + ": " + text);
    }
};

/// One JSON object of the file, read key by key. Every key asked for is remembered, so
/// `finish` can reject the keys nobody asked for and list the ones that are known.
class Fields {
public:
    Fields(const Json& value, std::string pointer, const Source& source, std::string_view what)
        : value_(value), pointer_(std::move(pointer)), source_(source), what_(what) {
        if (!value_.is_object()) {
            source_.fail(pointer_, "expected an object (" + what_ + "), got " + describe(value_));
        }
    }

    const Json& value() const { return value_; }
    const std::string& pointer() const { return pointer_; }
    std::string pointer(std::string_view key) const { return child_pointer(pointer_, key); }
    const Source& source() const { return source_; }
    const std::string& what() const { return what_; }
    void set_what(std::string what) { what_ = std::move(what); }

    bool has(std::string_view key) {
        ask(key);
        return value_.contains(key);
    }

    /// The raw value of a required key.
    const Json& required(std::string_view key, std::string_view expected) {
        ask(key);
        const auto found = value_.find(key);
        if (found == value_.end()) {
            source_.fail(pointer_, "missing required key \"" + std::string(key) + "\" (" +
                                       std::string(expected) + ") in " + what_);
        }
        return *found;
    }

    double number(std::string_view key) {
        return to_number(required(key, "a number"), pointer(key));
    }
    double number(std::string_view key, double fallback) {
        return has(key) ? number(key) : fallback;
    }
    /// An angle written in degrees, returned in radians.
    double degrees(std::string_view key, double fallback_degrees) {
        return number(key, fallback_degrees) * kPi / 180.0;
    }

    std::size_t count(std::string_view key) {
        const Json& value = required(key, "a whole number");
        return to_count(value, pointer(key));
    }

    bool boolean(std::string_view key, bool fallback) {
        if (!has(key)) return fallback;
        const Json& value = value_.at(key);
        if (!value.is_boolean()) fail(key, "expected true or false, got " + describe(value));
        return value.get<bool>();
    }

    std::string string(std::string_view key) {
        const Json& value = required(key, "a string");
        if (!value.is_string()) fail(key, "expected a string, got " + describe(value));
        return value.get<std::string>();
    }
    std::string string(std::string_view key, const std::string& fallback) {
        return has(key) ? string(key) : fallback;
    }

    Vector3 vector(std::string_view key) {
        return to_vector(required(key, "an array of 3 numbers"), pointer(key));
    }
    Vector3 vector(std::string_view key, const Vector3& fallback) {
        return has(key) ? vector(key) : fallback;
    }
    /// A colour: an array of 3 numbers, or one number for a grey.
    Vector3 colour(std::string_view key, const Vector3& fallback) {
        if (!has(key)) return fallback;
        const Json& value = value_.at(key);
        if (value.is_number()) return Vector3::Constant(to_number(value, pointer(key)));
        return to_vector(value, pointer(key));
    }

    /// A required array (of anything); `minimum` elements at least.
    const Json& array(std::string_view key, std::size_t minimum, std::string_view of) {
        const Json& value = required(key, "an array of " + std::string(of));
        if (!value.is_array()) {
            fail(key, "expected an array of " + std::string(of) + ", got " + describe(value));
        }
        if (value.size() < minimum) {
            fail(key, "expected at least " + std::to_string(minimum) + " " + std::string(of) +
                          ", got " + std::to_string(value.size()));
        }
        return value;
    }

    /// Rejects every key that was not asked for, naming the known ones.
    void finish() const {
        for (auto it = value_.begin(); it != value_.end(); ++it) {
            if (std::find(asked_.begin(), asked_.end(), it.key()) != asked_.end()) continue;
            std::string message = "unknown key " + quote_name(it.key()) + " in " + what_;
            if (it.key() == "material" || it.key() == "name") {
                message += " (\"" + it.key() + "\" belongs to the top-level objects)";
            } else if (it.key() == "materials") {
                message += " (\"materials\" belongs to top-level grids)";
            }
            std::string known;
            for (const std::string& key : asked_) known += (known.empty() ? "" : ", ") + key;
            source_.fail(pointer(it.key()), message + "; expected one of: " + known);
        }
    }

    [[noreturn]] void fail(std::string_view key, const std::string& message) const {
        source_.fail(key.empty() ? pointer_ : pointer(key), message);
    }

    double to_number(const Json& value, const std::string& at) const {
        if (!value.is_number()) source_.fail(at, "expected a number, got " + describe(value));
        const double number = value.get<double>();
        // JSON has no NaN or infinity, but a literal like 1e999 overflows to infinity.
        if (!std::isfinite(number))
            source_.fail(at, "expected a finite number, got " + value.dump());
        return number;
    }

    std::size_t to_count(const Json& value, const std::string& at) const {
        if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
            source_.fail(at, "expected a whole number >= 0, got " + describe(value));
        }
        return value.get<std::size_t>();
    }

    Vector3 to_vector(const Json& value, const std::string& at) const {
        if (!value.is_array() || value.size() != 3) {
            source_.fail(at, "expected an array of 3 numbers, got " + describe(value));
        }
        return Vector3(to_number(value[0], child_pointer(at, 0)),
                       to_number(value[1], child_pointer(at, 1)),
                       to_number(value[2], child_pointer(at, 2)));
    }

private:
    void ask(std::string_view key) {
        if (std::find(asked_.begin(), asked_.end(), key) == asked_.end()) asked_.emplace_back(key);
    }

    const Json& value_;
    std::string pointer_;
    const Source& source_;
    std::string what_;
    std::vector<std::string> asked_;
};

class Loader;

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
    std::string pointer;
};

class Loader {
public:
    Loader(const Json& root, const Source& source) : root_(root), source_(source) {}

    Scene load();

    /// Builds the shape described by the node at `pointer`; `fields` may already have had
    /// top-level keys read from it.
    ShapePointer shape(Fields& fields);
    ShapePointer shape(const Json& value, const std::string& pointer, std::string_view what) {
        Fields fields(value, pointer, source_, what);
        ShapePointer built = shape(fields);
        fields.finish();
        return built;
    }

    /// The shapes of an array of nodes, with every grid replaced by its copies.
    std::vector<ListItem> list(Fields& fields, std::string_view key, std::size_t minimum,
                               std::string_view of);

    /// The copies of a grid node, each its item moved into place.
    std::vector<ShapePointer> grid(Fields& fields);

    ShapePointer definition(const std::string& name, const std::string& pointer);

    /// A mesh node: the file at "path", relative to the scene file's folder, loaded once per
    /// path and settings however often it is named.
    ShapePointer mesh(Fields& fields);

    const Source& source() const { return source_; }

    Transform transform(const Json& list, const std::string& pointer) const;

private:
    void camera(Scene& scene);
    void materials(Scene& scene, std::map<std::string, std::uint32_t>& by_name);
    void lights(Scene& scene);
    void ambient_and_background(Scene& scene);

    /// Counts `shape`'s expanded leaves into the scene's total and fails at `pointer` once the
    /// total passes kMaxExpandedLeaves.
    void count_leaves(const Shape& shape, const std::string& pointer);

    const Json& root_;
    const Source& source_;
    const Json* definitions_ = nullptr;
    /// The definitions by name, so a ref costs a hash look-up, not a scan of the object.
    std::unordered_map<std::string, const Json*> definition_index_;
    std::map<std::string, ShapePointer> built_;
    /// Shapes being built, one per nesting level (refs included), against kMaxShapeDepth.
    std::size_t depth_ = 0;
    /// Each distinct shape's count of expanded leaves, so shared subtrees are counted once.
    std::unordered_map<const Shape*, std::uint64_t> leaves_;
    std::uint64_t total_leaves_ = 0;
    std::map<std::string, ShapePointer> meshes_;
    /// Definitions being built, outermost first: a name met again here is a cycle.
    std::vector<std::string> building_;
};

/// `shape` placed by `world_from_object`; nested instances are folded into one.
ShapePointer place(ShapePointer shape, const Transform& world_from_object) {
    if (world_from_object.is_identity()) return shape;
    if (const auto* instance = dynamic_cast<const Instance*>(shape.get())) {
        return std::make_shared<Instance>(instance->shared_shape(),
                                          world_from_object * instance->world_from_object());
    }
    return std::make_shared<Instance>(std::move(shape), world_from_object);
}

std::string solid_requirement(const ListItem& item) {
    std::string kind(item.shape->kind());
    if (kind == "mesh") kind = "an open mesh (one with a boundary, not a closed surface)";
    return "expected a solid (a closed shape: sphere, box, capped cylinder or cone, torus, "
           "boolean, ready-made solid, compound of solids, closed mesh) as a boolean operand, "
           "got " +
           kind;
}

std::vector<ShapePointer> operand_shapes(const std::vector<ListItem>& items, const Source& source) {
    std::vector<ShapePointer> shapes;
    for (const ListItem& item : items) {
        if (!item.shape->is_solid()) source.fail(item.pointer, solid_requirement(item));
        shapes.push_back(item.shape);
    }
    return shapes;
}

std::vector<ShapePointer> plain_shapes(const std::vector<ListItem>& items) {
    std::vector<ShapePointer> shapes;
    for (const ListItem& item : items) shapes.push_back(item.shape);
    return shapes;
}

CompoundConfig compound_config(Fields& fields) {
    CompoundConfig config;
    config.accelerator = fields.string("accelerator", "auto");
    return config;
}

const ShapeEntry kShapeTable[] = {
    {"sphere",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 center = f.vector("center", Point3::Zero());
         return std::make_shared<Sphere>(center, f.number("radius"));
     }},
    {"plane",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 point = f.vector("point", Point3::Zero());
         return std::make_shared<Plane>(point, f.vector("normal"));
     }},
    {"triangle",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 p0 = f.vector("p0");
         const Point3 p1 = f.vector("p1");
         return std::make_shared<Triangle>(p0, p1, f.vector("p2"));
     }},
    {"disk",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 center = f.vector("center", Point3::Zero());
         const Normal3 normal = f.vector("normal");
         return std::make_shared<Disk>(center, normal, f.number("radius"));
     }},
    {"rectangle",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 corner = f.vector("corner");
         const Vector3 edge_a = f.vector("edge_a");
         return std::make_shared<Rectangle>(corner, edge_a, f.vector("edge_b"));
     }},
    {"box",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 lower = f.vector("lower");
         return std::make_shared<Box>(lower, f.vector("upper"));
     }},
    {"cylinder",
     [](Fields& f, Loader&) -> ShapePointer {
         const double radius = f.number("radius");
         const double y_min = f.number("y_min");
         const double y_max = f.number("y_max");
         return std::make_shared<Cylinder>(radius, y_min, y_max, f.boolean("capped", true));
     }},
    {"cone",
     [](Fields& f, Loader&) -> ShapePointer {
         const double base_radius = f.number("base_radius");
         const double top_radius = f.number("top_radius", 0.0);
         const double height = f.number("height");
         return std::make_shared<Cone>(base_radius, top_radius, height, f.boolean("capped", true));
     }},
    {"part_sphere",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 center = f.vector("center", Point3::Zero());
         const double radius = f.number("radius");
         const double phi_min = f.degrees("phi_min", 0.0);
         const double phi_max = f.degrees("phi_max", 360.0);
         const double theta_min = f.degrees("theta_min", 0.0);
         return std::make_shared<PartSphere>(center, radius, phi_min, phi_max, theta_min,
                                             f.degrees("theta_max", 180.0));
     },
     true},
    {"part_cylinder",
     [](Fields& f, Loader&) -> ShapePointer {
         const double radius = f.number("radius");
         const double y_min = f.number("y_min");
         const double y_max = f.number("y_max");
         const double phi_min = f.degrees("phi_min", 0.0);
         return std::make_shared<PartCylinder>(radius, y_min, y_max, phi_min,
                                               f.degrees("phi_max", 360.0));
     },
     true},
    {"annulus",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 center = f.vector("center", Point3::Zero());
         const Normal3 normal = f.vector("normal");
         const double inner_radius = f.number("inner_radius", 0.0);
         const double outer_radius = f.number("outer_radius");
         const double phi_min = f.degrees("phi_min", 0.0);
         return std::make_shared<Annulus>(center, normal, inner_radius, outer_radius, phi_min,
                                          f.degrees("phi_max", 360.0));
     },
     true},
    {"torus",
     [](Fields& f, Loader&) -> ShapePointer {
         const double major_radius = f.number("major_radius");
         return std::make_shared<Torus>(major_radius, f.number("minor_radius"));
     }},
    {"part_torus",
     [](Fields& f, Loader&) -> ShapePointer {
         const double major_radius = f.number("major_radius");
         const double minor_radius = f.number("minor_radius");
         const double phi_min = f.degrees("phi_min", 0.0);
         const double phi_max = f.degrees("phi_max", 360.0);
         const double theta_min = f.degrees("theta_min", 0.0);
         return std::make_shared<PartTorus>(major_radius, minor_radius, phi_min, phi_max, theta_min,
                                            f.degrees("theta_max", 360.0));
     },
     true},
    {"mesh", [](Fields& f, Loader& loader) -> ShapePointer { return loader.mesh(f); }},
    {"solid_cylinder",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 bottom = f.vector("bottom");
         const Point3 top = f.vector("top");
         return make_solid_cylinder(bottom, top, f.number("radius"));
     }},
    {"solid_cone",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 base = f.vector("base");
         const Point3 top = f.vector("top");
         const double base_radius = f.number("base_radius");
         return make_solid_cone(base, top, base_radius, f.number("top_radius", 0.0));
     }},
    {"thick_ring",
     [](Fields& f, Loader&) -> ShapePointer {
         const double y_min = f.number("y_min");
         const double y_max = f.number("y_max");
         const double inner_radius = f.number("inner_radius");
         return make_thick_ring(y_min, y_max, inner_radius, f.number("outer_radius"));
     }},
    {"bowl",
     [](Fields& f, Loader&) -> ShapePointer {
         const double outer_radius = f.number("outer_radius");
         return make_bowl(outer_radius, f.number("inner_radius"));
     }},
    {"rounded_box",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 lower = f.vector("lower");
         const Point3 upper = f.vector("upper");
         return make_rounded_box(lower, upper, f.number("radius"));
     }},
    {"union",
     [](Fields& f, Loader& loader) -> ShapePointer {
         return make_union(
             operand_shapes(loader.list(f, "operands", 2, "operand shapes"), loader.source()));
     }},
    {"intersection",
     [](Fields& f, Loader& loader) -> ShapePointer {
         return make_intersection(
             operand_shapes(loader.list(f, "operands", 2, "operand shapes"), loader.source()));
     }},
    {"difference",
     [](Fields& f, Loader& loader) -> ShapePointer {
         std::vector<ShapePointer> operands = operand_shapes(
             loader.list(f, "operands", 2, "operand shapes (the first minus the others)"),
             loader.source());
         const ShapePointer first = operands.front();
         operands.erase(operands.begin());
         return make_difference(first, operands);
     }},
    {"compound",
     [](Fields& f, Loader& loader) -> ShapePointer {
         auto children = plain_shapes(loader.list(f, "children", 1, "child shapes"));
         return std::make_shared<Compound>(std::move(children), compound_config(f));
     }},
    {"grid",
     [](Fields& f, Loader& loader) -> ShapePointer {
         // Outside a list a grid is one shape: the compound of its copies.
         auto copies = loader.grid(f);
         return std::make_shared<Compound>(std::move(copies), compound_config(f));
     }},
    {"ref",
     [](Fields& f, Loader& loader) -> ShapePointer {
         return loader.definition(f.string("definition"), f.pointer("definition"));
     }},
};

const ShapeEntry* find_entry(std::string_view type) {
    for (const ShapeEntry& entry : kShapeTable) {
        if (entry.type == type) return &entry;
    }
    return nullptr;
}

std::string known_types() {
    std::string known;
    for (const ShapeEntry& entry : kShapeTable) {
        known += (known.empty() ? "" : ", ") + std::string(entry.type);
    }
    return known;
}

/// Turns a shape's InvalidParameter ("Sphere: radius must be > 0 ...") into a SceneError at the
/// key the message names, when the node has that key, else at the node.
[[noreturn]] void rethrow_invalid(const InvalidParameter& error, const Fields& fields,
                                  const Json& node, bool angles) {
    std::string message = error.what();
    std::string pointer = fields.pointer();
    std::string parameter = error.parameter();
    // The structure name of a compound or grid is its "accelerator" key; the keys every node
    // may have are never a shape's parameter.
    if (message.starts_with("make_accelerator:") && parameter == "name") parameter = "accelerator";
    const bool shape_key = !parameter.empty() && parameter != "name" && parameter != "material" &&
                           parameter != "type" && parameter != "transform";
    if (shape_key && node.is_object() && node.contains(parameter)) {
        pointer = fields.pointer(parameter);
    }
    if (angles && (parameter.starts_with("phi") || parameter.starts_with("theta"))) {
        message += " (radians: the file's degrees times pi / 180)";
    }
    fields.source().fail(pointer, message);
}

/// `value` plus `add`, saturating at the largest count rather than wrapping.
std::uint64_t saturating_add(std::uint64_t value, std::uint64_t add) {
    return add > std::numeric_limits<std::uint64_t>::max() - value
               ? std::numeric_limits<std::uint64_t>::max()
               : value + add;
}

/// The leaves of the tree under `shape` with every shared subtree counted once per use,
/// memoised per distinct shape: linear in the distinct shapes, whatever the expansion.
std::uint64_t expanded_leaves(const Shape& shape,
                              std::unordered_map<const Shape*, std::uint64_t>& memo) {
    if (const auto found = memo.find(&shape); found != memo.end()) return found->second;
    const std::vector<const Shape*> children = shape.children();
    std::uint64_t leaves = children.empty() ? 1 : 0;
    for (const Shape* child : children)
        leaves = saturating_add(leaves, expanded_leaves(*child, memo));
    memo.emplace(&shape, leaves);
    return leaves;
}

void Loader::count_leaves(const Shape& shape, const std::string& pointer) {
    total_leaves_ = saturating_add(total_leaves_, expanded_leaves(shape, leaves_));
    if (total_leaves_ > kMaxExpandedLeaves) {
        const std::string count = total_leaves_ == std::numeric_limits<std::uint64_t>::max()
                                      ? "at least 2^64 - 1"
                                      : std::to_string(total_leaves_);
        source_.fail(pointer, "the scene expands to " + count +
                                  " leaf shapes up to here (every grid copy and every use of a "
                                  "definition counts); at most " +
                                  std::to_string(kMaxExpandedLeaves) +
                                  " are allowed (docs/scene-format.md, Limits)");
    }
}

/// Counts the expanded leaves the parsed file describes before anything is built, so a file
/// over kMaxExpandedLeaves is refused in time linear in its size instead of after building
/// legal inner structures (a 10^6-sphere grid inside a grid of 10). Each definition is counted
/// once (memoised by name); a node it does not understand counts as one leaf and is left to
/// the loader to report. Pointers are assembled from the stack of tokens only for a message.
class LeafPrescan {
public:
    LeafPrescan(const Json& root, const Source& source) : root_(root), source_(source) {
        if (const auto found = root.find("definitions");
            found != root.end() && found->is_object()) {
            definitions_ = &*found;
        }
    }

    /// Fails, with the loader's own messages and pointers, at the first grid whose copies
    /// pass the cap or at the object where the running total of the objects passes it.
    void run() {
        if (definitions_ != nullptr) {
            tokens_.push_back("definitions");
            for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
                definition(it.key(), it.value(), 0);
            }
            tokens_.pop_back();
        }
        const auto objects = root_.find("objects");
        if (objects == root_.end() || !objects->is_array()) return;
        tokens_.push_back("objects");
        std::uint64_t total = 0;
        for (std::size_t i = 0; i < objects->size(); ++i) {
            tokens_.push_back(std::to_string(i));
            total = saturating_add(total, node((*objects)[i], 0));
            if (total > kMaxExpandedLeaves) too_many(total);
            tokens_.pop_back();
        }
        tokens_.pop_back();
    }

private:
    std::uint64_t definition(const std::string& name, const Json& body, std::size_t depth) {
        if (const auto found = counted_.find(name); found != counted_.end()) return found->second;
        // A cycle is the loader's to report; it counts as one leaf here.
        if (!in_progress_.insert(name).second) return 1;
        tokens_.push_back(name);
        const std::uint64_t leaves = node(body, depth + 1);
        tokens_.pop_back();
        in_progress_.erase(name);
        counted_.emplace(name, leaves);
        return leaves;
    }

    std::uint64_t node(const Json& value, std::size_t depth) {
        // Deeper than the loader allows: the loader reports the depth.
        if (depth > kMaxShapeDepth || !value.is_object()) return 1;
        const auto type = value.find("type");
        if (type == value.end() || !type->is_string()) return 1;
        const std::string& name = type->get_ref<const std::string&>();
        std::uint64_t leaves = 1;
        if (name == "union" || name == "intersection" || name == "difference") {
            leaves = list(value, "operands", depth);
        } else if (name == "compound") {
            leaves = list(value, "children", depth);
        } else if (name == "grid") {
            leaves = grid(value, depth);
        } else if (name == "ref") {
            const auto target = value.find("definition");
            if (definitions_ != nullptr && target != value.end() && target->is_string()) {
                const auto body = definitions_->find(target->get_ref<const std::string&>());
                if (body != definitions_->end()) {
                    // The definition's own tokens replace this node's in a message.
                    std::vector<std::string> saved = std::move(tokens_);
                    tokens_ = {"definitions"};
                    leaves = definition(target->get_ref<const std::string&>(), *body, depth);
                    tokens_ = std::move(saved);
                }
            }
        }
        return leaves;
    }

    std::uint64_t list(const Json& value, const char* key, std::size_t depth) {
        const auto array = value.find(key);
        if (array == value.end() || !array->is_array()) return 1;
        std::uint64_t leaves = 0;
        tokens_.push_back(key);
        for (std::size_t i = 0; i < array->size(); ++i) {
            tokens_.push_back(std::to_string(i));
            leaves = saturating_add(leaves, node((*array)[i], depth + 1));
            tokens_.pop_back();
        }
        tokens_.pop_back();
        return leaves;
    }

    std::uint64_t grid(const Json& value, std::size_t depth) {
        const auto count = value.find("count");
        const auto item = value.find("item");
        if (count == value.end() || item == value.end() || !count->is_array()) return 1;
        std::uint64_t copies = 1;
        for (const Json& axis : *count) {
            // Malformed counts are the loader's to report; whole numbers multiply, saturating.
            if (!axis.is_number_unsigned() && !axis.is_number_integer()) return 1;
            const auto n = axis.get<std::int64_t>();
            if (n <= 0) return 1;
            copies =
                static_cast<std::uint64_t>(n) > std::numeric_limits<std::uint64_t>::max() / copies
                    ? std::numeric_limits<std::uint64_t>::max()
                    : copies * static_cast<std::uint64_t>(n);
        }
        // Over one grid's copy limit: the loader refuses it before building its item.
        if (copies > kMaxGridCopies) return 1;
        tokens_.push_back("item");
        const std::uint64_t item_leaves = node(*item, depth + 1);
        tokens_.pop_back();
        if (item_leaves != 0 && copies > kMaxExpandedLeaves / item_leaves) {
            tokens_.push_back("count");
            std::string message = count_text(copies);
            message.append(" copies of an item of ").append(std::to_string(item_leaves));
            message.append(" leaf shapes are more than the ");
            message.append(std::to_string(kMaxExpandedLeaves));
            message.append(" leaves a scene may expand to (docs/scene-format.md, Limits)");
            source_.fail(pointer(), message);
        }
        return copies * item_leaves;
    }

    /// A count for a message; the saturated count is a lower bound.
    static std::string count_text(std::uint64_t count) {
        return count == std::numeric_limits<std::uint64_t>::max() ? "at least 2^64 - 1"
                                                                  : std::to_string(count);
    }

    [[noreturn]] void too_many(std::uint64_t leaves) const {
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        std::string message = "the scene expands to ";
        message.append(count_text(leaves));
        message.append(" leaf shapes up to here (every grid copy and every use of a definition ");
        message.append("counts); at most ").append(std::to_string(kMaxExpandedLeaves));
        message.append(" are allowed (docs/scene-format.md, Limits)");
        source_.fail(pointer(), message);
    }

    std::string pointer() const {
        std::string text;
        for (const std::string& token : tokens_)
            text.append("/").append(escape_pointer_token(token));
        return text;
    }

    const Json& root_;
    const Source& source_;
    const Json* definitions_ = nullptr;
    std::unordered_map<std::string, std::uint64_t> counted_;
    std::unordered_set<std::string> in_progress_;
    std::vector<std::string> tokens_;
};

/// Fails at `at` unless `transform` and its inverse are finite: a product of finite steps can
/// overflow (scale 1e200 twice) or underflow, whose inverse then overflows (scale 1e-320).
void require_representable(const Transform& transform, const Source& source, const std::string& at,
                           bool product) {
    const bool forward = transform.linear().allFinite() && transform.translation().allFinite();
    const bool backward =
        transform.inverse_linear().allFinite() && transform.inverse().translation().allFinite();
    if (forward && backward) return;
    const std::string what =
        product ? "the product of the transforms up to this one" : "this transform";
    source.fail(at, what + (forward ? " underflows: its inverse" : " overflows: it") +
                        " has a coefficient beyond the largest double (1.8e308)");
}

/// Fails at `key` of `fields` unless |v|^2 is finite (and, for a direction, not zero when v
/// is not): the shading and the camera square lengths and normalise.
void require_length(const Vector3& v, Fields& fields, std::string_view key, std::string_view what,
                    bool direction) {
    // stableNorm scales first, so the length it reports is the true one, not an overflow.
    const double length = v.stableNorm();
    if (!(length <= kMaxLength)) {
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", length);
        fields.fail(key, std::string(what) + " has length " + text +
                             ", beyond 1e150: its square overflows a double in the shading");
    }
    if (direction && v.squaredNorm() < DBL_MIN) {
        fields.fail(key, std::string(what) + " " + detail::describe(v) +
                             " is too short: its square underflows a double, so it has no "
                             "direction");
    }
}

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

ShapePointer Loader::mesh(Fields& fields) {
    const std::string path = fields.string("path");
    if (path.find('\0') != std::string::npos) {
        fields.fail("path", "the path contains a NUL byte (\\u0000), which no file name can");
    }
    if (path.empty()) fields.fail("path", "expected a file name, got an empty string");
    MeshConfig config;
    config.double_precision = fields.boolean("double_precision", false);
    config.accelerator = fields.string("accelerator", config.accelerator);
    // Shading and welding (docs/scene-format.md): "flat", "crease_degrees" in (0, 180],
    // "weld" (merge vertices at equal positions: a per-corner soup becomes a solid).
    config.flat_shading = fields.boolean("flat", false);
    const double crease_degrees = fields.number("crease_degrees", 180.0);
    if (!(crease_degrees > 0.0 && crease_degrees <= 180.0))
        fields.fail("crease_degrees", "expected an angle in (0, 180] degrees");
    config.crease_angle = crease_degrees * kPi / 180.0;
    config.weld_vertices = fields.boolean("weld", false);
    const std::filesystem::path file = source_.directory / path;
    const std::string key =
        file.lexically_normal().string() + "|" + (config.double_precision ? "double" : "float") +
        "|" + config.accelerator + "|" + (config.flat_shading ? "flat" : "smooth") + "|" +
        std::to_string(crease_degrees) + "|" + (config.weld_vertices ? "weld" : "");
    if (const auto found = meshes_.find(key); found != meshes_.end()) return found->second;
    ShapePointer loaded;
    try {
        loaded = Mesh::load(file, config);
    } catch (const MeshError& error) {
        fields.fail("path", std::string("cannot use the mesh: ") + error.what());
    } catch (const InvalidParameter& error) {
        // An unknown structure name.
        fields.fail("accelerator", error.what());
    }
    meshes_[key] = loaded;
    return loaded;
}

Transform Loader::transform(const Json& list, const std::string& pointer) const {
    // Each entry acts on the result of the ones before it: world = T_n ... T_2 T_1.
    Transform world_from_object;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string at = child_pointer(pointer, i);
        const Json& entry = list[i];
        if (!entry.is_object() || entry.size() != 1) {
            source_.fail(at,
                         "expected an object with one key (translate, rotate, scale, shear "
                         "or matrix), got " +
                             describe(entry));
        }
        const std::string kind = entry.begin().key();
        const Json& value = entry.begin().value();
        const std::string value_at = child_pointer(at, kind);
        Fields probe(entry, at, source_, "a transform");
        Transform step;
        try {
            if (kind == "translate") {
                step = Transform::translate(probe.to_vector(value, value_at));
            } else if (kind == "scale") {
                step = value.is_number() ? Transform::scale(probe.to_number(value, value_at))
                                         : Transform::scale(probe.to_vector(value, value_at));
            } else if (kind == "rotate") {
                Fields rotate(value, value_at, source_, "a rotation");
                const Vector3 axis = rotate.vector("axis");
                step = Transform::rotate(axis, rotate.number("degrees") * kPi / 180.0);
                rotate.finish();
            } else if (kind == "shear") {
                Fields shear(value, value_at, source_, "a shear");
                auto axis_of = [&](std::string_view key) {
                    const std::string name = shear.string(key);
                    if (name == "x") return 0;
                    if (name == "y") return 1;
                    if (name == "z") return 2;
                    shear.fail(key, "expected \"x\", \"y\" or \"z\", got " + quote_name(name));
                };
                const int axis = axis_of("axis");
                const int by = axis_of("by");
                if (by == axis) shear.fail("by", "expected an axis other than \"axis\"");
                step = Transform::shear(axis, by, shear.number("factor"));
                shear.finish();
            } else if (kind == "matrix") {
                if (!value.is_array() || value.size() != 4) {
                    source_.fail(value_at, "expected 4 rows of 4 numbers, got " + describe(value));
                }
                Eigen::Matrix4d matrix;
                for (int row = 0; row < 4; ++row) {
                    const Json& values = value[row];
                    const std::string row_at = child_pointer(value_at, row);
                    if (!values.is_array() || values.size() != 4) {
                        source_.fail(row_at,
                                     "expected a row of 4 numbers, got " + describe(values));
                    }
                    for (int column = 0; column < 4; ++column) {
                        matrix(row, column) =
                            probe.to_number(values[column], child_pointer(row_at, column));
                    }
                }
                step = Transform::from_matrix(matrix);
            } else {
                source_.fail(child_pointer(at, kind),
                             "unknown transform \"" + kind +
                                 "\"; expected one of: translate, rotate, scale, shear, matrix");
            }
        } catch (const InvalidParameter& error) {
            source_.fail(value_at, error.what());
        }
        require_representable(step, source_, value_at, false);
        world_from_object = step * world_from_object;
        require_representable(world_from_object, source_, value_at, true);
    }
    return world_from_object;
}

void Loader::camera(Scene& scene) {
    Camera camera;
    if (root_.contains("camera")) {
        Fields fields(root_.at("camera"), "/camera", source_, "the camera");
        const std::string projection = fields.string("projection", "pinhole");
        if (projection == "orthographic") {
            camera.projection = Camera::Projection::Orthographic;
        } else if (projection != "pinhole") {
            fields.fail("projection",
                        "expected \"pinhole\" or \"orthographic\", got " + quote_name(projection));
        }
        camera.position = fields.vector("position", camera.position);
        camera.look_at = fields.vector("look_at", camera.look_at);
        camera.up = fields.vector("up", camera.up);
        camera.vertical_fov_degrees =
            fields.number("vertical_fov_degrees", camera.vertical_fov_degrees);
        camera.orthographic_height =
            fields.number("orthographic_height", camera.orthographic_height);
        fields.finish();
        require_length(camera.position, fields, "position", "the position", false);
        require_length(camera.look_at, fields, "look_at", "look_at", false);
        require_length(camera.up, fields, "up", "the up vector", true);
        // look_at == position is Camera::validate's to report.
        if (camera.look_at != camera.position) {
            require_length(camera.look_at - camera.position, fields, "look_at",
                           "the view direction look_at - position", true);
        }
        try {
            camera.validate();
        } catch (const InvalidParameter& error) {
            rethrow_invalid(error, fields, root_.at("camera"), false);
        }
    }
    scene.set_camera(camera);
}

void Loader::materials(Scene& scene, std::map<std::string, std::uint32_t>& by_name) {
    by_name["default"] = 0;
    if (!root_.contains("materials")) return;
    const Json& materials = root_.at("materials");
    if (!materials.is_object()) {
        source_.fail("/materials",
                     "expected an object of named materials, got " + describe(materials));
    }
    for (auto it = materials.begin(); it != materials.end(); ++it) {
        const std::string at = child_pointer("/materials", it.key());
        if (it.key() == "default") {
            source_.fail(at, "the name \"default\" is taken by material 0, the neutral grey");
        }
        Fields fields(it.value(), at, source_, "a material");
        Material material{it.key(), fields.colour("albedo", Vector3(0.8, 0.8, 0.8))};
        // Secondary-ray terms (render/materials.h, docs/scene-format.md): each checked here.
        material.specular = fields.colour("specular", material.specular);
        material.mirror = fields.colour("mirror", material.mirror);
        for (const char* key : {"specular", "mirror"}) {
            const Vector3& colour = key[0] == 's' ? material.specular : material.mirror;
            if (!((colour.array() >= 0.0) && (colour.array() <= 1.0)).all()) {
                fields.fail(key, "expected values in [0, 1], got " + detail::describe(colour));
            }
        }
        material.shininess = fields.number("shininess", material.shininess);
        if (!(material.shininess >= 0.0 && material.shininess <= 1e6)) {
            fields.fail("shininess", "expected a Phong exponent in [0, 1e6], got " +
                                         detail::describe(material.shininess));
        }
        material.ior = fields.number("ior", material.ior);
        if (!(material.ior == 0.0 || (material.ior >= 1.0 && material.ior <= 10.0))) {
            fields.fail("ior", "expected 0 (opaque) or an index of refraction in [1, 10], got " +
                                   detail::describe(material.ior));
        }
        fields.finish();
        try {
            by_name[it.key()] = scene.add_material(material);
        } catch (const InvalidParameter& error) {
            source_.fail(child_pointer(at, "albedo"), error.what());
        }
    }
}

void Loader::lights(Scene& scene) {
    if (!root_.contains("lights")) return;
    const Json& lights = root_.at("lights");
    if (!lights.is_array()) {
        source_.fail("/lights", "expected an array of lights, got " + describe(lights));
    }
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const std::string at = child_pointer("/lights", i);
        Fields fields(lights[i], at, source_, "a light");
        const std::string type = fields.string("type");
        auto check_colour = [&](std::string_view key, const Vector3& colour) {
            if (!(colour.array() >= 0.0).all()) {
                fields.fail(key, "expected values >= 0, got " + detail::describe(colour));
            }
            if (!(colour.array() <= kMaxIntensity).all()) {
                fields.fail(key, "expected values <= " + detail::describe(kMaxIntensity) +
                                     " (brighter overflows the image's float pixels), got " +
                                     detail::describe(colour));
            }
        };
        if (type == "point") {
            fields.set_what("a point light");
            PointLight light;
            light.position = fields.vector("position");
            require_length(light.position, fields, "position", "the position", false);
            light.intensity = fields.colour("intensity", light.intensity);
            check_colour("intensity", light.intensity);
            light.falloff = fields.number("falloff", light.falloff);
            if (!(light.falloff >= 0.0 && light.falloff <= 4.0)) {
                fields.fail("falloff", "expected an exponent in [0, 4] (2: 1/d^2), got " +
                                           detail::describe(light.falloff));
            }
            scene.add_light(light);
        } else if (type == "directional") {
            fields.set_what("a directional light");
            DirectionalLight light;
            light.direction = fields.vector("direction");
            if ((light.direction.array() == 0.0).all()) {
                fields.fail("direction", "expected a non-zero direction, got (0, 0, 0)");
            }
            require_length(light.direction, fields, "direction", "the direction", true);
            light.radiance = fields.colour("radiance", light.radiance);
            check_colour("radiance", light.radiance);
            scene.add_light(light);
        } else if (type == "rectangle" || type == "disk" || type == "sphere") {
            // Area lights (render/lights.h): a radiance and a count of stratified samples.
            fields.set_what("a " + type + " light");
            const Vector3 radiance = fields.colour("radiance", Vector3::Constant(10.0));
            check_colour("radiance", radiance);
            int samples = kDefaultAreaLightSamples;
            if (fields.has("samples")) {
                const std::size_t count = fields.count("samples");
                if (count < 1 || count > static_cast<std::size_t>(kMaxAreaLightSamples)) {
                    fields.fail("samples", "expected a sample count in [1, " +
                                               std::to_string(kMaxAreaLightSamples) + "], got " +
                                               std::to_string(count));
                }
                samples = static_cast<int>(count);
            }
            auto positive_radius = [&] {
                const double radius = fields.number("radius", 1.0);
                if (!(radius > 0.0 && radius <= kMaxLength)) {
                    fields.fail("radius", "expected a radius in (0, 1e150], got " +
                                              detail::describe(radius));
                }
                return radius;
            };
            if (type == "rectangle") {
                RectangleLight light{.radiance = radiance, .samples = samples};
                light.corner = fields.vector("corner");
                require_length(light.corner, fields, "corner", "the corner", false);
                for (const char* key : {"edge_u", "edge_v"}) {
                    Vector3& edge = key[5] == 'u' ? light.edge_u : light.edge_v;
                    edge = fields.vector(key);
                    require_length(edge, fields, key, "the edge", true);
                }
                const Vector3 normal = light.edge_u.cross(light.edge_v);
                if (!(normal.norm() > 1e-12 * light.edge_u.norm() * light.edge_v.norm())) {
                    fields.fail("edge_v", "expected an edge not parallel to edge_u, got " +
                                              detail::describe(light.edge_v));
                }
                scene.add_light(light);
            } else if (type == "disk") {
                DiskLight light{.radiance = radiance, .samples = samples};
                light.centre = fields.vector("center");
                require_length(light.centre, fields, "center", "the center", false);
                light.normal = fields.vector("normal");
                require_length(light.normal, fields, "normal", "the normal", true);
                light.radius = positive_radius();
                scene.add_light(light);
            } else {
                SphereLight light{.radiance = radiance, .samples = samples};
                light.centre = fields.vector("center");
                require_length(light.centre, fields, "center", "the center", false);
                light.radius = positive_radius();
                scene.add_light(light);
            }
        } else {
            fields.fail("type", "expected \"point\" or \"directional\", or an area light "
                                "\"rectangle\", \"disk\" or \"sphere\", got " + quote_name(type));
        }
        fields.finish();
    }
}

/// The top-level "ambient" and "background" colours (docs/scene-format.md): linear radiance,
/// each channel in [0, kMaxIntensity].
void Loader::ambient_and_background(Scene& scene) {
    Fields fields(root_, "", source_, "the scene");
    for (const char* key : {"ambient", "background"}) {
        if (!root_.contains(key)) continue;
        const Vector3 colour = fields.colour(key, Vector3::Zero());
        if (!((colour.array() >= 0.0) && (colour.array() <= kMaxIntensity)).all()) {
            fields.fail(key, "expected values in [0, " + detail::describe(kMaxIntensity) +
                                 "] (linear radiance), got " + detail::describe(colour));
        }
        if (key[0] == 'a') scene.set_ambient(colour);
        else scene.set_background(colour);
    }
}

Scene Loader::load() {
    Fields top(root_, "", source_, "the scene");
    Scene scene;
    // Asked for so finish() accepts them; each is read below.
    for (const char* key : {"description", "camera", "materials", "lights", "definitions",
                            "ambient", "background"})
        top.has(key);
    if (top.has("description")) top.string("description");
    camera(scene);
    std::map<std::string, std::uint32_t> material_index;
    materials(scene, material_index);
    lights(scene);
    ambient_and_background(scene);
    LeafPrescan(root_, source_).run();
    if (top.has("definitions")) {
        definitions_ = &root_.at("definitions");
        if (!definitions_->is_object()) {
            source_.fail("/definitions",
                         "expected an object of named shapes, got " + describe(*definitions_));
        }
        for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
            definition_index_.emplace(it.key(), &it.value());
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
        } else {
            ShapePointer built = shape(fields);
            fields.finish();
            count_leaves(*built, fields.pointer());
            scene.add_object(std::move(built), palette.front(), name);
        }
    }
    return scene;
}

/// Builds the JSON tree from the parser's events, rejecting duplicate keys (nlohmann keeps the
/// last one silently) and nesting deeper than kMaxJsonDepth, each at its JSON pointer.
///
/// It replaces nlohmann's callback parser, which after every closed child scans its parent
/// for a discarded element (quadratic in the length of "objects"), and ordered_json's
/// `operator[]`, which finds a key by a linear search (quadratic in the number of materials
/// or definitions): a key is checked once against a hash set and appended. The pointer of the
/// current place is only assembled for a message.
class SceneTreeBuilder {
public:
    using String = Json::string_t;

    SceneTreeBuilder(Json& root, const Source& source) : root_(root), source_(source) {}

    bool null() { return place(Json(nullptr)); }
    bool boolean(bool value) { return place(Json(value)); }
    bool number_integer(Json::number_integer_t value) { return place(Json(value)); }
    bool number_unsigned(Json::number_unsigned_t value) { return place(Json(value)); }
    bool number_float(Json::number_float_t value, const String&) { return place(Json(value)); }
    bool string(String& value) { return place(Json(std::move(value))); }
    bool binary(Json::binary_t& value) { return place(Json::binary(std::move(value))); }

    bool start_object(std::size_t) { return open(Json::value_t::object); }
    bool start_array(std::size_t) { return open(Json::value_t::array); }
    bool end_object() { return close(); }
    bool end_array() { return close(); }

    bool key(String& key) {
        Frame& frame = frames_.back();
        if (!frame.keys.insert(key).second) {
            source_.fail(path() + "/" + escape_pointer_token(key),
                         "duplicate key " + quote_name(key) + " (JSON keeps only one of them)");
        }
        // The key is new: appended without ordered_map's linear search.
        auto& members =
            static_cast<Json::object_t::Container&>(*frame.value->get_ptr<Json::object_t*>());
        members.emplace_back(key, nullptr);
        frame.key = std::move(key);
        return true;
    }

    template <class Exception>
    bool parse_error(std::size_t, const std::string&, const Exception& error) {
        throw error;
    }

private:
    struct Frame {
        Json* value;
        std::size_t elements = 0;
        std::string key;
        std::unordered_set<std::string> keys;
    };

    /// Where the next value goes: the root, the last key's slot, or the end of an array.
    Json* slot() {
        if (frames_.empty()) return &root_;
        Frame& frame = frames_.back();
        ++frame.elements;
        if (frame.value->is_array()) {
            auto& elements = *frame.value->get_ptr<Json::array_t*>();
            elements.emplace_back();
            return &elements.back();
        }
        return &frame.value->get_ptr<Json::object_t*>()->back().second;
    }

    bool place(Json&& value) {
        *slot() = std::move(value);
        return true;
    }

    bool open(Json::value_t type) {
        if (frames_.size() >= kMaxJsonDepth) {
            source_.fail(path(), "nesting deeper than " + std::to_string(kMaxJsonDepth) +
                                     " arrays and objects (docs/scene-format.md, Limits)");
        }
        Json* value = slot();
        *value = Json(type);
        frames_.push_back(Frame{value, 0, {}, {}});
        return true;
    }

    bool close() {
        frames_.pop_back();
        return true;
    }

    /// The pointer of the value being read.
    std::string path() const {
        std::string pointer;
        for (std::size_t i = 0; i + 1 < frames_.size(); ++i) {
            pointer += '/';
            pointer += frames_[i].value->is_array() ? std::to_string(frames_[i].elements - 1)
                                                    : escape_pointer_token(frames_[i].key);
        }
        return pointer;
    }

    Json& root_;
    const Source& source_;
    std::vector<Frame> frames_;
};

Scene load(std::string_view text, const Source& source) {
    Json root;
    try {
        SceneTreeBuilder builder(root, source);
        Json::sax_parse(text, &builder);
    } catch (const nlohmann::json::parse_error& error) {
        // what() is "[json.exception.parse_error.101] parse error at line 3, column 5: ...".
        std::string message = error.what();
        const auto start = message.find("] ");
        if (start != std::string::npos) message.erase(0, start + 2);
        throw SceneError(source.name + ": invalid JSON: " + message);
    } catch (const nlohmann::json::exception& error) {
        // A number too large for a double ("[json.exception.out_of_range.406] ...").
        std::string message = error.what();
        const auto start = message.find("] ");
        if (start != std::string::npos) message.erase(0, start + 2);
        throw SceneError(source.name + ": invalid JSON: " + message);
    }
    try {
        return Loader(root, source).load();
    } catch (const nlohmann::json::exception& error) {
        // Every value is checked before it is converted; this is a guard, not a path.
        throw SceneError(source.name + ": " + error.what());
    }
}

}  // namespace

Scene load_scene(const std::filesystem::path& path) {
    const std::string& native = path.native();
    if (native.find('\0') != std::string::npos) {
        throw SceneError(shown(native) + ": the path contains a NUL byte");
    }
    // Checked before opening: opening a FIFO blocks, and a device never ends.
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (!std::filesystem::exists(status)) {
        throw SceneError(path.string() + ": cannot open the scene file (no such file)");
    }
    if (!std::filesystem::is_regular_file(status)) {
        const char* kind =
            std::filesystem::is_directory(status) ? "a directory"
            : std::filesystem::is_fifo(status)    ? "a FIFO"
            : std::filesystem::is_character_file(status) || std::filesystem::is_block_file(status)
                ? "a device"
                : "a special file";
        throw SceneError(path.string() + ": is " + kind + ", not a regular file");
    }
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (error) throw SceneError(path.string() + ": cannot read its size: " + error.message());
    if (size > kMaxSceneFileBytes) {
        throw SceneError(path.string() + ": the file has " + std::to_string(size) +
                         " bytes; scene files are at most " + std::to_string(kMaxSceneFileBytes) +
                         " (256 MiB; docs/scene-format.md, Limits)");
    }
    std::ifstream file(path, std::ios::binary);
    if (!file) throw SceneError(path.string() + ": cannot open the scene file");
    std::ostringstream text;
    text << file.rdbuf();
    if (!file.good() && !file.eof()) throw SceneError(path.string() + ": cannot read the file");
    return load(text.str(), Source{path.string(), path.parent_path()});
}

Scene load_scene_from_string(std::string_view text, const std::string& name,
                             const std::filesystem::path& directory) {
    return load(text, Source{name, directory});
}

namespace {

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

std::span<const std::string_view> scene_shape_types() {
    static const std::vector<std::string_view> types = [] {
        std::vector<std::string_view> list;
        for (const ShapeEntry& entry : kShapeTable) list.push_back(entry.type);
        return list;
    }();
    return types;
}

}  // namespace csgrt
