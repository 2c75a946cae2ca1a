#include "recon/colmap_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

struct CameraModelInfo {
  int id;
  const char* name;
  int num_params;
};

// COLMAP 3.8's camera models (src/base/camera_models.h), in id order.
constexpr std::array<CameraModelInfo, 11> kCameraModels = {{{0, "SIMPLE_PINHOLE", 3},
                                                            {1, "PINHOLE", 4},
                                                            {2, "SIMPLE_RADIAL", 4},
                                                            {3, "RADIAL", 5},
                                                            {4, "OPENCV", 8},
                                                            {5, "OPENCV_FISHEYE", 8},
                                                            {6, "FULL_OPENCV", 12},
                                                            {7, "FOV", 5},
                                                            {8, "SIMPLE_RADIAL_FISHEYE", 4},
                                                            {9, "RADIAL_FISHEYE", 5},
                                                            {10, "THIN_PRISM_FISHEYE", 12}}};

const CameraModelInfo* FindCameraModel(std::string_view name) {
  for (const CameraModelInfo& info : kCameraModels) {
    if (name == info.name) return &info;
  }
  return nullptr;
}

constexpr long long kMaxPoint3DId = std::numeric_limits<int64_t>::max();

// A value and the rule it breaks, to be placed after "FILE: WHERE: ".
struct Problem {
  std::string value;
  std::string rule;
};

// Where each record was read ("line 12", "record 3 (byte 40)"), for problems spanning records.
struct RecordPlaces {
  std::map<uint32_t, std::string> cameras;
  std::map<uint32_t, std::string> images;
  std::map<uint64_t, std::string> points3d;
};

template <typename Key>
std::string PlaceOf(const RecordPlaces* places,
                    const std::map<Key, std::string> RecordPlaces::*member, Key id,
                    std::string_view label) {
  if (places != nullptr) {
    const auto& map = places->*member;
    if (auto it = map.find(id); it != map.end()) return it->second;
  }
  return fmt::format("{} {}", label, id);
}

std::string KnownModelNames() { return Join(ColmapModelNames(), ", "); }

std::optional<Problem> CheckCamera(const ColmapCamera& camera) {
  const int num_params = ColmapModelNumParams(camera.model);
  if (num_params < 0) {
    return Problem{camera.model,
                   "unknown camera model (COLMAP 3.8 knows " + KnownModelNames() + ")"};
  }
  if (static_cast<int>(camera.params.size()) != num_params) {
    return Problem{fmt::format("{} params", camera.params.size()),
                   fmt::format("wrong number of params: {} needs {}", camera.model, num_params)};
  }
  if (camera.width <= 0 || camera.height <= 0) {
    return Problem{fmt::format("{}x{}", camera.width, camera.height),
                   "WIDTH and HEIGHT must be positive"};
  }
  for (double p : camera.params) {
    if (!std::isfinite(p)) return Problem{fmt::format("{}", p), "params must be finite"};
  }
  return std::nullopt;
}

// Accepts |q| within kQuaternionNormalizeTolerance of 1; when `normalize` is given, writes the
// quaternion to keep there (unchanged within kQuaternionKeepTolerance, else q / |q|).
std::optional<Problem> CheckQuaternion(const Eigen::Vector4d& qvec, Eigen::Vector4d* normalize) {
  const double norm = qvec.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > kQuaternionNormalizeTolerance) {
    return Problem{fmt::format("|q| = {}", norm),
                   fmt::format("non-unit quaternion: |q| must be within {} of 1",
                               kQuaternionNormalizeTolerance)};
  }
  if (normalize != nullptr) {
    *normalize =
        std::abs(norm - 1.0) > kQuaternionKeepTolerance ? Eigen::Vector4d(qvec / norm) : qvec;
  }
  return std::nullopt;
}

std::optional<Problem> CheckImageName(const std::string& name) {
  if (name.empty()) return Problem{"\"\"", "NAME must not be empty"};
  if (name.find_first_of(std::string_view("\n\r\0", 3)) != std::string::npos ||
      Trim(name).size() != name.size()) {
    return Problem{name, "NAME must not contain line breaks or NUL, nor start or end with blanks"};
  }
  return std::nullopt;
}

