// Which bundle paths the viewer serves, and how it reads a request's resource.
#include "viewer/http_util.h"

#include <gtest/gtest.h>

namespace partsim::internal {
namespace {

TEST(ViewerHttpTest, BundlePathsStayInTheBundle) {
  for (const char* ok : {"/index.html", "/viewer.js", "/assets/index-3f2a.js", "/a/b/c.css"})
    EXPECT_TRUE(SafeBundlePath(ok)) << ok;
  for (const char* bad : {"", "/", "index.html", "/../x", "/a/../x", "/..", "/.env", "/a/.git/x",
                          "//x", "/a//b", "/a/", "/%2e%2e/x", "/a\\b", "/a b", "/a?b"})
    EXPECT_FALSE(SafeBundlePath(bad)) << bad;
}

TEST(ViewerHttpTest, ResourceSplitsIntoPathAndQuery) {
  std::string path, query;
  SplitResource("/api/scene.json?x=1&token=abc", &path, &query);
  EXPECT_EQ(path, "/api/scene.json");
  EXPECT_EQ(QueryValue(query, "token"), "abc");
  EXPECT_EQ(QueryValue(query, "x"), "1");
  EXPECT_EQ(QueryValue(query, "tok"), "");
  SplitResource("/", &path, &query);
  EXPECT_EQ(path, "/");
  EXPECT_EQ(query, "");
}

TEST(ViewerHttpTest, ContentTypesByExtensionAndSignature) {
  EXPECT_EQ(ContentTypeOf("/viewer.JS"), "text/javascript; charset=utf-8");
  EXPECT_EQ(ContentTypeOf("/index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(ContentTypeOf("/blob"), "application/octet-stream");
  EXPECT_EQ(ImageContentType("\x89PNG\r\n"), "image/png");
  EXPECT_EQ(ImageContentType("\xff\xd8\xff\xe0"), "image/jpeg");
  EXPECT_EQ(ImageContentType("GIF89a"), "application/octet-stream");
}

TEST(ViewerHttpTest, PathIndexReadsOnlyPlainDecimals) {
  EXPECT_EQ(PathIndex("/api/mesh/12.bin", "/api/mesh/", ".bin"), 12);
  EXPECT_EQ(PathIndex("/api/mesh/0.bin", "/api/mesh/", ".bin"), 0);
  EXPECT_EQ(PathIndex("/api/mesh/.bin", "/api/mesh/", ".bin"), -1);
  EXPECT_EQ(PathIndex("/api/mesh/-1.bin", "/api/mesh/", ".bin"), -1);
  EXPECT_EQ(PathIndex("/api/mesh/1e3.bin", "/api/mesh/", ".bin"), -1);
  EXPECT_EQ(PathIndex("/api/mesh/1234567890.bin", "/api/mesh/", ".bin"), -1);
  EXPECT_EQ(PathIndex("/api/mesh/7.png", "/api/mesh/", ".bin"), -1);
  EXPECT_EQ(PathIndex("/api/thumbnail/7.png", "/api/mesh/", ".png"), -1);
}

}  // namespace
}  // namespace partsim::internal
