// What a mesh file claims against what it can hold: the counts in PLY, STL, COLLADA and glTF
// headers are checked against the file's size before assimp reads the file, since assimp
// allocates what a header claims (a 218-byte PLY claiming 2e9 vertices asked for tens of GB).
#pragma once

#include <cstdint>
#include <string>

namespace partsim::internal {

/// Throws partsim::Error "mesh file '<path>': ..." naming what the header claims and what the
/// file can hold when a count in a PLY, binary STL, COLLADA or glTF (.gltf, .glb) file needs more
/// bytes than the file (or the buffer it names) has. The format is told by the extension or by
/// the file's first bytes; other formats are refused
/// (assimp's readers of them are unchecked). Reads the PLY, STL and GLB headers only, the
/// whole text of a COLLADA or .gltf file. `path` has been checked by CheckReadableFile.
void CheckMeshClaims(const std::string& path);

}  // namespace partsim::internal
