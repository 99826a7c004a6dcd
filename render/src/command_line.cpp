#include "csgrt/render/command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <ostream>
#include <string>
#include <vector>

#include "command_line_internal.h"
#include "csgrt/accel/factory.h"

namespace csgrt {

namespace command_line {

std::string available_structures() {
    std::string list = "auto";
    for (std::string_view name : accelerator_names()) list.append(", ").append(name);
    return list;
}

}  // namespace command_line

namespace {

/// Newlines turned into spaces, so every error is one line.
std::string one_line(std::string text) {
    std::replace(text.begin(), text.end(), '\n', ' ');
    std::replace(text.begin(), text.end(), '\r', ' ');
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

/// The scene file every subcommand takes as its one positional argument.
void add_scene_argument(CLI::App& subcommand, std::string& path) {
    subcommand.add_option("scene", path, "The JSON scene file")
        ->required()
        ->check(CLI::ExistingFile)
        ->type_name("SCENE.json");
}

}  // namespace

int run_csgrt(int argc, const char* const* argv, CommandLineStreams streams) {
    using namespace command_line;
    CLI::App app{
        "csgrt renders scenes of analytic shapes, CSG solids and meshes described in "
        "JSON (docs/scene-format.md), and checks them.",
        "csgrt"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "csgrt " CSGRT_VERSION);
    app.footer(
        "Examples:\n"
        "  csgrt render data/scenes/showcase.json -o out.exr --spp 16\n"
        "  csgrt info data/scenes/showcase.json\n"
        "  csgrt validate my_scene.json\n"
        "\n"
        "Run 'csgrt SUBCOMMAND --help' for a subcommand's options. Exit status: 0 on success, 1 "
        "when a scene cannot be loaded or a render fails, 2 for a usage error (bad option, "
        "missing file); every error is one line on stderr.\n"
        "\n"
        "Documentation: 'man csgrt', and " CSGRT_DOC_DIR
        " (README.md, rendering.md,\n"
        "scene-format.md, the JSON Schema scene.schema.json, example scenes in examples/).");

    RenderOptions options;
    CLI::App* render = app.add_subcommand("render", "Render a scene to an EXR with PNG previews");
    render->footer(
        "Writes OUT.exr with the channels R G B A (half, linear, premultiplied), Z (distance\n"
        "along the centre camera ray; inf for background), N.X N.Y N.Z (world normal) and the\n"
        "layer cost (cost.nodes, cost.primitives, cost.solves, cost.total: the centre ray's box\n"
        "tests, primitive tests and root solves at every level) in its part \"rgba\", and id "
        "(uint\n"
        "object index; 4294967295 for background, named by the idManifest) in its part \"id\";\n"
        "beside it OUT.png (colour, tone mapped by --tonemap, sRGB) and OUT.cost.png (cost in\n"
        "false colour, with a scale). Prints one summary line: time, Mrays/s, the structure (with\n"
        "--json, one JSON object instead); --stats adds a table of rays, hits, the structure's "
        "work and time per stage.");
    add_scene_argument(*render, options.scene);
    render->add_option("-o,--output", options.output, "The EXR file to write")
        ->required()
        ->type_name("OUT.exr");
    render->add_option("--width", options.width, "Image width in pixels")
        ->check(CLI::Range(1, kMaxImageSize))
        ->capture_default_str();
    render->add_option("--height", options.height, "Image height in pixels")
        ->check(CLI::Range(1, kMaxImageSize))
        ->capture_default_str();
    render
        ->add_option("--spp", options.samples_per_pixel,
                     "Samples per pixel on a stratified jittered grid")
        ->check(CLI::Range(1, kMaxSamplesPerPixel))
        ->capture_default_str();
    render->add_option("--threads", options.threads, "Worker threads; 0 uses every core")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    std::vector<std::string> structures = {"auto"};
    for (std::string_view name : accelerator_names()) structures.emplace_back(name);
    render
        ->add_option("--accel", options.accelerator,
                     "The structure over the scene's objects: " + available_structures() +
                         " ('csgrt info' shows what auto picks)")
        ->check(CLI::IsMember(structures))
        ->capture_default_str()
        ->type_name("NAME");
    render
        ->add_option("--tonemap", options.tone_curve,
                     "The PNG preview's tone curve: filmic (ACES fit), reinhard (x/(1+x)) or "
                     "clamp; the EXR stays linear")
        ->capture_default_str()
        ->type_name("CURVE");
    render
        ->add_option("--exposure", options.exposure_stops,
                     "Stops of exposure applied before the PNG's tone curve (linear * 2^EV)")
        ->capture_default_str()
        ->type_name("EV");
    render->add_flag("--timing-in-header", options.timing_in_header,
                     "Record acceleratorBuildMs and renderSeconds in the EXR header (files of "
                     "identical renders then differ)");
    render->add_flag("--stats", options.statistics,
                     "Print a statistics table after the summary: rays by kind, hits by shape "
                     "kind, the structure's work, time per stage");
    render->add_flag("--cost-all", options.cost_all,
                     "Also count the centre rays' cost with every registered structure at every "
                     "level: a cost layer per structure in the EXR (cost.bvh.total, ...; build "
                     "times in the header) and OUT.cost-all.png, the layers on one scale");
    render->add_flag("--json", options.json, "Print the summary as one JSON object");

    std::string scene_path;
    bool info_json = false;
    CLI::App* info = app.add_subcommand("info", "Describe a scene and the structure 'auto' builds");
    info->footer(
        "Counts every shape by kind through the whole tree (instances, booleans, compounds;\n"
        "a shared shape once per use), and prints materials, lights, camera, world bounds\n"
        "and the structure 'auto' picks for the top-level objects, with the reason.");
    add_scene_argument(*info, scene_path);
    info->add_flag("--json", info_json, "Print the description as one JSON object");
    CLI::App* validate =
        app.add_subcommand("validate", "Check a scene file (errors only; exit 0 when usable)");
    validate->footer(
        "Loads and commits the scene. Prints nothing and exits 0 when it is usable; otherwise\n"
        "prints the first error (file, place in the file, what was expected) and exits 1.");
    add_scene_argument(*validate, scene_path);

    try {
        // CLI11 would report a mistyped subcommand as a missing one.
        const std::string first = argc > 1 ? argv[1] : "";
        if (!first.empty() && first[0] != '-' && first != "render" && first != "info" &&
            first != "validate") {
            throw UsageError("unknown subcommand '" + first +
                             "' (expected render, info or validate; see 'csgrt --help')");
        }
        try {
            app.parse(argc, argv);
        } catch (const CLI::Success& success) {
            return app.exit(success, streams.out, streams.err);  // --help, --version
        } catch (const CLI::ParseError& error) {
            throw UsageError(std::string(error.what()) + " (see 'csgrt --help')");
        }
        if (render->parsed()) {
            render_command(options, streams);
        } else if (info->parsed()) {
            info_command(scene_path, info_json, streams);
        } else {
            validate_command(scene_path);
        }
        return 0;
    } catch (const UsageError& error) {
        streams.out.flush();
        streams.err << "csgrt: error: " << one_line(error.what()) << std::endl;
        return kUsageErrorStatus;
    } catch (const std::exception& error) {
        streams.out.flush();
        streams.err << "csgrt: error: " << one_line(error.what()) << std::endl;
        return 1;
    }
}

}  // namespace csgrt
