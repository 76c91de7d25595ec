// Child processes for the tests that start partsim (or a ROS master) the way users do.
#pragma once

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace partsim {

/// A shell command in a child process (killed with SIGTERM, then waited for, on destruction);
/// the first line of its standard output is read at start.
class ChildProcess {
 public:
  explicit ChildProcess(const std::string& command, bool read_first_line = true) {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], 1);
      ::close(fds[0]);
      ::close(fds[1]);
      std::string cmd = "exec " + command;
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    out_ = ::fdopen(fds[0], "r");
    char line[512];
    if (read_first_line && out_ && std::fgets(line, sizeof(line), out_)) first_line_ = line;
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    if (out_) std::fclose(out_);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  const std::string& FirstLine() const { return first_line_; }

 private:
  pid_t pid_ = -1;
  FILE* out_ = nullptr;
  std::string first_line_;
};

/// `partsim serve ARGS` in a child process; its first output line names the rosbridge port.
class ServeProcess : public ChildProcess {
 public:
  /// `env`: assignments put before the command, e.g. "ROS_MASTER_URI=http://127.0.0.1:11311".
  explicit ServeProcess(const std::string& args, const std::string& env = "")
      : ChildProcess((env.empty() ? "" : "env " + env + " ") + "'" + PARTSIM_CLI_PATH + "' serve " +
                     args) {
    size_t at = FirstLine().find("127.0.0.1:");
    if (at != std::string::npos) port_ = std::atoi(FirstLine().c_str() + at + 10);
  }
  int Port() const { return port_; }

 private:
  int port_ = 0;
};

/// Runs a shell command; returns its standard output and sets `code`.
inline std::string RunShell(const std::string& cmd, int* code) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  int status = ::pclose(p);
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

/// A TCP port free on 127.0.0.1 now (the kernel's pick), or 0.
inline int FreePort() {
  int s = ::socket(AF_INET, SOCK_STREAM, 0);
  if (s < 0) return 0;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof(a);
  int port = 0;
  if (::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0 &&
      ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) == 0)
    port = ntohs(a.sin_port);
  ::close(s);
  return port;
}

}  // namespace partsim
