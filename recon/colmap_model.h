#pragma once
// COLMAP sparse models (cameras, images, points3D) as COLMAP 3.8 writes them, in TXT or BIN;
// the 3D points as COLMAP's PLY export.
//
// Frames and conventions are COLMAP's: an image's pose is `cam_from_world`
// (x_cam = R(qvec) * x_world + tvec), qvec = (w, x, y, z); camera x right, y down, z forward;
// pixel (0.5, 0.5) is the centre of the top-left pixel; intrinsics follow COLMAP's camera models
// and parameter order (PINHOLE = fx, fy, cx, cy).
//
// Reading validates everything and throws igi::InputError, one line per problem:
//   "FILE: line N: VALUE: RULE"                       (TXT)
//   "FILE: camera record I (byte B): VALUE: RULE"     (BIN; image / point records likewise)
// for: a missing file, an unknown camera model, a wrong number of params, a non-numeric or
// out-of-range token, a truncated file or trailing bytes, duplicate ids or image names, a
// non-unit quaternion, an image referencing a missing camera, a 2D point referencing a missing 3D
// point, and a track referencing a missing image or 2D point. Up to kMaxReportedProblems lines.
//
// Quaternions: COLMAP normalises every qvec it reads. igi keeps a qvec whose norm is within
// kQuaternionKeepTolerance of 1 exactly as read (so full-precision files round-trip bit for bit),
// normalises one within kQuaternionNormalizeTolerance (files written with few digits), and
// rejects anything further from unit length.
//
// Image names: COLMAP 3.8 reads NAME in images.txt up to the first blank; igi reads the rest of
// the line, so names with blanks survive a TXT round trip through igi (not through COLMAP).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace igi::recon {

// | |q| - 1 | up to which a quaternion is kept bit for bit: a unit quaternion printed with 17
// significant digits and read back is within a few 1e-16 of unit length.
inline constexpr double kQuaternionKeepTolerance = 1e-12;
// | |q| - 1 | up to which a quaternion is normalised; beyond it the file is rejected. 1e-3 admits
// quaternions printed with 4+ digits and rejects ones that are not rotations at all.
inline constexpr double kQuaternionNormalizeTolerance = 1e-3;
// At most this many problems are listed in one InputError.
inline constexpr size_t kMaxReportedProblems = 20;
// A 2D point without a 3D point in images.bin: COLMAP stores point3D_id -1 as this uint64.
inline constexpr uint64_t kColmapNoPoint3DIdBinary = std::numeric_limits<uint64_t>::max();

struct ColmapCamera {
  uint32_t camera_id = 0;
  std::string model;           // COLMAP model name, e.g. "PINHOLE"
  int width = 0;               // pixels
  int height = 0;              // pixels
  std::vector<double> params;  // in COLMAP's order for `model`, focal lengths in pixels

  bool operator==(const ColmapCamera&) const = default;
};

struct ColmapPoint2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // pixels, (0.5, 0.5) = centre of top-left pixel
  int64_t point3d_id = -1;                       // -1: not triangulated

  bool operator==(const ColmapPoint2D&) const = default;
};

struct ColmapImage {
  uint32_t image_id = 0;
  Eigen::Vector4d qvec = Eigen::Vector4d(1, 0, 0, 0);  // w, x, y, z; rotation cam_from_world
  Eigen::Vector3d tvec = Eigen::Vector3d::Zero();      // cam_from_world translation
  uint32_t camera_id = 0;
  std::string name;  // image file name relative to the image folder
  std::vector<ColmapPoint2D> points2d;

  bool operator==(const ColmapImage&) const = default;
};

struct ColmapTrackElement {
  uint32_t image_id = 0;
  uint32_t point2d_idx = 0;

  bool operator==(const ColmapTrackElement&) const = default;
};

