// The writer of PartNet-Mobility folders, shared by the generator (WriteObject,
// WriteUnannotatedObject) and the annotation tool's export (ExportAnnotation), which writes
// meshes it read and the part hierarchy it was given.
#pragma once

#include <functional>
#include <string>

#include "partsim/assets/generator.h"

namespace partsim::internal {

/// What WriteObjectFolder writes besides the meshes.
struct ObjectFolderOptions {
  /// mobility.urdf, mobility_v2.json and semantics.txt; false: the unannotated form (meshes,
  /// part hierarchy, meta.json and bounding_box.json only)
  bool mobility = true;
  std::string meta_json;    ///< meta.json's text; "": the generator's
  std::string result_json;  ///< result.json's text; "": made from the links (with
                            ///< result_after_merging.json)
  /// A non-empty folder at the destination is replaced only when this accepts it.
  std::function<bool(const std::string& folder)> replaceable = IsGeneratedObjectFolder;
  std::string writer = "partsim";  ///< named in the refusal to replace a folder
};

/// Writes `object` into `dir` as WriteObject documents, with `options`.
void WriteObjectFolder(const GeneratedObject& object, const std::string& dir,
                       const ObjectFolderOptions& options);

}  // namespace partsim::internal
