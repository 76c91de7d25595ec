// `partsim assets decompose`: convex decomposition of a mesh file from the command line.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "partsim/assets/convex_decomposition.h"
#include "partsim/core/constants.h"

namespace partsim {
namespace {

using tools::ArgParser;
using tools::FlagValue;
using tools::RunWithExitCode;

constexpr const char* kUsage =
    "usage: partsim assets decompose MESH --out DIR [--concavity C] [--max-pieces N]\n"
    "                                [--min-pieces N] [--max-hull-vertices N] [--name BASENAME]\n"
    "  Splits MESH (OBJ, STL, DAE, ...; metres) into convex pieces with HACD and writes\n"
    "  DIR/BASENAME_K.obj and DIR/BASENAME_collision.urdf.xml (one <collision> per piece).\n"
    "  --concavity C         largest concavity of a piece (m); default 1% of the bounding-box\n"
    "                        diagonal\n"
    "  --max-pieces N        at most N pieces (default 32)\n"
    "  --min-pieces N        at least N pieces where HACD can split that far (default 1)\n"
    "  --max-hull-vertices N simplify each piece to N vertices (default: full hulls)\n"
    "  --name BASENAME       file name prefix (default: MESH's file stem)\n";

}  // namespace

int RunDecomposeCommand(int argc, char** argv) {
  // argv[0] is "decompose"
  const std::vector<std::string> args(argv + std::min(argc, 1), argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  return RunWithExitCode("partsim assets decompose", kUsage, [&] {
    std::string mesh, out, name;
    ConvexDecompositionOptions options;
    ArgParser p("partsim assets decompose");
    p.Positional([&](const FlagValue& v) {
      if (!mesh.empty()) v.Fail("unexpected argument '" + v.Text() + "' (one MESH only)");
      mesh = v.Text();
    });
    p.Option("--out", [&](const FlagValue& v) { out = v.NonEmpty("a folder name"); });
    p.Option("--concavity",
             [&](const FlagValue& v) { options.concavity = v.Number(0, false, kInf); });
    p.Option("--max-pieces", [&](const FlagValue& v) {
      options.max_pieces = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
    });
    p.Option("--min-pieces", [&](const FlagValue& v) {
      options.min_pieces = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
    });
    p.Option("--max-hull-vertices", [&](const FlagValue& v) {
      options.max_hull_vertices = static_cast<int>(v.Integer(0, std::numeric_limits<int>::max()));
      if (options.max_hull_vertices > 0 && options.max_hull_vertices < 4)
        v.Fail("--max-hull-vertices expects 0 (full hulls) or at least 4, got '" + v.Text() + "'");
    });
    p.Option("--name", [&](const FlagValue& v) { name = v.Text(); });
    p.Switch("--help", [] {});  // answered above; declared to be suggested
    p.Parse(args);
    if (mesh.empty()) p.Fail("MESH is missing");
    if (out.empty()) p.Fail("--out DIR is missing");
    if (options.min_pieces > options.max_pieces)
      p.Fail("--min-pieces must not exceed --max-pieces");

    if (name.empty()) name = std::filesystem::path(mesh).stem().string();
    const auto start = std::chrono::steady_clock::now();
    ConvexDecompositionResult r = DecomposeConvexFile(mesh, options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<std::string> files = WriteConvexPieces(r, out, name);
    std::printf("%s: %zu convex pieces in %.2f s\n", mesh.c_str(), r.pieces.size(), seconds);
    std::printf("  concavity bound     %.4g m (bounding-box diagonal %.4g m)\n", r.concavity,
                r.diagonal);
    std::printf("  coverage            %.4f of surface samples within %.4g m of a piece\n",
                r.coverage, r.coverage_tolerance);
    std::printf("  max surface dist.   %.4g m\n", r.max_surface_distance);
    std::printf("  excess              %.4f of the mesh volume (%.4g m^3) outside it\n", r.excess,
                r.mesh_volume);
    std::printf("  wrote %zu pieces and %s\n", r.pieces.size(), files.back().c_str());
    return 0;
  });
}

}  // namespace partsim
