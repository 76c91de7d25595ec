// Which bundle paths the viewer serves, which files it reads for them, and how it reads a
// request's resource.
#include "viewer/http_util.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "server/web_security.h"

namespace partsim::internal {
namespace {

TEST(ViewerHttpTest, BundlePathsStayInTheBundle) {
  for (const char* ok : {"/index.html", "/viewer.js", "/assets/index-3f2a.js", "/a/b/c.css"})
    EXPECT_TRUE(SafeBundlePath(ok)) << ok;
  for (const char* bad : {"", "/", "index.html", "/../x", "/a/../x", "/..", "/.env", "/a/.git/x",
                          "//x", "/a//b", "/a/", "/%2e%2e/x", "/a\\b", "/a b", "/a?b"})
    EXPECT_FALSE(SafeBundlePath(bad)) << bad;
}

TEST(ViewerHttpTest, OnlyRegularFilesInsideTheFolderAreRead) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("partsim_http_util_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "root" / "sub");
  std::ofstream(dir / "root" / "a.js") << "let a;";
  std::ofstream(dir / "outside.txt") << "secret";
  fs::create_symlink("a.js", dir / "root" / "alias.js");
  fs::create_symlink("/", dir / "root" / "all");
  fs::create_symlink("../outside.txt", dir / "root" / "up.txt");
  ASSERT_EQ(mkfifo((dir / "root" / "fifo.js").c_str(), 0600), 0);
  const std::string root = (dir / "root").string();
  const std::string a = fs::canonical(dir / "root" / "a.js").string();
  EXPECT_EQ(RegularFileInside(root + "/a.js", root), a);
  EXPECT_EQ(RegularFileInside(root + "/alias.js", root), a);  // a link that stays inside
  EXPECT_EQ(RegularFileInside(root + "/sub/../a.js", root), a);
  for (const char* bad : {"/all/etc/passwd", "/up.txt", "/../outside.txt", "/sub", "/all",
                          "/fifo.js", "/missing.js", ""})
    EXPECT_EQ(RegularFileInside(root + bad, root), "") << bad;
  EXPECT_EQ(RegularFileInside(root + "/a.js", ""), "");

  std::string bytes;
  EXPECT_TRUE(ReadRegularFile(a, 100, &bytes));
  EXPECT_EQ(bytes, "let a;");
  EXPECT_FALSE(ReadRegularFile(a, 5, &bytes));  // larger than allowed
  // a FIFO returns at once (no writer: a blocking open would wait forever), as do a folder and
  // a link as the last component
  EXPECT_FALSE(ReadRegularFile(root + "/fifo.js", 100, &bytes));
  EXPECT_FALSE(ReadRegularFile(root + "/sub", 100, &bytes));
  EXPECT_FALSE(ReadRegularFile(root + "/up.txt", 100, &bytes));
  fs::remove_all(dir);
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
