// csgrt.Scene.render and csgrt.Scene.cost_layers: the renderer's AOVs and the cost of every
// structure at every level (docs/rendering.md) as NumPy arrays.

#include <pybind11/stl.h>

#include <algorithm>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/render/cost_layers.h"
#include "csgrt/render/exr.h"
#include "csgrt/render/renderer.h"
#include "arrays.h"
#include "scene.h"

namespace csgrt::python {

namespace {

RenderSettings settings_of(int width, int height, int spp, int nthreads, std::uint64_t seed) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.samples_per_pixel = spp;
    settings.threads = nthreads;
    settings.seed = seed;
    validate(settings);
    return settings;
}

/// The structure names `requested` lists (None: every registered one), each checked.
std::vector<std::string_view> structures_of(const py::object& requested) {
    const std::span<const std::string_view> known = accelerator_names();
    if (requested.is_none()) return {known.begin(), known.end()};
    if (py::isinstance<py::str>(requested)) {
        throw py::value_error("structures: expected a list of names, got the string '" +
                              requested.cast<std::string>() + "'");
    }
    std::vector<std::string_view> names;
    for (const py::handle& item : requested) {
        const std::string name = py::str(item);
        const auto found = std::find(known.begin(), known.end(), name);
        if (found == known.end()) {
            std::string list;
            for (const std::string_view k : known) list.append(list.empty() ? "" : ", ").append(k);
            throw py::value_error("structures: unknown structure '" + name + "'; known: " + list);
        }
        names.push_back(*found);  // a view of the registry's own name, which outlives the call
    }
    return names;
}

/// A (height, width) float32 array of one channel.
py::array_t<float> channel_array(const std::vector<float>& values, int width, int height) {
    py::array_t<float> array(std::vector<py::ssize_t>{height, width});
    std::copy(values.begin(), values.end(), array.mutable_data());
    return array;
}

/// {structure: {"nodes", "primitives", "solves", "total", "build_milliseconds"}}.
py::dict layers_dict(const std::vector<CostLayer>& layers) {
    py::dict out;
    for (const CostLayer& layer : layers) {
        py::dict entry;
        entry["nodes"] = channel_array(layer.nodes, layer.width, layer.height);
        entry["primitives"] = channel_array(layer.primitives, layer.width, layer.height);
        entry["solves"] = channel_array(layer.solves, layer.width, layer.height);
        entry["total"] = channel_array(layer.total, layer.width, layer.height);
        entry["build_milliseconds"] = layer.build_milliseconds;
        out[py::str(layer.structure)] = entry;
    }
    return out;
}

py::dict render_scene(const PyScene& self, int width, int height, int spp, int nthreads,
                      std::uint64_t seed, const py::object& exr_path, bool cost_all) {
    const auto scene = self.committed();
    const RenderSettings settings = settings_of(width, height, spp, nthreads, seed);
    RenderResult result;
    std::vector<CostLayer> layers;
    {
        py::gil_scoped_release release;
        result = render(*scene, settings);
        if (cost_all) {
            const std::span<const std::string_view> names = accelerator_names();
            layers = cost_layers(*scene, settings,
                                 std::vector<std::string_view>(names.begin(), names.end()));
        }
    }
    const auto h = static_cast<py::ssize_t>(height), w = static_cast<py::ssize_t>(width);
    py::array_t<float> color(std::vector<py::ssize_t>{h, w, 4});
    py::array_t<float> depth(std::vector<py::ssize_t>{h, w});
    py::array_t<float> normal(std::vector<py::ssize_t>{h, w, 3});
    py::array_t<std::uint32_t> object_id(std::vector<py::ssize_t>{h, w});
    py::array_t<float> cost(std::vector<py::ssize_t>{h, w});
    py::array_t<float> cost_nodes(std::vector<py::ssize_t>{h, w});
    py::array_t<float> cost_primitives(std::vector<py::ssize_t>{h, w});
    py::array_t<float> cost_solves(std::vector<py::ssize_t>{h, w});
    float* c = color.mutable_data();
    float* d = depth.mutable_data();
    float* n = normal.mutable_data();
    std::uint32_t* id = object_id.mutable_data();
    float* k = cost.mutable_data();
    float* kn = cost_nodes.mutable_data();
    float* kp = cost_primitives.mutable_data();
    float* ks = cost_solves.mutable_data();
    const auto& pixels = result.image.pixels();
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const Pixel& p = pixels[i];
        c[4 * i] = p.red, c[4 * i + 1] = p.green, c[4 * i + 2] = p.blue, c[4 * i + 3] = p.alpha;
        d[i] = p.depth;
        n[3 * i] = p.normal_x, n[3 * i + 1] = p.normal_y, n[3 * i + 2] = p.normal_z;
        id[i] = p.object_id;
        k[i] = p.cost;
        kn[i] = p.cost_nodes, kp[i] = p.cost_primitives, ks[i] = p.cost_solves;
    }
    if (!exr_path.is_none()) {
        ExrMetadata metadata;
        metadata.camera = scene->camera();
        metadata.accelerator = std::string(scene->accelerator_name());
        metadata.accelerator_build_milliseconds = scene->accelerator_stats().build_milliseconds;
        metadata.samples_per_pixel = spp;
        metadata.objects = exr_objects(*scene);
        const std::filesystem::path path = py::str(exr_path).cast<std::string>();
        py::gil_scoped_release release;
        write_render_files(path, result.image, metadata, ToneMapping{}, layers);
    }
    py::dict out = named_results({{"color", color},
                                  {"depth", depth},
                                  {"normal", normal},
                                  {"object_id", object_id},
                                  {"cost", cost},
                                  {"cost_nodes", cost_nodes},
                                  {"cost_primitives", cost_primitives},
                                  {"cost_solves", cost_solves}});
    out["stats"] = named_results({{"primary_rays", py::int_(result.stats.primary_rays)},
                                  {"shadow_rays", py::int_(result.stats.shadow_rays)},
                                  {"seconds", py::float_(result.stats.seconds)}});
    if (cost_all) out["cost_layers"] = layers_dict(layers);
    return out;
}

