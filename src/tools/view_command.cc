// `partsim view`: an asset (or a scene file, or the built-in cabinet) simulated in real time on a
// SimServer, with the browser viewer attached; `partsim view --dataset ROOT`: the gallery of a
// PartNet-Mobility tree (partsim/viewer/gallery.h), the viewer in synchronous mode on this thread.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "net_options.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/physics/scene.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/server/sim_server.h"
#include "partsim/viewer/gallery.h"
#include "partsim/viewer/viewer.h"

namespace partsim::tools {
namespace {

namespace fs = std::filesystem;

constexpr char kViewUsage[] = R"(usage:
  partsim view [FILE.urdf | FOLDER | FILE.xml | SCENE.json] [--port P] [--address A] [--paused]
               [--rate R] [--token T] [--allow-origin O]... [--duration S]
  partsim view --dataset ROOT [--category C] [--port P] [--address A] [--rate R] [--token T]
               [--allow-origin O]... [--duration S]

Simulates the asset in real time (a URDF file or a PartNet-Mobility folder at the origin with its
root fixed, an MJCF model whole, a JSON scene file's objects at their poses, or with nothing
given the built-in cabinet) on a ground under lights, with a camera "front" looking at it, and serves the browser
viewer (docs/viewer.md): open the printed URL. The page orbits the camera, moves joints with
sliders, pauses, steps and resets the simulation, and shows the camera's pictures. For a remote
machine: ssh -L 8000:127.0.0.1:8000 HOST, then open the URL on your own.

With --dataset, the page is a gallery of the PartNet-Mobility tree under ROOT (every folder
holding a mobility.urdf, at any depth; real or from partsim assets generate): thumbnails rendered
by partsim, a category and a text filter; a click opens the object, simulated with its joints
sweeping their ranges (one cycle per 4 s). Folders that cannot be read are listed on the page.
  --dataset ROOT    the tree to show
  --category C      only objects of category C (meta.json model_cat, e.g. StorageFurniture)
  --port P          the page's port (default 8000; 0 picks a free one)
  --address A       interface to listen on (default 127.0.0.1; anything else is reachable from
                    other machines, which still need the token)
  --paused          start paused (the page's resume and step buttons run it; not with --dataset)
  --rate R          physics rate in Hz (default 500)
  --token T         the token the page must carry (default: a random one, in the URL)
  --allow-origin O  web pages of origin O may connect (repeatable; default: pages of this
                    machine)
  --duration S      stop after S wall-clock seconds (default: until Ctrl-C or SIGTERM)
)";

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

/// partsim view --dataset: the gallery, the viewer in synchronous mode on this thread.
int RunGallery(const std::string& root, const std::string& category, double timestep,
               const NetOptions& net, double duration) {
  std::unique_ptr<Gallery> gallery;
  try {
    GalleryOptions go;
    go.root = root;
    go.category = category;
    go.timestep = timestep;
    const auto t0 = std::chrono::steady_clock::now();
    gallery = std::make_unique<Gallery>(go);
    std::printf("partsim view: %zu objects under %s (%zu folders could not be read) in %.1f s\n",
                gallery->Objects().size(), root.c_str(), gallery->Errors().size(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    for (const GalleryError& e : gallery->Errors())
      std::fprintf(stderr, "partsim view: %s: %s\n", e.name.c_str(), e.error.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim view: %s\n", e.what());
    return 2;
  }
  try {
    ViewerOptions vo;
    net.ApplyTo(&vo);
    Viewer viewer(nullptr, vo);
    gallery->AttachTo(&viewer);
    try {
      viewer.Start();
    } catch (const std::exception& e) {
      throw CannotListen(e);
    }
    std::printf("  open %s in a browser%s; stop with Ctrl-C\n", viewer.GetUrl().c_str(),
                viewer.GetWebRoot().empty()
                    ? " (web page not built: bash scripts/build_web.sh; the gallery is served)"
                    : "");
    std::fflush(stdout);
    const auto t0 = std::chrono::steady_clock::now();
    gallery->Run([&] {
      return !g_stop &&
             !(duration > 0 &&
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >=
                   duration);
    });
    viewer.Stop();
    std::printf("partsim view: stopped%s\n",
                g_stop || duration > 0 ? "" : "; the page closed the viewer");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim view: %s\n", e.what());
    return 1;
  }
}

}  // namespace

int RunViewCommand(int argc, char** argv) {
  std::string file, dataset, category;
  NetOptions net;
  net.port = 8000;
  double rate = 500, duration = 0;
  bool paused = false;
  const std::vector<std::string> args(argv, argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::fputs(kViewUsage, stdout);
    return 0;
  }
  const int parsed = RunWithExitCode("partsim view", "see partsim view --help\n", [&] {
    ArgParser p("partsim view");
    p.Positional([&](const FlagValue& v) {
      if (!file.empty()) v.Fail("unexpected extra argument '" + v.Text() + "'");
      file = v.Text();
    });
    AddNetOptions(&p, &net);
    p.Switch("--paused", [&] { paused = true; });
    p.Option("--rate", [&](const FlagValue& v) { rate = v.Number(0, false, 1e9); });
    p.Option("--duration", [&](const FlagValue& v) { duration = v.Number(0, false, 1e9); });
    p.Option("--dataset", [&](const FlagValue& v) { dataset = v.NonEmpty("a folder"); });
    p.Option("--category", [&](const FlagValue& v) { category = v.NonEmpty("a category"); });
    p.Switch("--help", [] {});  // answered above; declared to be suggested
    p.Parse(args);
    return 0;
  });
  if (parsed != 0) return parsed;
  // from here on Ctrl-C and SIGTERM end the command cleanly (exit 0), whenever they come: a
  // client that reads the printed URL may stop it at once
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  if (!dataset.empty() || !category.empty()) {
    if (dataset.empty()) {
      std::fprintf(stderr, "partsim view: --category needs --dataset ROOT\n");
      return 2;
    }
    if (!file.empty() || paused) {
      std::fprintf(stderr, "partsim view: --dataset takes no %s\n",
                   file.empty() ? "--paused" : ("FILE ('" + file + "')").c_str());
      return 2;
    }
    return RunGallery(dataset, category, 1.0 / rate, net, duration);
  }

  try {
    // the scene: the asset on a ground, lit, with a camera looking at it
    SceneConfig cfg;
    cfg.timestep = 1.0 / rate;
    Scene scene(cfg);
    scene.AddGround(0.0);
    AddServedObjects(&scene, file, Pose());
    // an object (a PartNet-Mobility folder, a URDF) stands on the ground, as in the gallery: its
    // frame is near its middle, which would sink its lower half; a scene file or MJCF model
    // keeps the poses it gives
    const std::string ext = fs::path(file).extension().string();
    const bool placed = file.empty() || ext == ".json" || ext == ".xml";
    if (!placed)
      for (Articulation& a : scene.GetArticulations()) PlaceOnGround(a, 0.002);
    SetAmbientLight(scene, Eigen::Vector3f(0.35f, 0.35f, 0.35f));
    AddDirectionalLight(scene, Eigen::Vector3d(-1, -0.5, -1), Eigen::Vector3f(0.8f, 0.8f, 0.8f));
    // the camera "front" looks at the front right: PartNet-Mobility objects face -x, the
    // built-in cabinet +x
    Camera camera = AddCamera(scene, "front", 640, 480, 1.0, 0.05, 20.0);
    const double side = file.empty() ? 1.0 : -1.0;
    camera.SetLocalPose(
        CameraLookAt(Eigen::Vector3d(1.8 * side, -1.8 * side, 1.4), Eigen::Vector3d(0, 0, 0.4)));

    SimServer sim(&scene, nullptr);
    ViewerOptions vo;
    net.ApplyTo(&vo);
    Viewer viewer(&scene, vo);
    viewer.Attach(&sim);
    try {
      viewer.Start();
    } catch (const std::exception& e) {
      throw CannotListen(e);
    }
    sim.Start(paused);
    std::printf("partsim view: %zu articulations, %zu actors, %g Hz physics%s\n",
                scene.GetArticulations().size(), scene.GetActors().size(), rate,
                paused ? ", paused" : "");
    std::printf("  open %s in a browser%s; stop with Ctrl-C\n", viewer.GetUrl().c_str(),
                viewer.GetWebRoot().empty()
                    ? " (web page not built: bash scripts/build_web.sh; the scene is served)"
                    : "");
    std::fflush(stdout);

    const auto t0 = std::chrono::steady_clock::now();
    while (!g_stop && !viewer.IsClosed()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      if (duration > 0 &&
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >= duration)
        break;
    }
    sim.Stop();
    viewer.Stop();
    std::printf("partsim view: stopped after %lld steps (%.3f s simulated)%s\n",
                sim.GetClockSteps(), sim.GetClockSeconds(),
                g_stop ? "" : (duration > 0 ? "" : "; the page closed the viewer"));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim view: %s\n", e.what());
    return 1;
  }
}

}  // namespace partsim::tools
