// JSON parsing of hostile shapes: many small containers in one array, as a client may send up to
// the server's 16 MB bound. Runs nlohmann's callback parser (what ParseJsonBounded used to do: a
// depth callback) and ParseJsonBounded (a linear depth scan, then the plain parser) on the same
// inputs; prints the median of the repeats in seconds. Usage: partsim_json_parse_bench [--quick]
// (--quick: skips the callback parser on inputs where it takes more than a few seconds).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "core/json_parse.h"

namespace {

using Json = nlohmann::json;

// the previous ParseJsonBounded
Json ParseWithDepthCallback(const std::string& text, int max_depth) {
  Json::parser_callback_t guard = [max_depth](int depth, Json::parse_event_t, Json&) {
    if (depth > max_depth)
      throw Json::out_of_range::create(406, "nested deeper than N levels", nullptr);
    return true;
  };
  return Json::parse(text, guard);
}

std::string ManyObjects(size_t n) {
  std::string s = "{\"op\":\"x\",\"a\":[";
  for (size_t i = 0; i < n; ++i) s += i ? ",{}" : "{}";
  return s + "]}";
}

std::string Trajectory(size_t n) {
  std::string s =
      "{\"op\":\"publish\",\"topic\":\"/r/joint_trajectory_controller/command\","
      "\"msg\":{\"joint_names\":[\"j1\",\"j2\",\"j3\",\"j4\",\"j5\",\"j6\",\"j7\"],\"points\":[";
  for (size_t i = 0; i < n; ++i) {
    if (i) s += ",";
    s += "{\"positions\":[0.1,0.2,0.3,0.4,0.5,0.6,0.7],\"time_from_start\":{\"secs\":" +
         std::to_string(i) + ",\"nsecs\":0}}";
  }
  return s + "]}}";
}

double MedianSeconds(const std::function<void()>& f, int repeats) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  struct Case {
    const char* name;
    std::string text;
    bool old_runs;  // the callback parser finishes in minutes at most
  };
  std::vector<Case> cases = {{"100k {}", ManyObjects(100000), true},
                             {"300k {}", ManyObjects(300000), !quick},
                             {"15 MB of {}", ManyObjects(5000000), false},
                             {"JointTrajectory 100k points", Trajectory(100000), !quick},
                             {"JointTrajectory 200k points", Trajectory(200000), !quick}};
  std::printf("%-30s %10s %14s %14s\n", "input", "bytes", "callback (s)", "bounded (s)");
  for (const Case& c : cases) {
    const double fresh = MedianSeconds([&] { partsim::internal::ParseJsonBounded(c.text); }, 5);
    std::string old = "not run";
    if (c.old_runs) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.3f",
                    MedianSeconds([&] { ParseWithDepthCallback(c.text, 64); }, 1));
      old = buf;
    }
    std::printf("%-30s %10zu %14s %14.3f\n", c.name, c.text.size(), old.c_str(), fresh);
    std::fflush(stdout);
  }
  return 0;
}
