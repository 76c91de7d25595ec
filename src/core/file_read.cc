#include "core/file_read.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "partsim/core/error.h"

namespace partsim::internal {

namespace fs = std::filesystem;

namespace {

const char* KindOf(fs::file_type t) {
  switch (t) {
    case fs::file_type::directory:
      return "a folder";
    case fs::file_type::character:
      return "a character device";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::fifo:
      return "a FIFO (named pipe)";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

}  // namespace

std::string NonRegularFileKind(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // follows symbolic links
  if (ec == std::errc::too_many_symbolic_link_levels) return "a symbolic link loop";
  if (ec || st.type() == fs::file_type::not_found || st.type() == fs::file_type::regular) return "";
  return KindOf(st.type());
}

void CheckReadableFile(const std::string& path, const std::string& what, std::uintmax_t max_bytes) {
  const std::string where = what + " " + path;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // follows symbolic links
  if (ec == std::errc::too_many_symbolic_link_levels)
    throw Error(where + ": is a symbolic link loop, not a regular file");
  if (ec || st.type() == fs::file_type::not_found)
    throw Error(where + ": the file does not exist" + (ec ? " (" + ec.message() + ")" : ""));
  if (st.type() != fs::file_type::regular)
    throw Error(where + ": is " + KindOf(st.type()) + ", not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(where + ": cannot read its size (" + ec.message() + ")");
  if (size > max_bytes)
    throw Error(where + ": is " + std::to_string(size >> 20) + " MB, more than the " +
                std::to_string(max_bytes >> 20) + " MB partsim reads");
}

std::string ReadWholeFile(const std::string& path, const std::string& what,
                          std::uintmax_t max_bytes) {
  CheckReadableFile(path, what, max_bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(what + " " + path + ": cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace partsim::internal
