// internal::ProgressLine (src/core/progress.h): '\r' on a terminal only, bounded plain lines
// elsewhere.
#include "core/progress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace partsim::internal {
namespace {

/// What `report` writes through a ProgressLine on a temporary file.
template <class F>
std::string Written(bool terminal, double min_interval_s, F report) {
  std::FILE* f = std::tmpfile();
  if (!f) return "";
  {
    ProgressLine progress(f, terminal, min_interval_s);
    report(progress);
  }
  std::string out;
  std::rewind(f);
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) out.append(buf, n);
  std::fclose(f);
  return out;
}

long Count(const std::string& s, char c) { return std::count(s.begin(), s.end(), c); }

TEST(ProgressLineTest, ALogGetsPlainLinesForTheFirstItemEachTenthAndTheLast) {
  const std::string out = Written(false, 0.0, [](ProgressLine& p) {
    for (long i = 1; i <= 1000; ++i) p.Update(i, 1000, "item " + std::to_string(i));
  });
  EXPECT_EQ(Count(out, '\r'), 0);
  // item 1, then 100, 200, ..., 1000: each tenth once
  EXPECT_EQ(Count(out, '\n'), 11) << out;
  EXPECT_EQ(out.substr(0, 7), "item 1\n");
  EXPECT_NE(out.find("item 500\n"), std::string::npos) << out;
  EXPECT_EQ(out.substr(out.size() - 10), "item 1000\n");
  // fewer items than tenths: a line each
  const std::string few = Written(false, 0.0, [](ProgressLine& p) {
    for (long i = 1; i <= 3; ++i) p.Update(i, 3, std::to_string(i));
  });
  EXPECT_EQ(few, "1\n2\n3\n");
}

TEST(ProgressLineTest, ATerminalGetsOneLineRewrittenInPlace) {
  // a long interval: the first and the last update are shown, the last ends the line
  const std::string out = Written(true, 3600.0, [](ProgressLine& p) {
    for (long i = 1; i <= 50; ++i) p.Update(i, 50, "item " + std::to_string(i));
  });
  EXPECT_EQ(Count(out, '\r'), 2) << out;
  EXPECT_EQ(Count(out, '\n'), 1) << out;
  EXPECT_EQ(out.front(), '\r');
  EXPECT_EQ(out.back(), '\n');
  EXPECT_NE(out.find("\ritem 50"), std::string::npos) << out;
  // Break ends an open line once, so that other output starts on a line of its own
  const std::string broken = Written(true, 0.0, [](ProgressLine& p) {
    p.Update(1, 2, "half");
    p.Break();
    p.Break();
  });
  EXPECT_EQ(broken, "\rhalf   \n");
  // elsewhere Break writes nothing
  EXPECT_EQ(Written(false, 0.0,
                    [](ProgressLine& p) {
                      p.Update(1, 2, "half");
                      p.Break();
                    }),
            "half\n");
}

}  // namespace
}  // namespace partsim::internal
