#include "capture/raw_import.h"

#include <libraw/libraw.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <set>

#include "capture/manifest.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::capture {
namespace fs = std::filesystem;
namespace {

constexpr const char* kManifestFile = "manifest.jsonl";

struct RawItem {
  fs::path path;
  RawFileInfo info;
  int bracket = 0;
  int frame = 0;
};

std::string Extension(const fs::path& path) {
  std::string extension = ToLower(path.extension().string());
  if (!extension.empty() && extension[0] == '.') extension.erase(0, 1);
  return extension;
}

// Every raw file of the folder, by name, read; all problems at once.
std::vector<RawItem> ReadFolder(const fs::path& raw_dir, RawImportSummary* summary) {
  std::vector<fs::path> paths;
  for (const auto& item : fs::directory_iterator(raw_dir)) {
    if (!item.is_regular_file()) continue;
    if (IsRawExtension(Extension(item.path()))) {
      paths.push_back(item.path());
    } else {
      summary->ignored.push_back(item.path().filename().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  ProblemList problems;
  std::vector<RawItem> items;
  for (const fs::path& path : paths) {
    try {
      items.push_back({path, ReadRawInfo(path)});
    } catch (const Error& e) {
      problems.Append(e);
    }
  }
  if (paths.empty()) problems.Add(raw_dir.string(), "", "", "holds no raw files");
  problems.ThrowIfAny();
  return items;
}

// Brackets are the distinct exposures, shortest first; frames count up within
// each.
void AssignSlots(std::vector<RawItem>* items) {
  std::set<double> exposures;
  for (const RawItem& item : *items) exposures.insert(item.info.exposure_us);
  std::map<double, int> next_frame;
  for (RawItem& item : *items) {
    item.bracket = int(std::distance(exposures.begin(), exposures.find(item.info.exposure_us)));
    item.frame = next_frame[item.info.exposure_us]++;
  }
}

ManifestEntry MakeEntry(const RawItem& item) {
  ManifestEntry entry;
  entry.file = "frames/" + item.path.filename().string();
  entry.camera = item.info.camera;
  entry.exposure_us = item.info.exposure_us;
  if (item.info.iso) entry.gain = *item.info.iso / 100.0;
  entry.pixel_format = "raw:" + Extension(item.path);
  entry.timestamp = item.info.timestamp;
  entry.bracket = item.bracket;
  entry.frame = item.frame;
  entry.extra["iso"] = item.info.iso ? Json(*item.info.iso) : Json(nullptr);
  entry.extra["black_level"] = item.info.black_level;
  entry.extra["white_level"] = item.info.white_level;
  entry.extra["width"] = item.info.width;
  entry.extra["height"] = item.info.height;
  entry.extra["source"] = fs::absolute(item.path).lexically_normal().string();
  return entry;
}

}  // namespace

bool IsRawExtension(const std::string& extension) {
  static const std::set<std::string> kRaw = {"3fr", "ari", "arw", "bay", "cr2", "cr3", "crw", "dcr",
                                             "dng", "erf", "fff", "iiq", "k25", "kdc", "mef", "mos",
                                             "mrw", "nef", "nrw", "orf", "pef", "raf", "raw", "rw2",
                                             "rwl", "sr2", "srf", "srw", "x3f"};
  return kRaw.count(extension) > 0;
}

RawFileInfo ReadRawInfo(const fs::path& path) {
  auto raw = std::make_unique<LibRaw>();  // large: keep it off the stack
  const int status = raw->open_file(path.c_str());
  if (status != LIBRAW_SUCCESS) {
    throw InputError(DescribeProblem(path.string(), "", "",
                                     std::string("cannot read raw: ") + libraw_strerror(status)));
  }
  const auto& data = raw->imgdata;
  RawFileInfo info;
  info.camera = Trim(std::string(data.idata.make) + " " + data.idata.model);
  info.exposure_us = double(data.other.shutter) * 1e6;
  if (data.other.iso_speed > 0) info.iso = double(data.other.iso_speed);
  if (data.other.timestamp > 0) {
    info.timestamp = FormatTimestamp(uint64_t(data.other.timestamp) * 1000000000u);
  }
  info.black_level = int(data.color.black);
  info.white_level = int(data.color.maximum);
  info.width = data.sizes.raw_width;
  info.height = data.sizes.raw_height;
  if (!(info.exposure_us > 0)) {
    throw InputError(DescribeProblem(path.string(), "ExposureTime",
                                     std::to_string(data.other.shutter),
                                     "must be a positive exposure time"));
  }
  return info;
}

void RawImportOptions::Validate() const {
  ProblemList problems;
  if (raw_dir.empty() || !fs::is_directory(raw_dir)) {
    problems.Add(raw_dir.string(), "--from-raw", "", "must be an existing folder");
  }
  if (out_dir.empty()) problems.Add("", "--out", "", "must name the output folder");
  problems.ThrowIfAny();
}

RawImportSummary ImportRaw(const RawImportOptions& options) {
  options.Validate();
  const fs::path manifest = options.out_dir / kManifestFile;
  if (fs::exists(manifest) && !options.resume) {
    throw InputError(DescribeProblem(options.out_dir.string(), "", "",
                                     "already holds a capture; pass --resume to add the "
                                     "missing files or choose another --out"));
  }
  RawImportSummary summary;
  std::vector<RawItem> items = ReadFolder(options.raw_dir, &summary);
  AssignSlots(&items);
  summary.files_found = int(items.size());
  std::set<std::string> done;
  if (fs::exists(manifest)) {
    for (const ManifestEntry& entry : ReadManifest(manifest).entries) {
      if (fs::exists(options.out_dir / entry.file)) done.insert(entry.file);
    }
  }
  for (const RawItem& item : items) {
    const ManifestEntry entry = MakeEntry(item);
    if (done.count(entry.file)) {
      ++summary.files_already_done;
      continue;
    }
    AtomicOutput output(options.out_dir / entry.file);
    fs::copy_file(item.path, output.temp_path(), fs::copy_options::overwrite_existing);
    output.Commit();
    AppendManifest(manifest, entry);
    ++summary.files_imported;
    spdlog::debug("imported {} ({} us, ISO {})", entry.file, entry.exposure_us,
                  item.info.iso.value_or(0));
  }
  return summary;
}

}  // namespace igi::capture
