// `partsim annotate`: the mobility annotation tool (docs/annotation.md) served to a browser: the
// Annotator's routes and services on a Viewer with no scene, its requests run on this thread.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "net_options.h"
#include "partsim/viewer/annotator.h"
#include "partsim/viewer/viewer.h"

namespace partsim::tools {
namespace {

constexpr char kAnnotateUsage[] = R"(usage:
  partsim annotate INPUT --out DIR [--review] [--strict] [--port P] [--address A] [--token T]
                   [--allow-origin O]... [--duration S]

Turns a part-segmented object into a PartNet-Mobility object by the question-answering procedure
of the SAPIEN paper's annotation tool (docs/annotation.md): open the printed URL, answer the
questions (which parts move, which are fixed together, hinges, sliders and screws with their
axes and limits, whether each root is fixed, free or an outlier) and export.
  INPUT             a folder holding result.json (PartNet's part hierarchy) and the meshes its
                    leaves name, in objs/ or textured_objs/ (partsim assets generate
                    --unannotated writes such folders)
  --out DIR         the session: DIR/session.json keeps every answer (saved after each one; run
                    the command again on DIR to resume) and the export goes to DIR/object/
  --review          review mode: once every question is answered, the page replays each joint
                    and a reviewer accepts or rejects it (saved in DIR/session.json)
  --strict          a part mesh that is not manifold is an error (default: a warning)
  --port P          the page's port (default 8000; 0 picks a free one)
  --address A       interface to listen on (default 127.0.0.1)
  --token T         the token the page must carry (default: a random one, in the URL)
  --allow-origin O  web pages of origin O may connect (repeatable; default: pages of this
                    machine)
  --duration S      stop after S wall-clock seconds (default: until Ctrl-C or SIGTERM)
)";

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

}  // namespace

int RunAnnotateCommand(int argc, char** argv) {
  AnnotatorOptions options;
  NetOptions net;
  net.port = 8000;
  double duration = 0;
  const std::vector<std::string> args(argv, argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::fputs(kAnnotateUsage, stdout);
    return 0;
  }
  const int parsed = RunWithExitCode("partsim annotate", "see partsim annotate --help\n", [&] {
    ArgParser p("partsim annotate");
    p.Positional([&](const FlagValue& v) {
      if (!options.input.empty()) v.Fail("unexpected extra argument '" + v.Text() + "'");
      options.input = v.Text();
    });
    AddNetOptions(&p, &net);
    p.Option("--out", [&](const FlagValue& v) { options.out = v.NonEmpty("a folder"); });
    p.Switch("--review", [&] { options.review = true; });
    p.Switch("--strict", [&] { options.strict = true; });
    p.Option("--duration", [&](const FlagValue& v) { duration = v.Number(0, false, 1e9); });
    p.Switch("--help", [] {});  // answered above; declared to be suggested
    p.Parse(args);
    if (options.input.empty()) p.Fail("missing INPUT (a folder with result.json)");
    if (options.out.empty()) p.Fail("missing --out DIR (the session folder)");
    return 0;
  });
  if (parsed != 0) return parsed;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  try {
    Annotator annotator(options);
    const AnnotationSession& s = annotator.Store().Session();
    std::printf("partsim annotate: %zu part nodes, %zu meshes; %zu answers saved in %s\n",
                s.Input().nodes.size(), s.Input().meshes.size(), s.Answers().size(),
                options.out.c_str());
    for (const std::string& w : s.Input().warnings) std::printf("  warning: %s\n", w.c_str());
    ViewerOptions vo;
    net.ApplyTo(&vo);
    Viewer viewer(nullptr, vo);
    annotator.AttachTo(&viewer);
    try {
      viewer.Start();
    } catch (const std::exception& e) {
      throw CannotListen(e);
    }
    std::string url = viewer.GetUrl();
    const size_t q = url.find("/?");
    if (q != std::string::npos) url.replace(q, 2, "/annotate.html?");
    std::printf(
        "partsim annotate: open %s%s; stop with Ctrl-C\n", url.c_str(),
        viewer.GetWebRoot().empty() ? " (web page not built: bash scripts/build_web.sh)" : "");
    std::fflush(stdout);
    const auto t0 = std::chrono::steady_clock::now();
    annotator.Run([&] {
      return !g_stop && !viewer.IsClosed() &&
             !(duration > 0 &&
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >=
                   duration);
    });
    viewer.Stop();
    std::printf("partsim annotate: stopped with %zu answers saved\n",
                annotator.Store().Session().Answers().size());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim annotate: %s\n", e.what());
    return 1;
  }
}

}  // namespace partsim::tools
