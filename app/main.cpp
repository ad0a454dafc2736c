// main.cpp - the `viewer` executable: the window (default) and the headless commands
//   viewer [SCENE]                       open the viewer (demo scene when SCENE is omitted)
//   viewer render SCENE --out shot.png   render one image offscreen with any backend/settings
//   viewer compare SCENE --out DIR       render every backend, write images, diffs, a table
//   viewer inspect SCENE --at X,Y        where a pixel comes from in each backend (JSON)
//   viewer demo-shots --out DIR          the demo scene with every backend (./run headless)
//   viewer convert SCENE --out x.json    save any scene in the native JSON format
//   viewer --version                     "viewer 0.1.0 (git a33dede)"
// SCENE is a file (.json .gltf .glb .obj .off .ply .stl) or the word "demo".
#include "build_info.h"
#include "cli.h"
#include "ui/viewer.h"

#include <CLI/CLI.hpp>

#include <cstdio>

int main(int argc, char** argv) {
    CLI::App app{
        "Scene-graph viewer: GL rasterization, CPU rasterizer and CPU ray caster side by side.\n"
        "Without a subcommand, opens the viewer window on SCENE (default: the bundled demo)."};
    app.set_help_all_flag("--help-all", "Print help for all subcommands");
    app.set_version_flag("--version", std::string("viewer ") + buildinfo::kVersion + " (git " + buildinfo::kGitRevision + ")",
                         "Print the version and the git revision it was built from, then exit");
    app.require_subcommand(0, 1);

    std::string windowScene;
    app.add_option("scene", windowScene, "Scene file to open (.json .gltf .glb .obj .off .ply .stl) or 'demo'");
    // Hidden window automation (tests, docs screenshots); see ui/src/viewer.cpp "automation":
    //   viewer [SCENE] --automate script.txt
    //   viewer [SCENE] --frames N [--screenshot window.png] [--backend raster] [--view split]
    ui::ViewerOptions windowOpts;
    std::string windowSize;
    app.add_option("--automate", windowOpts.script, "Run a window automation script")->group("");
    app.add_option("--frames", windowOpts.frames, "Run N frames, wait for the images, quit")->group("");
    app.add_option("--screenshot", windowOpts.screenshot, "With --frames: PNG of the whole window")->group("");
    app.add_option("--backend", windowOpts.backend, "Initial backend")->group("");
    app.add_option("--view", windowOpts.view, "Initial view: single, split, split3, difference")->group("");
    app.add_option("--window-size", windowSize, "Window size WxH")->group("");
    app.add_option("--timeout", windowOpts.timeoutSeconds, "Automation time limit in seconds")->group("");
    bool manOptions = false;   // the build's man page: the parameter tables' options as roff
    app.add_flag("--man-options", manOptions, "Print the settings options as man page text")->group("");

    cli::RenderArgs renderArgs;
    CLI::App* render = app.add_subcommand("render", "Render SCENE offscreen to a PNG (no window needed)");
    cli::addRenderOptions(*render, renderArgs, cli::Command::Render);

    cli::RenderArgs compareArgs;
    compareArgs.size = "960x540";
    CLI::App* compare = app.add_subcommand("compare", "Render SCENE with every backend; write images, pairwise diffs and a timing/difference table");
    cli::addRenderOptions(*compare, compareArgs, cli::Command::Compare);

    cli::RenderArgs inspectArgs;
    inspectArgs.backend = "all";
    CLI::App* inspect = app.add_subcommand("inspect", "Print where pixel X,Y of SCENE comes from in each backend, as JSON");
    cli::addRenderOptions(*inspect, inspectArgs, cli::Command::Inspect);

    std::string convertIn, convertOut;
    bool convertOverwrite = false;
    CLI::App* convert = app.add_subcommand("convert", "Load SCENE (any supported format or 'demo') and save it as a native JSON scene");
    convert->add_option("scene", convertIn, "Scene file or 'demo'")->required();
    convert->add_option("--out", convertOut, "Output .json file")->required();
    convert->add_flag("--overwrite", convertOverwrite, "Replace an existing output file");

    std::string demoOut = "out/demo";
    std::string demoSize = "960x540";
    CLI::App* demo = app.add_subcommand("demo-shots", "Render the demo scene with every backend into a folder");
    demo->add_option("--out", demoOut, "Output folder")->capture_default_str();
    demo->add_option("--size", demoSize, "Image size WxH")->capture_default_str();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) { return app.exit(e); }

    if (manOptions) {
        std::fputs(cli::manPageOptions().c_str(), stdout);
        return 0;
    }
    if (*render) return cli::runRender(renderArgs);
    if (*compare) return cli::runCompare(compareArgs);
    if (*inspect) return cli::runInspect(inspectArgs);
    if (*demo) return cli::runDemoShots(demoOut, demoSize);
    if (*convert) return cli::runConvert(convertIn, convertOut, convertOverwrite);
    windowOpts.scene = windowScene;
    if (!windowSize.empty() && std::sscanf(windowSize.c_str(), "%dx%d", &windowOpts.width, &windowOpts.height) != 2) {
        std::fprintf(stderr, "viewer: error: --window-size '%s': expected WIDTHxHEIGHT\n", windowSize.c_str());
        return 1;
    }
    return ui::runViewer(windowOpts);
}
