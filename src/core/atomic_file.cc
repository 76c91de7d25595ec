#include "core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>

#include "partsim/core/error.h"

namespace partsim::internal {

namespace fs = std::filesystem;

namespace {

// removes a file or folder, ignoring errors (it may never have been made)
void RemoveQuietly(const std::string& path) {
  std::error_code ignored;
  fs::remove_all(path, ignored);
}

}  // namespace

std::string UniqueTemporaryPath(const std::string& path) {
  static std::atomic<unsigned long> next_thread{0}, count{0};
  thread_local const unsigned long thread = next_thread.fetch_add(1);
  return path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(thread) + "." +
         std::to_string(count.fetch_add(1));
}

void WriteFileAtomically(const std::string& path, std::string_view bytes) {
  const std::string tmp = UniqueTemporaryPath(path);
  // O_EXCL: the name is ours alone; 0666 less the umask, as fopen makes files
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw Error("cannot write '" + path + "': " + std::strerror(errno));
  int error = 0;
  for (size_t done = 0; done < bytes.size() && error == 0;) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n >= 0)
      done += static_cast<size_t>(n);
    else if (errno != EINTR)
      error = errno;
  }
  // a full disk may show only when the file is closed
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) error = errno;
  if (error != 0) {
    ::unlink(tmp.c_str());
    throw Error("cannot write '" + path + "': " + std::strerror(error));
  }
}

StagedPath::StagedPath(std::string path, std::string temporary)
    : path_(std::move(path)), temporary_(std::move(temporary)) {
  if (temporary_.empty()) temporary_ = UniqueTemporaryPath(path_);
}

StagedPath::~StagedPath() {
  if (!committed_) RemoveQuietly(temporary_);
}

void StagedPath::Commit() {
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    const int error = errno;
    RemoveQuietly(temporary_);
    committed_ = true;  // nothing left to remove
    throw Error("cannot rename '" + temporary_ + "' to '" + path_ + "': " + std::strerror(error));
  }
  committed_ = true;
}

bool StagedPath::CommitUnlessPresent() {
  if (std::rename(temporary_.c_str(), path_.c_str()) == 0) {
    committed_ = true;
    return true;
  }
  const int error = errno;
  std::error_code ec;
  // rename(2) will not replace a non-empty folder: another writer's folder is there
  if ((error == ENOTEMPTY || error == EEXIST) && fs::is_directory(path_, ec) &&
      !fs::is_empty(path_, ec)) {
    RemoveQuietly(temporary_);
    committed_ = true;
    return false;
  }
  RemoveQuietly(temporary_);
  committed_ = true;
  throw Error("cannot rename '" + temporary_ + "' to '" + path_ + "': " + std::strerror(error));
}

}  // namespace partsim::internal
