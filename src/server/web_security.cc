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

}  // namespace partsim::internal
