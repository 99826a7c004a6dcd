#pragma once

// csgrt.Shape and csgrt.Scene as C++ types, shared by the files that bind them (scene.cpp:
// shapes, scene building and queries; rendering.cpp: render() and the cost layers).

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_set>
#include <vector>

#include "csgrt/core/shape.h"
#include "csgrt/csg/painted.h"
#include "csgrt/csg/scene.h"

namespace csgrt::python {

namespace py = pybind11;

/// A shape handed to Python: immutable and shared, so one shape may sit in several scenes.
struct PyShape {
    std::shared_ptr<const Shape> shape;
};

/// The shape a csgrt.Shape holds; ValueError naming `what` for anything else.
inline std::shared_ptr<const Shape> shape_of(const py::handle& object, const std::string& what) {
    if (!py::isinstance<PyShape>(object)) {
        throw py::value_error(what + ": expected a csgrt.Shape, got " +
                              std::string(py::str(py::type::of(object).attr("__name__"))));
    }
    return object.cast<const PyShape&>().shape;
}

/// The 3 numbers of `value` (a list, tuple or array); ValueError naming `what` otherwise.
template <class T>
Eigen::Vector3d vector3(const T& value, const char* what) {
    const py::array_t<double, py::array::c_style | py::array::forcecast> array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.size() != 3) {
        throw py::value_error(std::string(what) + ": expected 3 numbers");
    }
    return {array.at(0), array.at(1), array.at(2)};
}

/// A scene built from Python: objects, materials, lights and camera are added to `building`;
/// commit() commits a copy and publishes it, and every query reads the last published one. So
/// adding from one thread while others query is safe, and queries never see a half-built
/// scene.
class PyScene {
public:
    PyScene() = default;
    explicit PyScene(Scene scene) : building_(std::move(scene)) {}

    std::uint32_t add_object(const py::handle& shape, const py::object& material,
                             const std::string& name) {
        std::uint32_t index = 0;
        if (py::isinstance<py::str>(material)) {
            const std::string wanted = material.cast<std::string>();
            const auto& materials = building_.materials();
            auto it = std::find_if(materials.begin(), materials.end(),
                                   [&](const Material& m) { return m.name == wanted; });
            if (it == materials.end()) {
                throw py::value_error("material: no material named '" + wanted + "'");
            }
            index = static_cast<std::uint32_t>(it - materials.begin());
        } else {
            index = material.cast<std::uint32_t>();
        }
        std::lock_guard<std::mutex> lock(building_mutex_);
        return building_.add_object(shape_of(shape, "shape"), index, name);
    }
    std::uint32_t add_material(const std::string& name, const py::object& albedo) {
        std::lock_guard<std::mutex> lock(building_mutex_);
        return building_.add_material(Material{name, vector3(albedo, "albedo")});
    }
    void add_point_light(const py::object& position, const py::object& intensity) {
        PointLight light;
        light.position = vector3(position, "position");
        light.intensity =
            py::isinstance<py::float_>(intensity) || py::isinstance<py::int_>(intensity)
                ? Vector3::Constant(intensity.cast<double>())
                : vector3(intensity, "intensity");
        std::lock_guard<std::mutex> lock(building_mutex_);
        building_.add_light(light);
    }
    void add_directional_light(const py::object& direction, const py::object& radiance) {
        DirectionalLight light;
        light.direction = vector3(direction, "direction");
        light.radiance = py::isinstance<py::float_>(radiance) || py::isinstance<py::int_>(radiance)
                             ? Vector3::Constant(radiance.cast<double>())
                             : vector3(radiance, "radiance");
        std::lock_guard<std::mutex> lock(building_mutex_);
        building_.add_light(light);
    }
    void set_camera(const py::object& position, const py::object& look_at, const py::object& up,
                    double fov, const std::string& projection, double height) {
        Camera camera;
        camera.position = vector3(position, "position");
        camera.look_at = vector3(look_at, "look_at");
        camera.up = vector3(up, "up");
        camera.vertical_fov_degrees = fov;
        camera.orthographic_height = height;
        if (projection == "orthographic") {
            camera.projection = Camera::Projection::Orthographic;
        } else if (projection != "pinhole") {
            throw py::value_error("projection: expected 'pinhole' or 'orthographic', got '" +
                                  projection + "'");
        }
        camera.validate();
        std::lock_guard<std::mutex> lock(building_mutex_);
        building_.set_camera(camera);
    }

    void commit(const std::string& accelerator) {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(building_mutex_);
        check_painted_materials();
        auto next = std::make_shared<Scene>(building_);
        SceneConfig config;
        config.accelerator = accelerator;
        next->commit(config);
        std::lock_guard<std::mutex> publish(pointer_mutex_);
        committed_ = std::move(next);
    }

    /// The last committed scene; ValueError before the first commit.
    std::shared_ptr<const Scene> committed() const {
        std::lock_guard<std::mutex> lock(pointer_mutex_);
        if (!committed_) {
            throw py::value_error("scene: not committed; call commit() after adding objects");
        }
        return committed_;
    }
    std::size_t object_count() const {
        std::lock_guard<std::mutex> lock(building_mutex_);
        return building_.objects().size();
    }

private:
    /// ValueError naming the object unless every painted shape's material (csgrt.painted) is
    /// one of the scene's: the renderer would otherwise shade it with a default. Each
    /// distinct shape is visited once, without recursion.
    void check_painted_materials() const {
        std::unordered_set<const Shape*> seen;
        for (std::size_t i = 0; i < building_.objects().size(); ++i) {
            std::vector<const Shape*> stack{building_.objects()[i].shape.get()};
            while (!stack.empty()) {
                const Shape* shape = stack.back();
                stack.pop_back();
                if (!seen.insert(shape).second) continue;
                if (const auto* painted = dynamic_cast<const Painted*>(shape);
                    painted != nullptr && painted->material() >= building_.materials().size()) {
                    throw py::value_error(
                        "object " + std::to_string(i) + ": a painted shape names material " +
                        std::to_string(painted->material()) + ", but the scene has " +
                        std::to_string(building_.materials().size()) +
                        " (add_material returns the index)");
                }
                for (const Shape* child : shape->children()) stack.push_back(child);
            }
        }
    }

    mutable std::mutex building_mutex_;
    Scene building_;
    mutable std::mutex pointer_mutex_;
    std::shared_ptr<const Scene> committed_;
};

/// Adds render() and the cost layers to csgrt.Scene (rendering.cpp).
void bind_rendering(py::class_<PyScene>& scene);

}  // namespace csgrt::python
