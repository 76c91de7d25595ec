// Reading files that users hand to partsim (URDF, SRDF, JSON, textures, meshes): only regular
// files, and only up to a size, so that a path to /dev/zero, a FIFO or a huge file gives a clear
// error instead of filling memory or hanging.
#pragma once

#include <cstdint>
#include <string>

namespace partsim::internal {

/// Largest text file partsim reads (URDF, SRDF, JSON, semantics.txt): 256 MB.
constexpr std::uintmax_t kMaxTextFileBytes = 256ull << 20;
/// Largest texture or mesh file: 1 GB.
constexpr std::uintmax_t kMaxDataFileBytes = 1ull << 30;

/// What `path` (symbolic links followed) is when it is not a regular file: "a folder", "a
/// character device", "a block device", "a FIFO (named pipe)", "a socket", "a symbolic link
/// loop", or "" for a regular file and for a path that does not exist. Opens nothing.
std::string NonRegularFileKind(const std::string& path);

/// Throws partsim::Error "<what> <path>: ..." unless `path` (symbolic links followed) is a
/// regular file of at most `max_bytes`; the message says what the path is instead (missing, a
/// folder, a character device, a FIFO, a socket, too large).
void CheckReadableFile(const std::string& path, const std::string& what, std::uintmax_t max_bytes);

/// The whole content of a file checked by CheckReadableFile.
std::string ReadWholeFile(const std::string& path, const std::string& what,
                          std::uintmax_t max_bytes = kMaxTextFileBytes);

}  // namespace partsim::internal
