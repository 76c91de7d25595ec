// The HTTP side of the viewer, apart from its socket: splitting a request's resource, reading
// its query, which bundle paths may be served, and their content types.
#pragma once

#include <string>

namespace partsim::internal {

/// "/api/scene.json?token=T" -> path "/api/scene.json", query "token=T".
void SplitResource(const std::string& resource, std::string* path, std::string* query);

/// The value of `key` in a query "a=1&token=T" ("" when absent). Values are taken as they are
/// (tokens are hexadecimal: nothing to decode).
std::string QueryValue(const std::string& query, const std::string& key);

/// Whether `path` ("/viewer.js", "/assets/index-3f2a.js") names a file the bundle may serve:
/// segments of letters, digits, '.', '_' and '-' that do not start with '.', so that no path
/// leaves the bundle folder ("/../", "%2e%2e", "\\", "//" and hidden files are refused).
bool SafeBundlePath(const std::string& path);

/// K of a path "PREFIX" + K + "SUFFIX" ("/api/mesh/12.bin" with "/api/mesh/" and ".bin": 12),
/// K a decimal of at most 9 digits; -1 for any other path.
long long PathIndex(const std::string& path, const std::string& prefix, const std::string& suffix);

/// Content-Type of a file by its extension (".js" -> "text/javascript; charset=utf-8");
/// "application/octet-stream" for others.
std::string ContentTypeOf(const std::string& path);

/// Content-Type of image bytes by their signature: "image/png", "image/jpeg", else
/// "application/octet-stream".
std::string ImageContentType(const std::string& bytes);

}  // namespace partsim::internal
