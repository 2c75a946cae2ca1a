#pragma once
// Runs COLMAP 3.8's command line headless (CPU SIFT, exhaustive matching, incremental mapping) on
// a folder of photos and reads the largest reconstruction back. Without known intrinsics COLMAP
// self-calibrates `camera_model` (focal length and distortion refined in its bundle
// adjustments, principal point held at the image centre).
//
// Failures are reported, not hidden: a missing `colmap` executable or a version other than 3.8
// (igi::Error, exit 1, naming what was found), a step that fails (its log file is named), and a
// mapper that reconstructs nothing (too few matches) are all igi::Error. Every COLMAP step's
// output goes to `work_dir`/colmap.log; nothing is printed to stdout.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calib/camera_file.h"
#include "recon/colmap_model.h"

namespace igi::recon {

// Known intrinsics to give COLMAP (from camera.json): held fixed during mapping.
struct KnownIntrinsics {
  calib::ColmapCameraModel model = calib::ColmapCameraModel::kPinhole;  // the COLMAP model
  int width = 0;
  int height = 0;
  std::vector<double> params;  // COLMAP order
};

struct ColmapRunOptions {
  std::string executable = "colmap";  // name on PATH or a path
  int threads = 0;                    // 0 = all cores
  bool single_camera = true;          // one camera shared by every photo
  int max_image_size = 3200;          // SIFT extraction downscales larger photos (COLMAP default)
  // At most this many SIFT keypoints per photo (COLMAP's --SiftExtraction.max_num_features, its
  // default 8192; a keypoint may carry several orientations, so the features stored can be
  // more). COLMAP 3.8 matches on the CPU by brute force, so fewer keypoints shorten the
  // exhaustive matching, and leave fewer matches between photos that overlap little.
  int max_features = 8192;
  // Known intrinsics, held fixed during mapping; absent: COLMAP self-calibrates camera_model.
  std::optional<KnownIntrinsics> intrinsics;
  // The COLMAP camera model self-calibrated when `intrinsics` is not given (ignored with it):
  // kSimplePinhole, kPinhole, kSimpleRadial (default), kRadial or kOpenCv (kSelfCalibratedModels).
  // The pinhole models leave a lens's distortion in the focal length; each extra distortion term
  // trades off against the focal length where the photos do not separate them (a few photos of
  // one facade), so the one-parameter model is the default.
  calib::ColmapCameraModel camera_model = calib::ColmapCameraModel::kSimpleRadial;
  // COLMAP's --SiftMatching.guided_matching: once a pair's two-view geometry is estimated, match
  // again along it, which keeps more correct matches, for a longer matching step. Off by
  // default (COLMAP's default).
  bool guided_matching = false;
  bool allow_other_version = false;  // accept a COLMAP other than 3.8 (with a warning)
  // The mapper registers a photo when its pose has this many 2D-3D inliers (COLMAP's
  // --Mapper.abs_pose_min_num_inliers and its default). Lower values let close-ups that share
  // few points with the rest register, but a pose from few inliers can be far off. With
  // markers igi-register poses such a photo from them instead (RePoseImagesFromMarkers).
  int min_pose_inliers = 30;

  void Validate() const;
};

// The names of the COLMAP camera models ColmapRunOptions::camera_model accepts (those
// recon/camera.h reads; FULL_OPENCV is not among them).
extern const std::vector<std::string> kSelfCalibratedModels;

struct ColmapRunSummary {
  std::string version;                    // e.g. "3.8"
  ColmapModel model;                      // the largest reconstruction
  int num_models = 0;                     // reconstructions the mapper produced
  std::vector<std::string> images;        // the photos given (file names)
  std::vector<std::string> unregistered;  // photos that are not in `model`
  std::filesystem::path log;              // COLMAP's combined output
};

// "3.8" from `colmap -h`'s first line ("COLMAP 3.8 -- Structure-from-Motion …"); throws
// igi::Error when the executable cannot be run or prints no version.
std::string ColmapVersion(const std::string& executable);
// The version number in a `colmap -h` banner, or nullopt.
std::optional<std::string> ParseColmapVersion(const std::string& banner);

// The photos COLMAP would read in `images_dir` (JPEG, PNG, TIFF, BMP; sorted file names).
std::vector<std::string> ListColmapImages(const std::filesystem::path& images_dir);

// Feature extraction, exhaustive matching and mapping of every photo in `images_dir`, with the
// database, the mapper's models and the log under `work_dir` (created).
ColmapRunSummary RunColmap(const std::filesystem::path& images_dir,
                           const std::filesystem::path& work_dir, const ColmapRunOptions& options);

// A run's summary from an existing model of the photos in `images_dir` (COLMAP not run: version
// "not run", no log): the model in `model_dir` (TXT or BIN; InputError when unreadable).
ColmapRunSummary LoadColmapRun(const std::filesystem::path& images_dir,
                               const std::filesystem::path& model_dir);

}  // namespace igi::recon
