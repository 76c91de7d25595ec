// `partsim learn ...`: SAC on the door and drawer tasks, the SAPIEN paper's protocol. The
// command is Python (partsim.learn, on PyTorch); this runs `python3 -m partsim.learn` with the
// arguments as they are, with the package that goes with this program on the path (PackageParent).
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.h"

namespace partsim::tools {

namespace fs = std::filesystem;

namespace {

// The folder to put on PYTHONPATH so that `python3 -m partsim.learn` imports the partsim that
// goes with the program `exe`, or "" when the interpreter's own path has it: the build tree
// (build/partsim beside build/python/partsim), an install prefix (PREFIX/bin/partsim and
// PREFIX/<PARTSIM_PYTHON_INSTALL_DIR>/partsim, any prefix) or a wheel (site-packages/partsim/
// bin/partsim inside the package).
std::string PackageParent(const fs::path& exe) {
  const fs::path bin = exe.parent_path();
  std::vector<fs::path> candidates = {bin / "python", bin / "../.."};
#ifdef PARTSIM_PYTHON_INSTALL_DIR
  candidates.push_back(bin / ".." / PARTSIM_PYTHON_INSTALL_DIR);
#endif
  for (const fs::path& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c / "partsim/learn/__main__.py", ec) &&
        fs::is_regular_file(c / "partsim/__init__.py", ec))
      return fs::weakly_canonical(c, ec).string();
  }
  return "";
}

}  // namespace

int RunLearnCommand(int argc, char** argv) {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::string pythonpath = ec ? std::string() : PackageParent(exe);
  // the build tree's program runs the interpreter the build is for (the project's venv, with
  // Gymnasium), an installed one Debian's, unless PARTSIM_PYTHON names another (the wheel's
  // `partsim` entry point names the interpreter it was installed for)
  std::string python = "/usr/bin/python3";
#ifdef PARTSIM_BUILD_PYTHON
  if (!ec && pythonpath == fs::weakly_canonical(exe.parent_path() / "python", ec).string() &&
      fs::exists(PARTSIM_BUILD_PYTHON, ec))
    python = PARTSIM_BUILD_PYTHON;
#endif
  if (const char* chosen = std::getenv("PARTSIM_PYTHON"); chosen != nullptr && *chosen != '\0')
    python = chosen;
  if (const char* old = std::getenv("PYTHONPATH"); old != nullptr && *old != '\0')
    pythonpath = pythonpath.empty() ? std::string(old) : pythonpath + ":" + old;
  if (!pythonpath.empty()) setenv("PYTHONPATH", pythonpath.c_str(), 1);

  std::vector<std::string> args = {python, "-m", "partsim.learn"};
  for (int i = 0; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(stdout);
  execv(python.c_str(), cargs.data());
  std::fprintf(stderr,
               "partsim learn: cannot run the Python interpreter '%s' (%s); partsim learn needs "
               "python3 with PyTorch and Gymnasium (set PARTSIM_PYTHON to use another "
               "interpreter)\n",
               python.c_str(), std::strerror(errno));
  return 1;
}

}  // namespace partsim::tools
