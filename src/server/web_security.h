// Checks of partsim's network server (the rosbridge server, which also carries the browser
// viewer): which web pages may connect (the handshake's Origin), comparing tokens, making one,
// reading a token from a request's query, and what an unauthenticated client may send.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace partsim::internal {

/// Whether a page of `origin` ("scheme://host[:port]", compared without case) may connect: one
/// of `allowed` ("*" allows every origin), or with none given, a page of this machine (http or
/// https, host localhost, 127.0.0.1 or [::1], any port). An empty origin (not a browser: no page
/// to protect against) is allowed.
bool OriginAllowed(const std::string& origin, const std::vector<std::string>& allowed);

/// Whether `given` equals the non-empty `token`, compared without stopping at the first
/// difference (the time taken says nothing of where they differ).
bool SameToken(const std::string& given, const std::string& token);

/// A random token of 32 hexadecimal digits (128 bits from std::random_device).
std::string RandomToken();

/// "/api/scene.json?token=T" -> path "/api/scene.json", query "token=T".
void SplitResource(const std::string& resource, std::string* path, std::string* query);

/// The value of `key` in a query "a=1&token=T" ("" when absent). Values are taken as they are
/// (tokens are hexadecimal: nothing to decode).
std::string QueryValue(const std::string& query, const std::string& key);

/// Bytes a message may have before its client has authenticated (with a token set): the auth
/// op needs a few dozen; longer messages are refused before they are parsed.
constexpr size_t kMaxUnauthenticatedBytes = 4096;

}  // namespace partsim::internal
