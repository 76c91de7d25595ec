// The commands that are Python: `partsim learn ...` (SAC on the door and drawer tasks, the SAPIEN
// paper's protocol; partsim.learn, on PyTorch) and any list-shaped command given `--ray`
// (partsim.distributed, which runs its shards as Ray tasks). This runs `python3 -m MODULE` with
// the arguments as they are, with the package that goes with this program on the path
// (PackageParent).
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

// The folder to put on PYTHONPATH so that `python3 -m partsim.<module>` imports the partsim that
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

int RunPythonModule(const char* module, const char* what, int argc, char** argv) {
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
  // `python3 -m` puts the working folder first on the module path: a stray ray.py or torch.py
  // there would shadow the real module. Python 3.11 leaves it out with this (older ones ignore it)
  setenv("PYTHONSAFEPATH", "1", 0);

  std::vector<std::string> args = {python, "-m", module};
  for (int i = 0; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(stdout);
  execv(python.c_str(), cargs.data());
  std::fprintf(stderr,
               "partsim: cannot run the Python interpreter '%s' (%s); %s needs python3 with "
               "its modules (set PARTSIM_PYTHON to use another interpreter)\n",
               python.c_str(), std::strerror(errno), what);
  return 1;
}

int RunLearnCommand(int argc, char** argv) {
  return RunPythonModule("partsim.learn", "partsim learn (PyTorch, Gymnasium)", argc, argv);
}

}  // namespace partsim::tools
