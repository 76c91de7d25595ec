// The perception datasets of partsim's benchmark (the SAPIEN paper's movable-part detection and
// motion-attribute estimation), rendered from a tree of PartNet-Mobility folders, real or
// generated. docs/vision.md gives the layout of the files; in short:
//
//   OUT/dataset.json                    options, the split, counts, thresholds
//   OUT/instances_{train,test}.json     detection: COCO instance segmentation (RLE masks)
//   OUT/motion_{train,test}.json        motion: {"slider_range", "samples": [{"sample_id", "m"}]}
//   OUT/objects/<name>/                 one folder per object, written as <name>.partial and
//                                       renamed when whole (its DONE file written last)
//     views.json                        per view: camera (K, extrinsics), joint positions and
//                                       the annotated parts (detection) or samples (motion)
//     rgb/NN.png  depth/NN.png (16-bit mm)  depth/NN.npy (float32 m)
//     instances/NN.png (16-bit part index, 0 = none)  cloud/NN.npz (detection)
//     mask/NN.png (motion: the target part)
//
// Every random draw comes from the seed and the object's name, so the same seed gives the same
// bytes whatever the number of jobs and shards; objects already DONE are skipped (resume), and
// the split files are rebuilt from every DONE object at the end of each run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace partsim::vision {

/// Which dataset.
enum class DatasetKind { kDetection, kMotion };

/// Options of GenerateDataset.
struct DatasetOptions {
  std::string dataset_root;  ///< folder holding PartNet-Mobility object folders, at any depth
  std::string out;           ///< output folder
  DatasetKind kind = DatasetKind::kDetection;
  /// Detection: views per object. Motion: samples per target part (motion_parts), over every
  /// object with one.
  int views = 20;
  int size = 512;  ///< picture width and height, pixels
  std::uint64_t seed = 0;
  double split = 0.75;  ///< fraction of each category's objects in the training split
  int jobs = 1;         ///< worker threads, each rendering whole objects
  int shard_index = 0;  ///< this run renders the objects with index % shard_count == shard_index
  int shard_count = 1;
  std::string backend = "rasterizer";  ///< or "pathtracer"
  /// A part is annotated in a view when at least this fraction of the picture's pixels see it
  /// (1/4096: 64 pixels at 512 x 512).
  double min_area_fraction = 1.0 / 4096.0;
  double fovy_degrees = 35.0;  ///< vertical field of view of the cameras
  bool point_clouds = true;    ///< detection: write cloud/NN.npz
  /// Motion: the target parts, by words of their label. A labelled link whose label contains
  /// one of them is a target when it moves on a hinge (revolute or continuous: a "hinge"
  /// sample) or a slider (prismatic: a "slider" sample; a slider that also turns, such as a
  /// screw cap, is one, its state the slide). The paper's set, the default, is doors and
  /// drawers; {"lid"}, {"knob", "button"} or {"door", "drawer", "lid"} choose others.
  std::vector<std::string> motion_parts = {"door", "drawer"};
  bool merge_only = false;  ///< render nothing: rebuild the split files from DONE objects
  bool progress = true;     ///< progress lines on stderr
};

/// What a run did.
/// Where the time of a dataset run went, one phase of rendering an object, summed over the
/// workers: "load" (reading the object and building its scene), "render" (the pictures, read-back
/// included), "convert" (a picture into the view's pixels, depth and points), "write" (encoding
/// and writing a view's files, on each worker's writing thread beside its rendering).
struct DatasetPhase {
  std::string name;
  long count = 0;           ///< times the phase ran (objects for "load", views for the others)
  double wall_seconds = 0;  ///< wall time inside the phase
  double cpu_seconds = 0;   ///< CPU time of the thread inside it
};

struct DatasetSummary {
  int objects = 0;                  ///< objects in the dataset (all shards)
  int rendered = 0;                 ///< objects rendered by this run
  int skipped = 0;                  ///< objects of this shard already DONE
  int failed = 0;                   ///< objects of this shard that could not be read or rendered
  std::vector<std::string> errors;  ///< "<folder>: <why>" per failed object
  long views = 0;                   ///< pictures rendered by this run
  int train_objects = 0;            ///< in the merged split files
  int test_objects = 0;
  long train_images = 0;  ///< detection images or motion samples, merged
  long test_images = 0;
  long annotations = 0;              ///< detection: part instances, merged
  double slider_range = 0;           ///< motion: the slider normalisation, m
  double seconds = 0;                ///< wall time of the run
  std::vector<DatasetPhase> phases;  ///< load, render, convert, write: this run's objects
};

/// Renders the dataset's objects of this shard that are not DONE yet, then writes the split
/// files from every DONE object. Throws partsim::Error for bad options (naming the option) or
/// a dataset root without objects; an object that cannot be read or rendered is reported in
/// the summary and the others go on.
DatasetSummary GenerateDataset(const DatasetOptions& options);

}  // namespace partsim::vision
