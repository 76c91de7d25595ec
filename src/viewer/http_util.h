// The HTTP side of the viewer, apart from its socket (the server's): which bundle paths may be
// served, which files may be read for them, and their
// content types.
#pragma once

#include <cstdint>
#include <string>

namespace partsim::internal {

/// Whether `path` ("/viewer.js", "/assets/index-3f2a.js") names a file the bundle may serve:
/// segments of letters, digits, '.', '_' and '-' that do not start with '.', so that no path
/// leaves the bundle folder ("/../", "%2e%2e", "\\", "//" and hidden files are refused).
bool SafeBundlePath(const std::string& path);

/// The canonical path of `file` when, once the links of both are followed, it is a regular file
/// inside `folder` (or in a folder below it); "" when it is missing, a folder, a device, a FIFO or
/// a socket, or lies outside (a link out of the folder, "../" that climbs out of it).
std::string RegularFileInside(const std::string& file, const std::string& folder);

/// Reads a regular file whole into `bytes`: opened without following a last link and without
/// blocking, then checked with fstat, so a FIFO or a device swapped in is never read. False when
/// it is not a regular file, cannot be read or holds more than `max_bytes`.
bool ReadRegularFile(const std::string& path, std::uintmax_t max_bytes, std::string* bytes);

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
