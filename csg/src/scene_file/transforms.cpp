#include "csgrt/core/instance.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

void require_representable(const Transform& transform, const Source& source, const JsonPointer& at,
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

ShapePointer place(ShapePointer shape, const Transform& world_from_object) {
    if (world_from_object.is_identity()) return shape;
    if (const auto* instance = dynamic_cast<const Instance*>(shape.get())) {
        return std::make_shared<Instance>(instance->shared_shape(),
                                          world_from_object * instance->world_from_object());
    }
    return std::make_shared<Instance>(std::move(shape), world_from_object);
}

Transform Loader::transform(const Json& list, const JsonPointer& pointer) const {
    // Each entry acts on the result of the ones before it: world = T_n ... T_2 T_1.
    Transform world_from_object;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const JsonPointer at = pointer.child(i);
        const Json& entry = list[i];
        if (!entry.is_object() || entry.size() != 1) {
            source_.fail(at,
                         "expected an object with one key (translate, rotate, scale, shear "
                         "or matrix), got " +
                             describe(entry));
        }
        const std::string kind = entry.begin().key();
        const Json& value = entry.begin().value();
        const JsonPointer value_at = at.child(kind);
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
                    const JsonPointer row_at = value_at.child(static_cast<std::size_t>(row));
                    if (!values.is_array() || values.size() != 4) {
                        source_.fail(row_at,
                                     "expected a row of 4 numbers, got " + describe(values));
                    }
                    for (int column = 0; column < 4; ++column) {
                        matrix(row, column) = probe.to_number(values[column], [&] {
                            return row_at.child(static_cast<std::size_t>(column));
                        });
                    }
                }
                step = Transform::from_matrix(matrix);
            } else {
                source_.fail(at.child(kind),
                             "unknown transform " + quote_name(kind) +
                                 "; expected one of: translate, rotate, scale, shear, matrix");
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

}  // namespace csgrt::detail::scene_file
