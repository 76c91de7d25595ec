// `partsim assets decompose`: convex decomposition of a mesh file from the command line.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "partsim/assets/convex_decomposition.h"
#include "partsim/core/error.h"
#include "tools/commands.h"

namespace partsim {
namespace {

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

struct UsageError : Error {
  using Error::Error;
};

double ParseNumber(const std::string& flag, const std::string& text) {
  try {
    size_t used = 0;
    double v = std::stod(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw UsageError(flag + " expects a number, got '" + text + "'");
}

int ParseInt(const std::string& flag, const std::string& text) {
  try {
    size_t used = 0;
    int v = std::stoi(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw UsageError(flag + " expects an integer, got '" + text + "'");
}

}  // namespace

int RunDecomposeCommand(int argc, char** argv) {
  std::string mesh, out, name;
  ConvexDecompositionOptions options;
  try {
    // arguments after the command's name
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw UsageError(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "-h" || arg == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (arg == "--out") {
        out = value();
      } else if (arg == "--concavity") {
        options.concavity = ParseNumber(arg, value());
        if (!(options.concavity > 0)) throw UsageError("--concavity must be > 0");
      } else if (arg == "--max-pieces") {
        options.max_pieces = ParseInt(arg, value());
      } else if (arg == "--min-pieces") {
        options.min_pieces = ParseInt(arg, value());
      } else if (arg == "--max-hull-vertices") {
        options.max_hull_vertices = ParseInt(arg, value());
      } else if (arg == "--name") {
        name = value();
      } else if (!arg.empty() && arg[0] == '-') {
        throw UsageError("unknown option " + arg);
      } else if (mesh.empty()) {
        mesh = arg;
      } else {
        throw UsageError("unexpected argument '" + arg + "' (one MESH only)");
      }
    }
    if (mesh.empty()) throw UsageError("MESH is missing");
    if (out.empty()) throw UsageError("--out DIR is missing");
    if (options.min_pieces > options.max_pieces && options.max_pieces >= 1) {
      throw UsageError("--min-pieces must not exceed --max-pieces");
    }
  } catch (const UsageError& e) {
    std::fprintf(stderr, "decompose: %s\n%s", e.what(), kUsage);
    return 2;
  }

  try {
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
  } catch (const Error& e) {
    std::fprintf(stderr, "decompose: %s\n", e.what());
    return 1;
  }
}

}  // namespace partsim
