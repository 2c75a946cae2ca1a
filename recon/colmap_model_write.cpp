// COLMAP sparse models written: TXT with COLMAP's header comments, BIN in COLMAP 3.8's byte
// layout, and the points as COLMAP's PLY (recon/colmap_model.h).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "recon/colmap_model.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

double MeanPer(size_t total, size_t count) {
  return count == 0 ? 0.0 : static_cast<double>(total) / static_cast<double>(count);
}

// q as written: unchanged within kQuaternionKeepTolerance of unit length, else normalised (the
// model was validated: |q| is within kQuaternionNormalizeTolerance of 1).
Eigen::Vector4d QuaternionToWrite(const Eigen::Vector4d& qvec) {
  const double norm = qvec.norm();
  return std::abs(norm - 1.0) > kQuaternionKeepTolerance ? Eigen::Vector4d(qvec / norm) : qvec;
}

std::string CamerasText(const ColmapModel& model) {
  std::string out;
  auto it = std::back_inserter(out);
  fmt::format_to(it,
                 "# Camera list with one line of data per camera:\n"
                 "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                 "# Number of cameras: {}\n",
                 model.cameras.size());
  for (const auto& [id, camera] : model.cameras) {
    fmt::format_to(it, "{} {} {} {}", id, camera.model, camera.width, camera.height);
    for (double p : camera.params) fmt::format_to(it, " {:.17g}", p);
    out += '\n';
  }
  return out;
}

std::string ImagesText(const ColmapModel& model) {
  std::string out;
  auto it = std::back_inserter(out);
  fmt::format_to(it,
                 "# Image list with two lines of data per image:\n"
                 "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
                 "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
                 "# Number of images: {}, mean observations per image: {:.17g}\n",
                 model.images.size(), MeanPer(model.NumObservations(), model.images.size()));
  for (const auto& [id, image] : model.images) {
    const Eigen::Vector4d q = QuaternionToWrite(image.qvec);
    fmt::format_to(it, "{} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {} {}\n", id,
                   q[0], q[1], q[2], q[3], image.tvec[0], image.tvec[1], image.tvec[2],
                   image.camera_id, image.name);
    for (size_t i = 0; i < image.points2d.size(); ++i) {
      const ColmapPoint2D& point = image.points2d[i];
      fmt::format_to(it, "{}{:.17g} {:.17g} {}", i == 0 ? "" : " ", point.xy.x(), point.xy.y(),
                     point.point3d_id);
    }
    out += '\n';
  }
  return out;
}

std::string Points3DText(const ColmapModel& model) {
  std::string out;
  auto it = std::back_inserter(out);
  fmt::format_to(it,
                 "# 3D point list with one line of data per point:\n"
                 "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
                 "# Number of points: {}, mean track length: {:.17g}\n",
                 model.points3d.size(), MeanPer(model.NumObservations(), model.points3d.size()));
  for (const auto& [id, point] : model.points3d) {
    // Like COLMAP, a blank ends the fixed fields even when the track is empty.
    fmt::format_to(it, "{} {:.17g} {:.17g} {:.17g} {} {} {} {:.17g} ", id, point.xyz[0],
                   point.xyz[1], point.xyz[2], point.rgb[0], point.rgb[1], point.rgb[2],
                   point.error);
    for (size_t i = 0; i < point.track.size(); ++i) {
      fmt::format_to(it, "{}{} {}", i == 0 ? "" : " ", point.track[i].image_id,
                     point.track[i].point2d_idx);
    }
    out += '\n';
  }
  return out;
}

