#include "viewer/http_util.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <map>

#include "core/ascii.h"

namespace partsim::internal {

bool SafeBundlePath(const std::string& path) {
  if (path.size() < 2 || path[0] != '/') return false;
  size_t at = 1;
  while (at <= path.size()) {
    size_t end = path.find('/', at);
    if (end == std::string::npos) end = path.size();
    if (end == at || path[at] == '.') return false;  // empty segment, "..", hidden file
    for (size_t i = at; i < end; ++i) {
      const unsigned char c = static_cast<unsigned char>(path[i]);
      if (!std::isalnum(c) && c != '.' && c != '_' && c != '-') return false;
    }
    at = end + 1;
  }
  return path.back() != '/';
}

std::string RegularFileInside(const std::string& file, const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path root = fs::canonical(folder, ec);
  if (ec || folder.empty()) return "";
  const fs::path real = fs::canonical(file, ec);
  if (ec) return "";
  // inside: a relative path from the root that does not climb out of it
  const fs::path rel = real.lexically_relative(root);
  if (rel.empty() || rel == "." || *rel.begin() == "..") return "";
  if (fs::status(real, ec).type() != fs::file_type::regular || ec) return "";
  return real.string();
}

bool ReadRegularFile(const std::string& path, std::uintmax_t max_bytes, std::string* bytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
            static_cast<std::uintmax_t>(st.st_size) <= max_bytes;
  bytes->clear();
  char buf[65536];
  while (ok) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n == 0) break;
    if (n < 0 || bytes->size() + static_cast<size_t>(n) > max_bytes) ok = false;
    if (ok) bytes->append(buf, static_cast<size_t>(n));
  }
  ::close(fd);
  return ok;
}

std::string ContentTypeOf(const std::string& path) {
  static const std::map<std::string, std::string> types = {
      {"html", "text/html; charset=utf-8"},
      {"js", "text/javascript; charset=utf-8"},
      {"mjs", "text/javascript; charset=utf-8"},
      {"css", "text/css; charset=utf-8"},
      {"json", "application/json"},
      {"map", "application/json"},
      {"txt", "text/plain; charset=utf-8"},
      {"png", "image/png"},
      {"jpg", "image/jpeg"},
      {"jpeg", "image/jpeg"},
      {"svg", "image/svg+xml"},
      {"ico", "image/x-icon"},
      {"wasm", "application/wasm"},
      {"woff2", "font/woff2"}};
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos) return "application/octet-stream";
  const std::string ext = AsciiLower(path.substr(dot + 1));
  auto it = types.find(ext);
  return it == types.end() ? "application/octet-stream" : it->second;
}

std::string ImageContentType(const std::string& bytes) {
  if (bytes.rfind("\x89PNG", 0) == 0) return "image/png";
  if (bytes.rfind("\xff\xd8\xff", 0) == 0) return "image/jpeg";
  return "application/octet-stream";
}

long long PathIndex(const std::string& path, const std::string& prefix, const std::string& suffix) {
  if (path.rfind(prefix, 0) != 0 || path.size() <= prefix.size() + suffix.size() ||
      path.compare(path.size() - suffix.size(), suffix.size(), suffix) != 0)
    return -1;
  const std::string digits =
      path.substr(prefix.size(), path.size() - prefix.size() - suffix.size());
  if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoll(digits);
}

}  // namespace partsim::internal
