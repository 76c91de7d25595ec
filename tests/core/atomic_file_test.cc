#include "core/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "partsim/core/error.h"

namespace partsim::internal {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("partsim_atomic_file_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }
  std::vector<std::string> Names() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_))
      names.push_back(e.path().filename().string());
    return names;
  }
  static std::string Read(const fs::path& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  // the message of the Error that `f` throws, or "" when it throws none
  template <typename F>
  static std::string ErrorOf(F f) {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

// Two threads write one file over and over, with contents large enough that the writes
// overlap, while a third reads it: every read and the last content are one writer's whole
// bytes, and no temporary is left. With temporaries named by the process alone, the two
// threads wrote into one temporary and one thread's rename found it gone.
TEST_F(AtomicFileTest, TwoThreadsWritingOneFileLeaveOneWholeContent) {
  const std::string path = (dir_ / "shared.bin").string();
  const std::string a(256 << 10, 'a'), b((256 << 10) + 7, 'b');
  WriteFileAtomically(path, a);
  std::atomic<bool> go{false}, done{false};
  std::atomic<int> failures{0}, torn{0}, reads{0};
  auto writer = [&](const std::string& content) {
    while (!go) std::this_thread::yield();
    for (int i = 0; i < 200; ++i) {
      try {
        WriteFileAtomically(path, content);
      } catch (const Error&) {
        ++failures;
      }
    }
  };
  std::thread reader([&] {
    while (!done) {
      const std::string seen = Read(path);
      if (seen != a && seen != b) ++torn;
      ++reads;
    }
  });
  std::thread ta(writer, a), tb(writer, b);
  go = true;
  ta.join();
  tb.join();
  done = true;
  reader.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(torn.load(), 0) << "of " << reads.load() << " reads";
  const std::string last = Read(path);
  EXPECT_TRUE(last == a || last == b) << last.size() << " bytes";
  EXPECT_EQ(Names(), std::vector<std::string>{"shared.bin"});
}

TEST_F(AtomicFileTest, TemporariesAreUniqueAndBesideThePath) {
  const std::string path = (dir_ / "x.txt").string();
  const std::string t1 = UniqueTemporaryPath(path);
  std::string t2;
  std::thread([&] { t2 = UniqueTemporaryPath(path); }).join();
  EXPECT_NE(t1, t2);
  EXPECT_NE(t1, UniqueTemporaryPath(path));
  EXPECT_EQ(fs::path(t1).parent_path(), dir_);
  EXPECT_EQ(t1.rfind(path + ".tmp." + std::to_string(::getpid()) + ".", 0), 0u) << t1;
}

// A missing folder, a folder that cannot be written and a name taken by a folder: the error
// names the path and the OS's reason, the old content stays and nothing is left behind.
TEST_F(AtomicFileTest, FailuresNameThePathAndLeaveNothing) {
  const std::string missing = (dir_ / "no_such_folder" / "f.txt").string();
  std::string m = ErrorOf([&] { WriteFileAtomically(missing, "x"); });
  EXPECT_NE(m.find("'" + missing + "'"), std::string::npos) << m;
  EXPECT_NE(m.find("No such file or directory"), std::string::npos) << m;

  fs::create_directories(dir_ / "taken" / "inside");
  const std::string taken = (dir_ / "taken").string();
  m = ErrorOf([&] { WriteFileAtomically(taken, "x"); });
  EXPECT_NE(m.find("'" + taken + "'"), std::string::npos) << m;
  EXPECT_NE(m.find("Is a directory"), std::string::npos) << m;
  EXPECT_TRUE(fs::exists(dir_ / "taken" / "inside"));
  EXPECT_EQ(Names(), std::vector<std::string>{"taken"});

  // permissions do not hold back root
  if (::geteuid() != 0) {
    const fs::path locked = dir_ / "locked";
    fs::create_directories(locked);
    const std::string file = (locked / "f.txt").string();
    WriteFileAtomically(file, "old");
    fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
    m = ErrorOf([&] { WriteFileAtomically(file, "new"); });
    fs::permissions(locked, fs::perms::owner_all);
    EXPECT_NE(m.find("'" + file + "'"), std::string::npos) << m;
    EXPECT_NE(m.find("Permission denied"), std::string::npos) << m;
    EXPECT_EQ(Read(file), "old");
    EXPECT_EQ(std::distance(fs::directory_iterator(locked), fs::directory_iterator()), 1);
  }
}

// A staged folder: removed when not committed, renamed into place by Commit; a second writer of
// the same folder finds the first one's and leaves it.
TEST_F(AtomicFileTest, StagedFolderIsRemovedUnlessCommitted) {
  const std::string target = (dir_ / "object").string();
  {
    StagedPath staged(target);
    fs::create_directories(staged.Temporary());
    std::ofstream(staged.Temporary() + "/a.txt") << "first";
  }
  EXPECT_TRUE(Names().empty());
  {
    StagedPath staged(target);
    fs::create_directories(staged.Temporary());
    std::ofstream(staged.Temporary() + "/a.txt") << "first";
    staged.Commit();
  }
  {
    StagedPath staged(target);
    fs::create_directories(staged.Temporary());
    std::ofstream(staged.Temporary() + "/a.txt") << "second";
    EXPECT_FALSE(staged.CommitUnlessPresent());
  }
  EXPECT_EQ(Read(dir_ / "object" / "a.txt"), "first");
  EXPECT_EQ(Names(), std::vector<std::string>{"object"});
  // Commit onto a non-empty folder fails naming both names, and the temporary goes
  StagedPath staged(target, target + ".partial");
  fs::create_directories(staged.Temporary());
  std::ofstream(staged.Temporary() + "/a.txt") << "third";
  const std::string m = ErrorOf([&] { staged.Commit(); });
  EXPECT_NE(m.find("'" + target + ".partial' to '" + target + "'"), std::string::npos) << m;
  EXPECT_EQ(Names(), std::vector<std::string>{"object"});
}

}  // namespace
}  // namespace partsim::internal
