// The annotation tool in the browser (`partsim annotate`, docs/annotation.md): the object's part
// tree and meshes (/api/annotate/object.json, /api/annotate/mesh/K.bin), the session's state
// (/api/annotate/state.json) and the services that answer, undo, export and review, added to a
// Viewer (which serves the page, checks the token and the Origin, and bounds every client). The
// services run on the thread that calls Run(), one at a time, each saved before it replies.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "partsim/assets/annotation.h"
#include "partsim/viewer/viewer.h"

namespace partsim {

struct AnnotatorOptions {
  std::string input;    ///< the PartNet-style folder (result.json and part meshes)
  std::string out;      ///< the session folder: session.json, and the export in object/
  bool review = false;  ///< review mode: once every question is answered, review each joint
  bool strict = false;  ///< a part mesh that is not manifold is an error, not a warning
};

class Annotator {
 public:
  /// Reads the input and opens (or resumes) the session in options.out; throws partsim::Error
  /// naming what is wrong (ReadAnnotationInput, AnnotationStore), leaving a saved session as it
  /// is.
  explicit Annotator(const AnnotatorOptions& options);
  ~Annotator();
  Annotator(const Annotator&) = delete;
  Annotator& operator=(const Annotator&) = delete;

  /// Adds the routes and services to `viewer` (before its Start()).
  void AttachTo(Viewer* viewer);
  /// Runs the page's requests until `keep_going` says no (asked at least 10 times a second).
  void Run(const std::function<bool()>& keep_going);

  /// /api/annotate/object.json's text.
  const std::string& ObjectJson() const { return object_json_; }
  /// /api/annotate/state.json's text: the session's state, plus "exported" (the export's folder
  /// or null), "warnings" (ReadAnnotationInput's) and "review_mode".
  std::string StateJson() const;
  const AnnotationStore& Store() const { return *store_; }
  /// The export's folder: options.out/object.
  std::string ExportFolder() const;

 private:
  void Post(std::function<void()> task);

  AnnotatorOptions options_;
  std::shared_ptr<const AnnotationInput> input_;
  std::unique_ptr<AnnotationStore> store_;
  std::string object_json_;
  std::vector<std::string> meshes_;  ///< encoded, by AnnotationInput::meshes index
  bool exported_ = false;
  mutable std::mutex mutex_;  ///< guards store_'s state and exported_ against StateJson
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<std::function<void()>> queue_;
};

}  // namespace partsim
