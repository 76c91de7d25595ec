// `partsim learn ...`: SAC on the door and drawer tasks, the SAPIEN paper's protocol. The
// command is Python (partsim.learn, on PyTorch); this runs `python3 -m partsim.learn` with the
// arguments as they are, finding the package beside this program in a build tree (build/python)
// or where it is installed.
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

int RunLearnCommand(int argc, char** argv) {
  // the build tree keeps the package in python/ beside the program; an installed program finds
  // the installed package on the interpreter's own path
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::string pythonpath;
  if (!ec && fs::is_regular_file(exe.parent_path() / "python/partsim/learn/__main__.py", ec))
    pythonpath = (exe.parent_path() / "python").string();
  if (const char* old = std::getenv("PYTHONPATH"); old != nullptr && *old != '\0')
    pythonpath = pythonpath.empty() ? std::string(old) : pythonpath + ":" + old;
  if (!pythonpath.empty()) setenv("PYTHONPATH", pythonpath.c_str(), 1);

  // Debian's interpreter, which sees Debian's python3-torch, unless PARTSIM_PYTHON names another
  const char* chosen = std::getenv("PARTSIM_PYTHON");
  const std::string python = chosen != nullptr && *chosen != '\0' ? chosen : "/usr/bin/python3";
  std::vector<std::string> args = {python, "-m", "partsim.learn"};
  for (int i = 0; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(stdout);
  execv(python.c_str(), cargs.data());
  std::fprintf(stderr,
               "partsim learn: cannot run the Python interpreter '%s' (%s); partsim learn needs "
               "python3 with python3-torch (set PARTSIM_PYTHON to use another interpreter)\n",
               python.c_str(), std::strerror(errno));
  return 1;
}

}  // namespace partsim::tools
