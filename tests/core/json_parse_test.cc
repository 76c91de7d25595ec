#include "core/json_parse.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

namespace partsim::internal {
namespace {

std::string ParseError(const std::string& text) {
  try {
    ParseJsonBounded(text);
  } catch (const nlohmann::json::exception& e) {
    return e.what();
  }
  return "";
}

TEST(JsonParse, NestingUpToTheBoundParsesAndDeeperIsRefused) {
  const int n = kMaxJsonDepth;
  EXPECT_EQ(ParseJsonBounded(std::string(n, '[') + "1" + std::string(n, ']')).dump(),
            std::string(n, '[') + "1" + std::string(n, ']'));
  const std::string deeper = std::string(n + 1, '[') + "1" + std::string(n + 1, ']');
  EXPECT_NE(ParseError(deeper).find("nested deeper than 64 levels"), std::string::npos);
  // objects count as arrays do; a deep document is refused even when it never closes
  std::string objects;
  for (int i = 0; i <= n; ++i) objects += "{\"a\":";
  EXPECT_NE(ParseError(objects + "1" + std::string(n + 1, '}')).find("nested deeper"),
            std::string::npos);
  EXPECT_NE(ParseError(std::string(100000, '[')).find("nested deeper"), std::string::npos);
  EXPECT_EQ(JsonNestingDepth("[[]]", 64), 2);
}

TEST(JsonParse, BracketsInsideStringsDoNotCount) {
  // 200 brackets inside a string, with escaped quotes and backslashes before them
  const std::string text =
      "{\"s\": \"\\\\\\\"" + std::string(200, '[') + "\\\"" + std::string(200, '{') + "\"}";
  EXPECT_EQ(JsonNestingDepth(text, 64), 1);
  const nlohmann::json j = ParseJsonBounded(text);
  EXPECT_EQ(j["s"].get<std::string>().size(), 2 + 200 + 1 + 200u);
}

TEST(JsonParse, MalformedTextIsAParseError) {
  EXPECT_THROW(ParseJsonBounded("{\"a\": [1, 2}"), nlohmann::json::parse_error);
  EXPECT_THROW(ParseJsonBounded("]]]]"), nlohmann::json::parse_error);
  EXPECT_THROW(ParseJsonBounded(""), nlohmann::json::parse_error);
}

// The one wall-clock bound in this file: nlohmann's callback parser rescans the enclosing
// container at every closing bracket, and took 38 s over these 300,000 empty objects (900 KB,
// well under the server's 16 MB bound), against tens of milliseconds for a linear parse
// (bench/json_parse_bench.cc records both). 10 s is generous enough for a loaded machine and
// still fails on a quadratic parser.
TEST(JsonParse, ManyContainersParseInLinearTime) {
  std::string text = "{\"op\":\"x\",\"a\":[";
  for (int i = 0; i < 300000; ++i) text += i ? ",{}" : "{}";
  text += "]}";
  const auto start = std::chrono::steady_clock::now();
  const nlohmann::json j = ParseJsonBounded(text);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(j["a"].size(), 300000u);
  EXPECT_LT(seconds, 10.0);
}

}  // namespace
}  // namespace partsim::internal
