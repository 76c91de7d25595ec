// Files and folders that appear whole or not at all: written under a temporary name beside their
// destination (same folder, so same file system) and renamed onto it, which POSIX makes atomic.
// A reader never sees half a file; a process stopped meanwhile leaves only a temporary, never a
// torn file under the real name; writers at once (threads or processes) each write a temporary
// of their own, and the last rename wins.
#pragma once

#include <string>
#include <string_view>

namespace partsim::internal {

/// A name beside `path` that no other writer picks: "<path>.tmp.<pid>.<thread>.<n>", with the
/// process id, a number of the calling thread and a count over the whole process.
std::string UniqueTemporaryPath(const std::string& path);

/// Writes `bytes` to `path` through a unique temporary beside it (UniqueTemporaryPath), renamed
/// onto `path` once written and closed. On failure the temporary is removed, `path` keeps what it
/// held, and partsim::Error says "cannot write '<path>': <reason from the OS>".
void WriteFileAtomically(const std::string& path, std::string_view bytes);

/// A file or folder made under a temporary name (`Temporary()`) and renamed onto its path by
/// Commit: for writers that stream (a video encoder writing to a file name, a folder of files).
/// Until committed, the destructor removes the temporary (a file or a whole folder), so an error
/// on the way leaves nothing behind. Creates nothing itself.
class StagedPath {
 public:
  /// `temporary`: the name to write under, which must lie in the folder of `path`; empty picks
  /// UniqueTemporaryPath(path). A fixed name (a documented "<path>.partial") serves callers
  /// whose leftovers are looked for by name; it is unique only if the caller is.
  explicit StagedPath(std::string path, std::string temporary = "");
  ~StagedPath();
  StagedPath(const StagedPath&) = delete;
  StagedPath& operator=(const StagedPath&) = delete;

  /// The destination.
  const std::string& Path() const { return path_; }
  /// Where to write until Commit.
  const std::string& Temporary() const { return temporary_; }

  /// Renames the temporary onto the path, replacing a file there (or an empty folder by a
  /// folder). On failure removes the temporary and throws partsim::Error "cannot rename
  /// '<temporary>' to '<path>': <reason from the OS>".
  void Commit();
  /// For a folder that several writers make alike: renames the temporary onto the path unless
  /// the path is already a non-empty folder (another writer came first), in which case it removes
  /// the temporary and returns false. Other failures throw as Commit does.
  bool CommitUnlessPresent();

 private:
  std::string path_, temporary_;
  bool committed_ = false;
};

}  // namespace partsim::internal