// Appends `value`'s bytes in little-endian order (COLMAP's WriteBinaryLittleEndian).
template <typename T>
void PutLittleEndian(std::string& out, T value) {
  std::array<char, sizeof(T)> buffer;
  std::memcpy(buffer.data(), &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(buffer.begin(), buffer.end());
  out.append(buffer.data(), sizeof(T));
}

// cameras.bin: uint64 count; per camera uint32 id, int32 model id, uint64 width, uint64 height,
// double params[].
std::string CamerasBinary(const ColmapModel& model) {
  std::string out;
  out.reserve(8 + model.cameras.size() * (24 + 12 * 8));
  PutLittleEndian<uint64_t>(out, model.cameras.size());
  for (const auto& [id, camera] : model.cameras) {
    PutLittleEndian<uint32_t>(out, id);
    PutLittleEndian<int32_t>(out, ColmapModelIdFromName(camera.model).value());
    PutLittleEndian<uint64_t>(out, static_cast<uint64_t>(camera.width));
    PutLittleEndian<uint64_t>(out, static_cast<uint64_t>(camera.height));
    for (double p : camera.params) PutLittleEndian<double>(out, p);
  }
  return out;
}

// images.bin: uint64 count; per image uint32 id, double qvec[4] (w, x, y, z), double tvec[3],
// uint32 camera id, the name and a NUL, uint64 number of 2D points, then per 2D point double x,
// double y and uint64 3D point id (2^64 - 1 for none, COLMAP's kInvalidPoint3DId).
std::string ImagesBinary(const ColmapModel& model) {
  size_t bytes = 8;
  for (const auto& [id, image] : model.images) {
    bytes += 4 + 7 * 8 + 4 + image.name.size() + 1 + 8 + image.points2d.size() * 24;
  }
  std::string out;
  out.reserve(bytes);
  PutLittleEndian<uint64_t>(out, model.images.size());
  for (const auto& [id, image] : model.images) {
    PutLittleEndian<uint32_t>(out, id);
    const Eigen::Vector4d q = QuaternionToWrite(image.qvec);
    for (int k = 0; k < 4; ++k) PutLittleEndian<double>(out, q[k]);
    for (int k = 0; k < 3; ++k) PutLittleEndian<double>(out, image.tvec[k]);
    PutLittleEndian<uint32_t>(out, image.camera_id);
    out.append(image.name.c_str(), image.name.size() + 1);
    PutLittleEndian<uint64_t>(out, image.points2d.size());
    for (const ColmapPoint2D& point : image.points2d) {
      PutLittleEndian<double>(out, point.xy.x());
      PutLittleEndian<double>(out, point.xy.y());
      PutLittleEndian<uint64_t>(out, point.point3d_id < 0
                                         ? kColmapNoPoint3DIdBinary
                                         : static_cast<uint64_t>(point.point3d_id));
    }
  }
  return out;
}

// points3D.bin: uint64 count; per point uint64 id, double xyz[3], uint8 rgb[3], double error,
// uint64 track length, then per element uint32 image id and uint32 2D point index.
std::string Points3DBinary(const ColmapModel& model) {
  size_t bytes = 8;
  for (const auto& [id, point] : model.points3d)
    bytes += 8 + 24 + 3 + 8 + 8 + point.track.size() * 8;
  std::string out;
  out.reserve(bytes);
  PutLittleEndian<uint64_t>(out, model.points3d.size());
  for (const auto& [id, point] : model.points3d) {
    PutLittleEndian<uint64_t>(out, id);
    for (int k = 0; k < 3; ++k) PutLittleEndian<double>(out, point.xyz[k]);
    for (uint8_t c : point.rgb) PutLittleEndian<uint8_t>(out, c);
    PutLittleEndian<double>(out, point.error);
    PutLittleEndian<uint64_t>(out, point.track.size());
    for (const ColmapTrackElement& element : point.track) {
      PutLittleEndian<uint32_t>(out, element.image_id);
      PutLittleEndian<uint32_t>(out, element.point2d_idx);
    }
  }
  return out;
}

// The PLY that COLMAP's Reconstruction::ExportPLY writes: binary little-endian, one vertex per 3D
// point with float x, y, z and uchar red, green, blue (no normals), here in point id order.
std::string PointsPly(const ColmapModel& model) {
  std::string out = fmt::format(
      "ply\n"
      "format binary_little_endian 1.0\n"
      "element vertex {}\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "property uchar red\n"
      "property uchar green\n"
      "property uchar blue\n"
      "end_header\n",
      model.points3d.size());
  out.reserve(out.size() + model.points3d.size() * 15);
  for (const auto& [id, point] : model.points3d) {
    for (int k = 0; k < 3; ++k) PutLittleEndian<float>(out, static_cast<float>(point.xyz[k]));
    for (uint8_t c : point.rgb) PutLittleEndian<uint8_t>(out, c);
  }
  return out;
}

// Every coordinate of every 3D point must be finite and within float's range (the PLY stores
// float); problems name `path` and the point.
void CheckPointsForPly(const ColmapModel& model, const fs::path& path) {
  ProblemList problems;
  for (const auto& [id, point] : model.points3d) {
    if (problems.size() >= kMaxReportedProblems) break;
    if (!point.xyz.allFinite() ||
        point.xyz.cwiseAbs().maxCoeff() > std::numeric_limits<float>::max()) {
      problems.Add(path.string(), fmt::format("POINT3D_ID {}", id),
                   fmt::format("{} {} {}", point.xyz[0], point.xyz[1], point.xyz[2]),
                   "X, Y and Z must be finite and within float range (the PLY stores float)");
    }
  }
  problems.ThrowIfAny();
}

}  // namespace

void WriteColmapModelText(const ColmapModel& model, const fs::path& dir) {
  ValidateColmapModel(model, dir, ".txt");
  const std::string cameras = CamerasText(model);
  const std::string images = ImagesText(model);
  const std::string points3d = Points3DText(model);
  WriteFileAtomic(dir / "cameras.txt", cameras);
  WriteFileAtomic(dir / "images.txt", images);
  WriteFileAtomic(dir / "points3D.txt", points3d);
}

void WriteColmapModelBinary(const ColmapModel& model, const fs::path& dir) {
  ValidateColmapModel(model, dir, ".bin");
  const std::string cameras = CamerasBinary(model);
  const std::string images = ImagesBinary(model);
  const std::string points3d = Points3DBinary(model);
  WriteFileAtomic(dir / "cameras.bin", cameras);
  WriteFileAtomic(dir / "images.bin", images);
  WriteFileAtomic(dir / "points3D.bin", points3d);
}

void WriteColmapPointsPly(const ColmapModel& model, const fs::path& path) {
  CheckPointsForPly(model, path);
  WriteFileAtomic(path, PointsPly(model));
}

}  // namespace igi::recon