bool Full(const ProblemList& problems) { return problems.size() >= kMaxReportedProblems; }

void CheckCameras(const ColmapModel& model, const std::string& file, const RecordPlaces* places,
                  ProblemList& problems) {
  for (const auto& [id, camera] : model.cameras) {
    const std::string where = PlaceOf(places, &RecordPlaces::cameras, id, "CAMERA_ID");
    if (camera.camera_id != id) {
      problems.Add(file, where, std::to_string(camera.camera_id), "camera_id differs from its key");
    }
    if (auto p = CheckCamera(camera)) problems.Add(file, where, p->value, p->rule);
  }
}

void CheckImages(const ColmapModel& model, const std::string& file, const RecordPlaces* places,
                 ProblemList& problems) {
  std::map<std::string_view, uint32_t> names;
  for (const auto& [id, image] : model.images) {
    if (Full(problems)) return;
    const std::string where = PlaceOf(places, &RecordPlaces::images, id, "IMAGE_ID");
    auto add = [&](const std::string& value, const std::string& rule) {
      problems.Add(file, where, value, rule);
    };
    if (image.image_id != id) add(std::to_string(image.image_id), "image_id differs from its key");
    if (auto p = CheckQuaternion(image.qvec, nullptr)) add(p->value, p->rule);
    if (!image.tvec.allFinite())
      add(fmt::format("{} {} {}", image.tvec[0], image.tvec[1], image.tvec[2]), "T must be finite");
    if (!model.cameras.contains(image.camera_id)) {
      add(fmt::format("CAMERA_ID {}", image.camera_id), "image references a missing camera");
    }
    if (auto p = CheckImageName(image.name)) add(p->value, p->rule);
    if (auto [it, fresh] = names.emplace(image.name, id); !fresh) {
      add(image.name, fmt::format("duplicate NAME (also IMAGE_ID {})", it->second));
    }
    for (size_t i = 0; i < image.points2d.size() && !Full(problems); ++i) {
      const ColmapPoint2D& point = image.points2d[i];
      if (!point.xy.allFinite()) add(fmt::format("POINTS2D[{}]", i), "X and Y must be finite");
      if (point.point3d_id < -1) {
        add(fmt::format("POINTS2D[{}] POINT3D_ID {}", i, point.point3d_id),
            "POINT3D_ID must be -1 or a point id");
      } else if (point.point3d_id >= 0 &&
                 !model.points3d.contains(static_cast<uint64_t>(point.point3d_id))) {
        add(fmt::format("POINTS2D[{}] POINT3D_ID {}", i, point.point3d_id),
            "2D point references a missing 3D point");
      }
    }
  }
}

void CheckPoints3D(const ColmapModel& model, const std::string& file, const RecordPlaces* places,
                   ProblemList& problems) {
  for (const auto& [id, point] : model.points3d) {
    if (Full(problems)) return;
    const std::string where = PlaceOf(places, &RecordPlaces::points3d, id, "POINT3D_ID");
    if (point.point3d_id != id) {
      problems.Add(file, where, std::to_string(point.point3d_id),
                   "point3d_id differs from its key");
    }
    if (id > static_cast<uint64_t>(kMaxPoint3DId)) {
      problems.Add(file, where, std::to_string(id), "POINT3D_ID must be below 2^63");
    }
    if (!point.xyz.allFinite() || !std::isfinite(point.error)) {
      problems.Add(
          file, where,
          fmt::format("{} {} {} {}", point.xyz[0], point.xyz[1], point.xyz[2], point.error),
          "X, Y, Z and ERROR must be finite");
    }
    for (const ColmapTrackElement& element : point.track) {
      auto image = model.images.find(element.image_id);
      if (image == model.images.end()) {
        problems.Add(file, where, fmt::format("TRACK IMAGE_ID {}", element.image_id),
                     "track references a missing image");
      } else if (element.point2d_idx >= image->second.points2d.size()) {
        problems.Add(file, where,
                     fmt::format("TRACK (IMAGE_ID {}, POINT2D_IDX {})", element.image_id,
                                 element.point2d_idx),
                     fmt::format("track references a missing 2D point (that image has {})",
                                 image->second.points2d.size()));
      }
    }
  }
}