struct ColmapPoint3D {
  uint64_t point3d_id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // world frame
  std::array<uint8_t, 3> rgb = {0, 0, 0};
  double error = -1;  // mean reprojection error in pixels; -1 = unknown (COLMAP's convention)
  std::vector<ColmapTrackElement> track;

  bool operator==(const ColmapPoint3D&) const = default;
};

struct ColmapModel {
  std::map<uint32_t, ColmapCamera> cameras;
  std::map<uint32_t, ColmapImage> images;
  std::map<uint64_t, ColmapPoint3D> points3d;

  bool operator==(const ColmapModel&) const = default;

  // The image with this file name, or nullptr.
  const ColmapImage* FindImageByName(std::string_view name) const;
  // Number of 2D points with a 3D point, over all images (COLMAP's "observations").
  size_t NumObservations() const;
};

// Reads the model in `dir`: BIN when cameras.bin, images.bin and points3D.bin all exist (as
// COLMAP does), else TXT (InputError naming each missing .txt file).
ColmapModel ReadColmapModel(const std::filesystem::path& dir);
ColmapModel ReadColmapModelText(const std::filesystem::path& dir);
ColmapModel ReadColmapModelBinary(const std::filesystem::path& dir);

// Writes cameras.txt, images.txt and points3D.txt into `dir` (created if needed) with COLMAP's
// header comments and 17 significant digits, so that reading gives back the same model. The
// model is validated first (ValidateColmapModel; nothing is written if it fails); each file is
// written atomically. Unit quaternions are written as they are, others normalised.
void WriteColmapModelText(const ColmapModel& model, const std::filesystem::path& dir);

// Writes cameras.bin, images.bin and points3D.bin into `dir` (created if needed) in COLMAP 3.8's
// binary layout (little-endian; the layout ReadColmapModelBinary reads), so that reading gives
// back the same model bit for bit. A 2D point without a 3D point (point3d_id -1) is stored as
// 2^64 - 1, as COLMAP stores kInvalidPoint3DId. Records are in id order. Validated first
// (ValidateColmapModel with ".bin"; nothing is written if it fails); each file is written
// atomically. Unit quaternions are written as they are, others normalised.
void WriteColmapModelBinary(const ColmapModel& model, const std::filesystem::path& dir);

// Writes the 3D points to `path` as COLMAP's `model_converter --output_type PLY` does: binary
// little-endian PLY, one vertex per point with float x, y, z (world frame, rounded from double)
// and uchar red, green, blue; no normals, no faces. Points are in id order (COLMAP's order is its
// hash map's). Throws InputError, writing nothing, when a coordinate is not finite or beyond
// float's range; the file is written atomically.
void WriteColmapPointsPly(const ColmapModel& model, const std::filesystem::path& path);

// Checks a model against the rules above (known models, param counts, sizes, unit quaternions,
// non-empty unique names, every reference resolved). Problems name `dir`/cameras`extension` etc.
// and the record ("IMAGE_ID 7"); throws InputError listing them.
void ValidateColmapModel(const ColmapModel& model, const std::filesystem::path& dir,
                         std::string_view extension = ".txt");

// COLMAP 3.8 camera models: SIMPLE_PINHOLE = 0, PINHOLE = 1, SIMPLE_RADIAL = 2, RADIAL = 3,
// OPENCV = 4, OPENCV_FISHEYE = 5, FULL_OPENCV = 6, FOV = 7, SIMPLE_RADIAL_FISHEYE = 8,
// RADIAL_FISHEYE = 9, THIN_PRISM_FISHEYE = 10.
// Number of params of a model given by name; -1 if unknown.
int ColmapModelNumParams(std::string_view model);
// Model id for a name, and name for an id; nullopt if unknown.
std::optional<int> ColmapModelIdFromName(std::string_view model);
std::optional<std::string> ColmapModelNameFromId(int model_id);
// All model names in id order.
std::vector<std::string> ColmapModelNames();

}  // namespace igi::recon
