// `partsim serve` as users start it: what it says on a bad command line, on a port already taken,
// on start and when clients come and go.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "server/process_util.h"
#include "server/wait_for.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

const std::string kServe = std::string("'") + PARTSIM_CLI_PATH + "' serve ";

bool Contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A TCP socket connected to 127.0.0.1:`port`, or -1.
int Connect(int port) {
  int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<uint16_t>(port));
  if (s >= 0 && ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0) return s;
  if (s >= 0) ::close(s);
  return -1;
}

/// Sends a WebSocket opening handshake (RFC 6455, section 4.1) on `s` and returns the first line
/// of the server's answer ("HTTP/1.1 101 Switching Protocols" when accepted).
std::string Handshake(int s) {
  const std::string request =
      "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  if (::send(s, request.data(), request.size(), 0) != static_cast<ssize_t>(request.size()))
    return "";
  timeval timeout{10, 0};
  ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  std::string answer;
  char buf[512];
  while (answer.find("\r\n") == std::string::npos) {
    ssize_t n = ::recv(s, buf, sizeof(buf), 0);
    if (n <= 0) break;
    answer.append(buf, n);
  }
  return answer.substr(0, answer.find("\r\n"));
}

TEST(ServeCommandTest, BadValuesGetOneLineNamingTheValueAndTheRange) {
  struct Case {
    std::string args;
    std::vector<std::string> said;
  };
  const std::vector<Case> cases = {
      {"--port 99999", {"--port", "'99999'", "0 to 65535", "0 picks a free port"}},
      {"--port -1", {"--port", "'-1'"}},
      {"--port 80x", {"--port", "'80x'"}},
      {"--rate 0", {"--rate", "'0'"}},
      {"--robot pand", {"--robot", "'pand'", "did you mean 'panda'?"}},
      {"--prot 9090", {"'--prot'", "did you mean '--port'?"}},
      {"--camera 640", {"--camera", "'640'"}},
  };
  for (const Case& c : cases) {
    int code = 0;
    const std::string out = RunShell(kServe + c.args + " 2>&1", &code);
    EXPECT_EQ(code, 2) << c.args << "\n" << out;
    for (const std::string& s : c.said) EXPECT_TRUE(Contains(out, s)) << c.args << "\n" << out;
    // the error and where to read more, not the whole help page
    EXPECT_TRUE(Contains(out, "see partsim serve --help")) << out;
    EXPECT_FALSE(Contains(out, "usage:")) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << out;
  }
}

TEST(ServeCommandTest, APortInUseIsNamedWithAWayOut) {
  // a listening socket holds a port of 127.0.0.1
  int held = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(held, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof(a);
  ASSERT_EQ(::bind(held, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  ASSERT_EQ(::listen(held, 1), 0);
  ASSERT_EQ(::getsockname(held, reinterpret_cast<sockaddr*>(&a), &len), 0);
  const std::string port = std::to_string(ntohs(a.sin_port));

  // serve fails at once (--duration bounds the test should it serve after all)
  int code = 0;
  const std::string out =
      RunShell(kServe + "--robot gripper --port " + port + " --duration 10 2>&1", &code);
  ::close(held);
  EXPECT_EQ(code, 1) << out;
  EXPECT_TRUE(Contains(out, "127.0.0.1:" + port)) << out;
  EXPECT_TRUE(Contains(out, "address already in use")) << out;
  EXPECT_TRUE(Contains(out, "--port 0")) << out;
  EXPECT_FALSE(Contains(out, "Underlying Transport Error")) << out;
}

TEST(ServeCommandTest, SaysWhereToConnectAndLogsClientsComingAndGoing) {
  // on start: the URL, then how to connect
  int code = 0;
  const std::string out =
      RunShell(kServe + "--robot gripper --fast --port 0 --duration 0.2", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_TRUE(Contains(out, "rosbridge on ws://127.0.0.1:")) << out;
  EXPECT_TRUE(Contains(out, "connect a rosbridge client to ws://127.0.0.1:")) << out;
  EXPECT_TRUE(Contains(out, "/rosapi/topics")) << out;

  // a WebSocket client connects, then leaves: a line each on stderr, with the count
  const fs::path log =
      fs::temp_directory_path() / ("partsim_serve_clients_" + std::to_string(::getpid()) + ".log");
  {
    ServeProcess serve("--robot gripper --port 0 --duration 60 2>'" + log.string() + "'");
    ASSERT_GT(serve.Port(), 0) << "partsim serve printed: " << serve.FirstLine();
    int s = Connect(serve.Port());
    ASSERT_GE(s, 0);
    EXPECT_EQ(Handshake(s), "HTTP/1.1 101 Switching Protocols");
    EXPECT_TRUE(testing::WaitFor([&] {
      return Contains(ReadFile(log), "client 127.0.0.1:") &&
             Contains(ReadFile(log), "connected (1 client connected)");
    })) << ReadFile(log);
    ::close(s);
    EXPECT_TRUE(testing::WaitFor([&] {
      return Contains(ReadFile(log), "disconnected (0 clients connected)");
    })) << ReadFile(log);
  }
  fs::remove(log);
}

}  // namespace
}  // namespace partsim
