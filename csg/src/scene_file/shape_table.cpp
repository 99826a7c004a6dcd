#include <memory>

#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/complement.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/ready_made.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/mesh/mesh.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

namespace {

std::string solid_requirement(const ListItem& item) {
    std::string kind(item.shape->kind());
    if (kind == "mesh") kind = "an open mesh (one with a boundary, not a closed surface)";
    return "expected a solid (a closed shape: sphere, box, capped cylinder or cone, torus, "
           "half_space, boolean, not, ready-made solid, compound of solids, closed mesh) as a "
           "boolean operand, "
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

std::vector<ShapePointer> copy_shapes(std::vector<Copy> copies) {
    std::vector<ShapePointer> shapes;
    shapes.reserve(copies.size());
    for (Copy& copy : copies) shapes.push_back(std::move(copy.shape));
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
    {"half_space",
     [](Fields& f, Loader&) -> ShapePointer {
         const Point3 point = f.vector("point", Point3::Zero());
         return std::make_shared<HalfSpace>(point, f.vector("normal"));
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
         return std::make_shared<Compound>(copy_shapes(loader.copies(f, false)),
                                           compound_config(f));
     }},
    {"array",
     [](Fields& f, Loader& loader) -> ShapePointer {
         return std::make_shared<Compound>(copy_shapes(loader.copies(f, false)),
                                           compound_config(f));
     }},
    {"not",
     [](Fields& f, Loader& loader) -> ShapePointer {
         ListItem operand{loader.shape(f.required("operand", "a solid shape node"),
                                       f.pointer("operand"), "the operand of \"not\""),
                          f.pointer("operand")};
         return std::make_shared<Complement>(operand_shapes({operand}, loader.source()).front());
     }},
    {"ref",
     [](Fields& f, Loader& loader) -> ShapePointer {
         return loader.definition(f.string("definition"), f.pointer("definition"));
     }},
};

}  // namespace

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

[[noreturn]] void rethrow_invalid(const InvalidParameter& error, const Fields& fields,
                                  const Json& node, bool angles) {
    std::string message = error.what();
    JsonPointer pointer = fields.pointer();
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

}  // namespace csgrt::detail::scene_file

namespace csgrt {

std::span<const std::string_view> scene_shape_types() {
    static const std::vector<std::string_view> types = [] {
        std::vector<std::string_view> list;
        for (const auto& entry : detail::scene_file::kShapeTable) list.push_back(entry.type);
        return list;
    }();
    return types;
}

}  // namespace csgrt