void ValidateModel(const ColmapModel& model, const fs::path& dir, std::string_view extension,
                   const RecordPlaces* places) {
  auto file = [&](const char* stem) {
    return (dir / (std::string(stem) + std::string(extension))).string();
  };
  ProblemList problems;
  CheckCameras(model, file("cameras"), places, problems);
  CheckImages(model, file("images"), places, problems);
  CheckPoints3D(model, file("points3D"), places, problems);
  problems.ThrowIfAny();
}

// ---------------------------------------------------------------------------------------------
// TXT

std::vector<std::string_view> Tokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (true) {
    i = line.find_first_not_of(" \t\r", i);
    if (i == std::string_view::npos) break;
    size_t end = line.find_first_of(" \t\r", i);
    if (end == std::string_view::npos) end = line.size();
    tokens.push_back(line.substr(i, end - i));
    i = end;
  }
  return tokens;
}

// One text file, line by line, with the number of the line last returned (1-based). Token
// readers throw InputError "FILE: line N: TOKEN: RULE"; `what` names the field and `index`, when
// not negative, its position in a list.
class TextFile {
 public:
  explicit TextFile(const fs::path& path) : path_(path.string()), text_(ReadFileToString(path)) {}

  bool NextLine(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    const size_t end = std::min(text_.find('\n', pos_), text_.size());
    *line = std::string_view(text_).substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_number_;
    return true;
  }
  // Next line that is neither blank nor a comment, trimmed.
  bool NextDataLine(std::string_view* line) {
    while (NextLine(line)) {
      *line = Trim(*line);
      if (!line->empty() && line->front() != '#') return true;
    }
    return false;
  }
  const std::string& path() const { return path_; }
  std::string Place() const { return fmt::format("line {}", line_number_); }

  [[noreturn]] void Fail(std::string_view value, const std::string& rule) const {
    throw InputError(DescribeProblem(path_, Place(), std::string(value), rule));
  }
  double Double(std::string_view token, const char* what, long index = -1) const {
    const auto v = ParseDouble(token);
    if (!v) Fail(token, Field(what, index) + " is not a finite number");
    return *v;
  }
  long long Integer(std::string_view token, const char* what, long long min, long long max,
                    long index = -1) const {
    const auto v = ParseInt(token);
    if (!v || *v < min || *v > max) {
      Fail(token, fmt::format("{} must be an integer in [{}, {}]", Field(what, index), min, max));
    }
    return *v;
  }
  uint32_t Id32(std::string_view token, const char* what, long index = -1) const {
    return static_cast<uint32_t>(
        Integer(token, what, 0, std::numeric_limits<uint32_t>::max(), index));
  }

 private:
  static std::string Field(const char* what, long index) {
    return index < 0 ? std::string(what) : fmt::format(fmt::runtime(what), index);
  }
  std::string path_;
  std::string text_;
  size_t pos_ = 0;
  int line_number_ = 0;
};

