#include "tools/pipeline/stage_marker.h"

#include <fmt/format.h>

#include <algorithm>
#include <ctime>
#include <fstream>

namespace igi::pipeline {
namespace fs = std::filesystem;

void Fingerprint::AddBytes(const char* data, size_t size) {
  for (size_t i = 0; i < size; ++i) {
    hash_ ^= static_cast<unsigned char>(data[i]);
    hash_ *= 1099511628211ull;
  }
}

void Fingerprint::AddText(std::string_view text) {
  AddBytes(text.data(), text.size());
  AddBytes("\0", 1);
}

void Fingerprint::AddFile(const fs::path& path) {
  AddText(path.generic_string());
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(path, ec)) {
      if (e.is_regular_file()) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) AddFile(f);
    return;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    AddText("missing");
    return;
  }
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    AddBytes(buffer.data(), static_cast<size_t>(in.gcount()));
  }
  AddText("end");
}

std::string Fingerprint::Hex() const { return fmt::format("{:016x}", hash_); }

fs::path MarkerPath(const fs::path& stage_dir) { return stage_dir / "stage.json"; }

std::optional<StageMarker> ReadStageMarker(const fs::path& stage_dir) {
  const fs::path path = MarkerPath(stage_dir);
  if (!fs::exists(path)) return std::nullopt;
  try {
    const Json j = ReadJsonFile(path);
    StageMarker m;
    m.stage = j.at("stage").get<std::string>();
    m.fingerprint = j.at("fingerprint").get<std::string>();
    m.status = j.at("status").get<std::string>();
    m.seconds = j.value("seconds", 0.0);
    m.finished_utc = j.value("finished_utc", "");
    m.commands = j.value("commands", std::vector<std::string>{});
    if (j.contains("details")) m.details = j["details"];
    return m;
  } catch (const std::exception&) {
    return std::nullopt;  // a damaged marker = an unfinished stage
  }
}

void WriteStageMarker(const fs::path& stage_dir, const StageMarker& m) {
  const Json j = {
      {"format", "igi-run-stage"},      {"version", 1},           {"stage", m.stage},
      {"fingerprint", m.fingerprint},   {"status", m.status},     {"seconds", m.seconds},
      {"finished_utc", m.finished_utc}, {"commands", m.commands}, {"details", m.details}};
  WriteJsonFile(MarkerPath(stage_dir), j);
}

std::string UtcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace igi::pipeline
