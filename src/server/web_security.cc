#include "server/web_security.h"

#include <cstdio>
#include <cstring>
#include <random>

#include "core/ascii.h"

namespace partsim::internal {

bool OriginAllowed(const std::string& origin, const std::vector<std::string>& allowed) {
  if (origin.empty()) return true;
  const std::string o = AsciiLower(origin);
  for (const std::string& a : allowed)
    if (a == "*" || AsciiLower(a) == o) return true;
  if (!allowed.empty()) return false;
  for (const char* scheme : {"http://", "https://"}) {
    if (o.rfind(scheme, 0) != 0) continue;
    const std::string rest = o.substr(std::strlen(scheme));
    for (const char* host : {"localhost", "127.0.0.1", "[::1]"}) {
      const size_t n = std::strlen(host);
      if (rest.compare(0, n, host) == 0 && (rest.size() == n || rest[n] == ':')) return true;
    }
  }
  return false;
}

bool SameToken(const std::string& given, const std::string& token) {
  unsigned char diff = given.size() != token.size();
  for (size_t i = 0; i < given.size(); ++i)
    diff |= given[i] ^ token[i % (token.empty() ? 1 : token.size())];
  return diff == 0 && !token.empty();
}

std::string RandomToken() {
  std::random_device rd;
  std::string out;
  for (int i = 0; i < 4; ++i) {
    char buf[9];
    std::snprintf(buf, sizeof(buf), "%08x", static_cast<unsigned>(rd()));
    out += buf;
  }
  return out;
}

void SplitResource(const std::string& resource, std::string* path, std::string* query) {
  const size_t q = resource.find('?');
  *path = resource.substr(0, q);
  *query = q == std::string::npos ? "" : resource.substr(q + 1);
}

std::string QueryValue(const std::string& query, const std::string& key) {
  size_t at = 0;
  while (at <= query.size()) {
    size_t end = query.find('&', at);
    if (end == std::string::npos) end = query.size();
    const std::string item = query.substr(at, end - at);
    const size_t eq = item.find('=');
    if (item.substr(0, eq) == key) return eq == std::string::npos ? "" : item.substr(eq + 1);
    at = end + 1;
  }
  return "";
}

}  // namespace partsim::internal
