#include "tools/pipeline/photo_layout.h"

#include <algorithm>
#include <fstream>
#include <set>

#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::pipeline {
namespace fs = std::filesystem;

namespace {

const std::set<std::string> kLdr = {".png", ".jpg", ".jpeg", ".tif", ".tiff"};
const std::set<std::string> kRaw = {".dng", ".cr2", ".cr3", ".nef", ".arw", ".orf",
                                    ".rw2", ".raf", ".pef", ".srw", ".nrw", ".raw"};
const std::set<std::string> kRadiance = {".exr", ".hdr"};

bool ValidName(const std::string& name) {
  if (name.empty() || name[0] == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

// Exposure times listed in `file` (non-empty lines without '#' comments).
size_t CountExposures(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  size_t n = 0;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (!Trim(line).empty()) ++n;
  }
  return n;
}

std::string Lighting(const std::string& name, const std::vector<std::string>& lightings,
                     ProblemList* problems, const fs::path& dir) {
  const auto us = name.rfind('_');
  if (us != std::string::npos) {
    const std::string suffix = name.substr(us + 1);
    if (std::find(lightings.begin(), lightings.end(), suffix) != lightings.end()) return suffix;
  }
  if (lightings.size() == 1) return lightings[0];
  problems->Add(dir.string(), "lighting", name,
                "folder name must end in _LIGHTING, LIGHTING one of the scene's lightings (" +
                    Join(lightings, ", ") + ")");
  return "";
}

void Classify(PhotoSource* p, ProblemList* problems) {
  std::vector<fs::path> ldr, raw, radiance, other;
  for (const auto& e : fs::directory_iterator(p->dir)) {
    const std::string file = e.path().filename().string();
    if (file == "exposures.txt") {
      p->exposure_file = e.path();
    } else if (file == "manifest.jsonl") {
      p->manifest = e.path();
    } else if (!e.is_regular_file() || file[0] == '.') {
      continue;  // frames/ of a capture, hidden files
    } else {
      const std::string ext = ToLower(e.path().extension().string());
      (kLdr.count(ext)        ? ldr
       : kRaw.count(ext)      ? raw
       : kRadiance.count(ext) ? radiance
                              : other)
          .push_back(e.path());
    }
  }
  const std::string where = p->dir.string();
  if (!p->manifest.empty()) {
    p->kind = PhotoSourceKind::kCapture;
    return;
  }
  const int kinds = !ldr.empty() + !raw.empty() + !radiance.empty();
  if (!other.empty()) {
    problems->Add(other[0].string(), "", other[0].extension().string(),
                  "is not an image igi-run reads (PNG/JPEG/TIFF, raw, EXR/HDR)");
  } else if (kinds != 1) {
    problems->Add(where, "", kinds == 0 ? "empty" : "mixed kinds",
                  "must hold one of: an LDR bracket, raw files, one radiance map, "
                  "or a capture (manifest.jsonl)");
  } else if (!radiance.empty()) {
    p->kind = PhotoSourceKind::kRadiance;
    p->images = radiance;
    if (radiance.size() != 1) {
      problems->Add(where, "", std::to_string(radiance.size()) + " radiance maps",
                    "must hold exactly one");
    }
  } else {
    p->kind = ldr.empty() ? PhotoSourceKind::kRaw : PhotoSourceKind::kBracket;
    p->images = ldr.empty() ? raw : ldr;
    std::sort(p->images.begin(), p->images.end());
    if (p->kind == PhotoSourceKind::kBracket && p->images.size() < 2) {
      problems->Add(where, "", "1 LDR image",
                    "a bracket needs at least 2 exposures (or give a radiance map)");
    }
    if (!p->exposure_file.empty() && CountExposures(p->exposure_file) != p->images.size()) {
      problems->Add(p->exposure_file.string(), "",
                    std::to_string(CountExposures(p->exposure_file)) + " exposures",
                    "must list one per image (" + std::to_string(p->images.size()) + ")");
    }
  }
}

}  // namespace

const char* KindName(PhotoSourceKind kind) {
  switch (kind) {
    case PhotoSourceKind::kBracket:
      return "LDR bracket";
    case PhotoSourceKind::kRaw:
      return "raw";
    case PhotoSourceKind::kRadiance:
      return "radiance map";
    case PhotoSourceKind::kCapture:
      return "capture";
  }
  return "?";
}

int PhotoLayout::ResponseSource() const {
  int best = -1;
  for (size_t i = 0; i < photos.size(); ++i) {
    if (photos[i].kind != PhotoSourceKind::kBracket) continue;
    if (best < 0 || photos[i].images.size() > photos[best].images.size()) best = int(i);
  }
  return best;
}

PhotoLayout ScanPhotosDir(const fs::path& dir, const std::vector<std::string>& lightings) {
  if (!fs::is_directory(dir)) {
    throw InputError(DescribeProblem(dir.string(), "PHOTOS_DIR", "", "is not a folder"));
  }
  PhotoLayout layout;
  layout.dir = dir;
  ProblemList problems;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_directory()) {
      if (!ValidName(name)) {
        problems.Add(e.path().string(), "", name, "photo names use letters, digits, _ - . only");
        continue;
      }
      PhotoSource p;
      p.name = name;
      p.dir = e.path();
      p.lighting = Lighting(name, lightings, &problems, e.path());
      Classify(&p, &problems);
      layout.photos.push_back(p);
    } else if (name == "camera.json") {
      layout.camera = e.path();
    } else if (name == "markers.json") {
      layout.markers = e.path();
    } else if (name == "colour.json") {
      layout.colour = e.path();
    } else if (name == "lights.json") {
      layout.lights = e.path();
    } else if (name[0] != '.' && name != "README.md" && name != "README.txt") {
      problems.Add(e.path().string(), "", name,
                   "is not part of the layout (one sub-folder per photo, camera.json, "
                   "colour.json, lights.json, markers.json)");
    }
  }
  std::sort(layout.photos.begin(), layout.photos.end(),
            [](const PhotoSource& a, const PhotoSource& b) { return a.name < b.name; });
  if (layout.photos.empty() && problems.empty()) {
    problems.Add(dir.string(), "PHOTOS_DIR", "no photo folders",
                 "needs one sub-folder per photo (docs/run.md)");
  }
  problems.ThrowIfAny();
  return layout;
}

}  // namespace igi::pipeline