ColmapCamera ParseCameraLine(const TextFile& file, std::string_view line) {
  const auto tokens = Tokens(line);
  if (tokens.size() < 4) {
    file.Fail(line, "a camera line needs CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
  }
  ColmapCamera camera;
  camera.camera_id = file.Id32(tokens[0], "CAMERA_ID");
  camera.model = std::string(tokens[1]);
  camera.width = static_cast<int>(file.Integer(tokens[2], "WIDTH", 1, INT_MAX));
  camera.height = static_cast<int>(file.Integer(tokens[3], "HEIGHT", 1, INT_MAX));
  for (size_t i = 4; i < tokens.size(); ++i) {
    camera.params.push_back(file.Double(tokens[i], "PARAMS[{}]", static_cast<long>(i - 4)));
  }
  if (auto p = CheckCamera(camera)) file.Fail(p->value, p->rule);
  return camera;
}

// The first of an image's two lines; NAME is the rest of the line after CAMERA_ID.
ColmapImage ParseImageLine(const TextFile& file, std::string_view line) {
  const auto tokens = Tokens(line);
  if (tokens.size() < 10) {
    file.Fail(line, "an image line needs IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
  }
  ColmapImage image;
  image.image_id = file.Id32(tokens[0], "IMAGE_ID");
  static constexpr const char* kNames[] = {"QW", "QX", "QY", "QZ", "TX", "TY", "TZ"};
  for (int i = 0; i < 4; ++i) image.qvec[i] = file.Double(tokens[1 + i], kNames[i]);
  for (int i = 0; i < 3; ++i) image.tvec[i] = file.Double(tokens[5 + i], kNames[4 + i]);
  image.camera_id = file.Id32(tokens[8], "CAMERA_ID");
  image.name = std::string(Trim(line.substr(tokens[9].data() - line.data())));
  if (auto p = CheckQuaternion(image.qvec, &image.qvec)) file.Fail(p->value, p->rule);
  return image;
}

// The second line of an image: (X, Y, POINT3D_ID) triples, possibly none.
void ParsePoints2DLine(const TextFile& file, std::string_view line, ColmapImage* image) {
  const auto tokens = Tokens(line);
  if (tokens.size() % 3 != 0) {
    file.Fail(fmt::format("{} values", tokens.size()),
              "POINTS2D[] must be (X, Y, POINT3D_ID) triples");
  }
  image->points2d.resize(tokens.size() / 3);
  for (size_t i = 0; i < image->points2d.size(); ++i) {
    ColmapPoint2D& point = image->points2d[i];
    const long index = static_cast<long>(i);
    point.xy.x() = file.Double(tokens[3 * i], "POINTS2D[{}] X", index);
    point.xy.y() = file.Double(tokens[3 * i + 1], "POINTS2D[{}] Y", index);
    point.point3d_id =
        file.Integer(tokens[3 * i + 2], "POINTS2D[{}] POINT3D_ID", -1, kMaxPoint3DId, index);
  }
}

ColmapPoint3D ParsePoint3DLine(const TextFile& file, std::string_view line) {
  const auto tokens = Tokens(line);
  if (tokens.size() < 8 || tokens.size() % 2 != 0) {
    file.Fail(fmt::format("{} values", tokens.size()),
              "a 3D point line needs POINT3D_ID X Y Z R G B ERROR and (IMAGE_ID, POINT2D_IDX) "
              "pairs");
  }
  ColmapPoint3D point;
  point.point3d_id = static_cast<uint64_t>(file.Integer(tokens[0], "POINT3D_ID", 0, kMaxPoint3DId));
  static constexpr const char* kNames[] = {"X", "Y", "Z", "R", "G", "B"};
  for (int i = 0; i < 3; ++i) point.xyz[i] = file.Double(tokens[1 + i], kNames[i]);
  for (int i = 0; i < 3; ++i) {
    point.rgb[i] = static_cast<uint8_t>(file.Integer(tokens[4 + i], kNames[3 + i], 0, 255));
  }
  point.error = file.Double(tokens[7], "ERROR");
  point.track.resize((tokens.size() - 8) / 2);
  for (size_t k = 0; k < point.track.size(); ++k) {
    const long index = static_cast<long>(k);
    point.track[k] = {file.Id32(tokens[8 + 2 * k], "TRACK[{}] IMAGE_ID", index),
                      file.Id32(tokens[9 + 2 * k], "TRACK[{}] POINT2D_IDX", index)};
  }
  return point;
}

// Adds a parsed record unless its id is taken (then a problem naming the first place).
template <typename Key, typename Record>
void InsertUnique(const TextFile& file, const std::string& place, Key id, Record record,
                  std::map<Key, Record>* records, std::map<Key, std::string>* places,
                  const char* id_name) {
  auto [it, fresh] = places->emplace(id, place);
  if (!fresh) {
    throw InputError(
        DescribeProblem(file.path(), place, std::to_string(id),
                        fmt::format("duplicate {} (first on {})", id_name, it->second)));
  }
  records->emplace(id, std::move(record));
}

// Calls parse(file, line) for each data line, collecting the InputErrors it throws.
template <typename Parse>
void ForEachDataLine(const fs::path& path, ProblemList& problems, Parse&& parse) {
  TextFile file(path);
  std::string_view line;
  while (!Full(problems) && file.NextDataLine(&line)) {
    try {
      parse(file, line);
    } catch (const InputError& e) {
      problems.Append(e);
    }
  }
}

void ReadModelText(const fs::path& dir, ColmapModel* model, RecordPlaces* places,
                   ProblemList& problems) {
  ForEachDataLine(dir / "cameras.txt", problems, [&](TextFile& file, std::string_view line) {
    ColmapCamera camera = ParseCameraLine(file, line);
    InsertUnique(file, file.Place(), camera.camera_id, std::move(camera), &model->cameras,
                 &places->cameras, "CAMERA_ID");
  });
  ForEachDataLine(dir / "images.txt", problems, [&](TextFile& file, std::string_view line) {
    // The second line always follows (it may be empty); a file that ends right after the first
    // line is read as an image without 2D points.
    const std::string place = file.Place();
    std::string_view points_line;
    ColmapImage image;
    try {
      image = ParseImageLine(file, line);
    } catch (const InputError&) {
      file.NextLine(&points_line);  // skip this image's second line too
      throw;
    }
    if (file.NextLine(&points_line)) ParsePoints2DLine(file, points_line, &image);
    InsertUnique(file, place, image.image_id, std::move(image), &model->images, &places->images,
                 "IMAGE_ID");
  });
  ForEachDataLine(dir / "points3D.txt", problems, [&](TextFile& file, std::string_view line) {
    ColmapPoint3D point = ParsePoint3DLine(file, line);
    InsertUnique(file, file.Place(), point.point3d_id, std::move(point), &model->points3d,
                 &places->points3d, "POINT3D_ID");
  });
}

// ---------------------------------------------------------------------------------------------
// BIN (little-endian, as COLMAP's WriteBinaryLittleEndian)

template <typename T>
T FromLittleEndian(const char* bytes) {
  std::array<char, sizeof(T)> buffer;
  std::memcpy(buffer.data(), bytes, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(buffer.begin(), buffer.end());
  T value;
  std::memcpy(&value, buffer.data(), sizeof(T));
  return value;
}

// A whole binary file with a read position; problems name the current record and its offset.
class ByteReader {
 public:
  explicit ByteReader(const fs::path& path)
      : path_(path.string()), data_(ReadFileToString(path)), place_("header (byte 0)") {}

  void StartRecord(std::string_view what, uint64_t index) {
    place_ = fmt::format("{} record {} (byte {})", what, index, pos_);
  }
  const std::string& place() const { return place_; }

  [[noreturn]] void Fail(const std::string& value, const std::string& rule) const {
    throw InputError(DescribeProblem(path_, place_, value, rule));
  }
  void Need(size_t bytes) const {
    if (data_.size() - pos_ < bytes) {
      Fail(fmt::format("{} bytes needed at byte {}, file has {}", bytes, pos_, data_.size()),
           "truncated file");
    }
  }
  template <typename T>
  T Read() {
    Need(sizeof(T));
    const T value = FromLittleEndian<T>(data_.data() + pos_);
    pos_ += sizeof(T);
    return value;
  }
  double Finite(std::string_view what) {
    const double v = Read<double>();
    if (!std::isfinite(v)) Fail(fmt::format("{} = {}", what, v), "must be a finite number");
    return v;
  }
  // A count of records that take at least `min_bytes` each; rejects counts the file cannot hold
  // (before anything is allocated for them).
  uint64_t Count(size_t min_bytes, std::string_view what) {
    const uint64_t count = Read<uint64_t>();
    const uint64_t left = data_.size() - pos_;
    if (count > left / min_bytes) {
      Fail(fmt::format("{} {} need at least {} bytes, {} left", count, what,
                       static_cast<long double>(count) * min_bytes, left),
           "truncated file or corrupt count");
    }
    return count;
  }
  std::string NullTerminated(std::string_view what) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) {
      Fail(fmt::format("{} starting at byte {} has no terminating NUL", what, pos_),
           "truncated file");
    }
    std::string text = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return text;
  }
  void ExpectEnd() {
    if (pos_ != data_.size()) {
      place_ = fmt::format("byte {}", pos_);
      Fail(fmt::format("{} bytes", data_.size() - pos_), "trailing bytes after the last record");
    }
  }

 private:
  std::string path_;
  std::string data_;
  std::string place_;
  size_t pos_ = 0;
};

void ReadCamerasBinary(const fs::path& path, ColmapModel* model, RecordPlaces* places) {
  ByteReader in(path);
  const uint64_t count = in.Count(24, "cameras");
  for (uint64_t i = 0; i < count; ++i) {
    in.StartRecord("camera", i);
    ColmapCamera camera;
    camera.camera_id = in.Read<uint32_t>();
    const int32_t model_id = in.Read<int32_t>();
    const auto name = ColmapModelNameFromId(model_id);
    if (!name) in.Fail(fmt::format("model id {}", model_id), "unknown camera model (ids 0-10)");
    camera.model = *name;
    const uint64_t width = in.Read<uint64_t>();
    const uint64_t height = in.Read<uint64_t>();
    if (width == 0 || height == 0 || width > INT_MAX || height > INT_MAX) {
      in.Fail(fmt::format("{}x{}", width, height), "WIDTH and HEIGHT must be in [1, 2^31)");
    }
    camera.width = static_cast<int>(width);
    camera.height = static_cast<int>(height);
    camera.params.resize(ColmapModelNumParams(camera.model));
    for (double& p : camera.params) p = in.Finite("param");
    if (!places->cameras.emplace(camera.camera_id, in.place()).second) {
      in.Fail(std::to_string(camera.camera_id), "duplicate CAMERA_ID");
    }
    model->cameras.emplace(camera.camera_id, std::move(camera));
  }
  in.ExpectEnd();
}

void ReadImagesBinary(const fs::path& path, ColmapModel* model, RecordPlaces* places) {
  ByteReader in(path);
  const uint64_t count = in.Count(4 + 7 * 8 + 4 + 1 + 8, "images");
  for (uint64_t i = 0; i < count; ++i) {
    in.StartRecord("image", i);
    ColmapImage image;
    image.image_id = in.Read<uint32_t>();
    for (int k = 0; k < 4; ++k) image.qvec[k] = in.Finite("qvec");
    for (int k = 0; k < 3; ++k) image.tvec[k] = in.Finite("tvec");
    if (auto p = CheckQuaternion(image.qvec, &image.qvec)) in.Fail(p->value, p->rule);
    image.camera_id = in.Read<uint32_t>();
    image.name = in.NullTerminated("NAME");
    image.points2d.resize(in.Count(3 * 8, "points2D"));
    for (ColmapPoint2D& point : image.points2d) {
      point.xy.x() = in.Finite("X");
      point.xy.y() = in.Finite("Y");
      const uint64_t id = in.Read<uint64_t>();
      if (id != kColmapNoPoint3DIdBinary && id > static_cast<uint64_t>(kMaxPoint3DId)) {
        in.Fail(fmt::format("POINT3D_ID {}", id), "POINT3D_ID must be below 2^63 or 2^64-1");
      }
      point.point3d_id = id == kColmapNoPoint3DIdBinary ? -1 : static_cast<int64_t>(id);
    }
    if (!places->images.emplace(image.image_id, in.place()).second) {
      in.Fail(std::to_string(image.image_id), "duplicate IMAGE_ID");
    }
    model->images.emplace(image.image_id, std::move(image));
  }
  in.ExpectEnd();
}

void ReadPoints3DBinary(const fs::path& path, ColmapModel* model, RecordPlaces* places) {
  ByteReader in(path);
  const uint64_t count = in.Count(8 + 3 * 8 + 3 + 8 + 8, "points");
  for (uint64_t i = 0; i < count; ++i) {
    in.StartRecord("point", i);
    ColmapPoint3D point;
    point.point3d_id = in.Read<uint64_t>();
    for (int k = 0; k < 3; ++k) point.xyz[k] = in.Finite("XYZ");
    for (int k = 0; k < 3; ++k) point.rgb[k] = in.Read<uint8_t>();
    point.error = in.Finite("ERROR");
    point.track.resize(in.Count(8, "track elements"));
    for (ColmapTrackElement& element : point.track) {
      element.image_id = in.Read<uint32_t>();
      element.point2d_idx = in.Read<uint32_t>();
    }
    if (!places->points3d.emplace(point.point3d_id, in.place()).second) {
      in.Fail(std::to_string(point.point3d_id), "duplicate POINT3D_ID");
    }
    model->points3d.emplace(point.point3d_id, std::move(point));
  }
  in.ExpectEnd();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public API

int ColmapModelNumParams(std::string_view model) {
  const CameraModelInfo* info = FindCameraModel(model);
  return info == nullptr ? -1 : info->num_params;
}

std::optional<int> ColmapModelIdFromName(std::string_view model) {
  const CameraModelInfo* info = FindCameraModel(model);
  return info == nullptr ? std::nullopt : std::optional<int>(info->id);
}

std::optional<std::string> ColmapModelNameFromId(int model_id) {
  if (model_id < 0 || model_id >= static_cast<int>(kCameraModels.size())) return std::nullopt;
  return std::string(kCameraModels[model_id].name);
}

std::vector<std::string> ColmapModelNames() {
  std::vector<std::string> names;
  for (const CameraModelInfo& info : kCameraModels) names.emplace_back(info.name);
  return names;
}

const ColmapImage* ColmapModel::FindImageByName(std::string_view name) const {
  for (const auto& [id, image] : images) {
    if (image.name == name) return &image;
  }
  return nullptr;
}

size_t ColmapModel::NumObservations() const {
  size_t count = 0;
  for (const auto& [id, image] : images) {
    for (const ColmapPoint2D& point : image.points2d) count += point.point3d_id >= 0 ? 1 : 0;
  }
  return count;
}

void ValidateColmapModel(const ColmapModel& model, const fs::path& dir,
                         std::string_view extension) {
  ValidateModel(model, dir, extension, nullptr);
}

namespace {
// Throws InputError naming each of the three files missing from `dir`.
void RequireFiles(const fs::path& dir, const char* extension) {
  ProblemList problems;
  for (const char* stem : {"cameras", "images", "points3D"}) {
    const fs::path path = dir / (std::string(stem) + extension);
    if (!fs::is_regular_file(path)) {
      problems.Add(path.string(), "", "",
                   "missing file: a COLMAP model needs cameras, images and points3D");
    }
  }
  problems.ThrowIfAny();
}
}  // namespace

ColmapModel ReadColmapModel(const fs::path& dir) {
  for (const char* stem : {"cameras", "images", "points3D"}) {
    if (!fs::is_regular_file(dir / (std::string(stem) + ".bin"))) return ReadColmapModelText(dir);
  }
  return ReadColmapModelBinary(dir);
}

ColmapModel ReadColmapModelText(const fs::path& dir) {
  RequireFiles(dir, ".txt");
  ColmapModel model;
  RecordPlaces places;
  ProblemList problems;
  ReadModelText(dir, &model, &places, problems);
  problems.ThrowIfAny();
  ValidateModel(model, dir, ".txt", &places);
  return model;
}

ColmapModel ReadColmapModelBinary(const fs::path& dir) {
  RequireFiles(dir, ".bin");
  ColmapModel model;
  RecordPlaces places;
  ReadCamerasBinary(dir / "cameras.bin", &model, &places);
  ReadImagesBinary(dir / "images.bin", &model, &places);
  ReadPoints3DBinary(dir / "points3D.bin", &model, &places);
  ValidateModel(model, dir, ".bin", &places);
  return model;
}

}  // namespace igi::recon