py::dict scene_cost_layers(const PyScene& self, int width, int height, const py::object& structures,
                           int nthreads) {
    const auto scene = self.committed();
    const RenderSettings settings = settings_of(width, height, 1, nthreads, 0);
    const std::vector<std::string_view> names = structures_of(structures);
    std::vector<CostLayer> layers;
    {
        py::gil_scoped_release release;
        layers = cost_layers(*scene, settings, names);
    }
    return layers_dict(layers);
}

}  // namespace

void bind_rendering(py::class_<PyScene>& scene) {
    using namespace pybind11::literals;
    scene.def("render", &render_scene, "width"_a, "height"_a, "spp"_a = 1, "nthreads"_a = 0,
              "seed"_a = 0, "exr_path"_a = py::none(), "cost_all"_a = false, R"doc(
Renders the committed scene through its camera (docs/rendering.md) and returns a dict of
arrays, rows from the top: ``color`` (height, width, 4) float32 linear RGBA, premultiplied;
``depth`` (height, width) float32, inf for background; ``normal`` (height, width, 3);
``object_id`` (height, width) uint32, 2**32 - 1 for background; ``cost`` (height, width: the
centre ray's box tests, primitive tests and root solves at every level, summed) and its parts
``cost_nodes``, ``cost_primitives``, ``cost_solves``; and ``stats`` (primary_rays,
shadow_rays, seconds). With cost_all, also ``cost_layers`` as cost_layers() returns it for
every structure (``csgrt render --cost-all``). With exr_path, also writes the multi-channel
EXR and its PNG previews as `csgrt render` does (with cost_all, the layers and the contact
sheet too). The image does not depend on nthreads.
)doc");
    scene.def("cost_layers", &scene_cost_layers, "width"_a, "height"_a, "structures"_a = py::none(),
              "nthreads"_a = 0, R"doc(
What the camera's centre rays would cost if every structure of the scene (the top level's,
each compound's, each mesh's) were one kind: for each name in ``structures`` (None: every
registered one, csgrt.accelerator_names()), the scene rebuilt with it at every level and its
centre rays traced and counted, no shading (docs/rendering.md, "The cost of every structure").
Returns {name: {"nodes", "primitives", "solves", "total": (height, width) float32 counts,
"build_milliseconds": the rebuilt scene's summed structure build times}}.
)doc");
}

}  // namespace csgrt::python
