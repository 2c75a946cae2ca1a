#pragma once
// Stage markers of igi-run: DIR/NN-stage/stage.json, written atomically when a stage finished,
// with the fingerprint of everything the stage read. A rerun keeps a stage whose marker carries
// the same fingerprint and redoes one whose inputs changed (or that never finished).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tools/common/json.h"

namespace igi::pipeline {

// FNV-1a (64 bit) over strings and file contents, order-sensitive.
class Fingerprint {
 public:
  void AddText(std::string_view text);
  // A file's name and contents (a missing file adds its name and "missing"). A folder adds
  // every regular file under it, sorted by path.
  void AddFile(const std::filesystem::path& path);
  std::string Hex() const;

 private:
  void AddBytes(const char* data, size_t size);
  uint64_t hash_ = 1469598103934665603ull;
};

struct StageMarker {
  std::string stage;        // "04-solve"
  std::string fingerprint;  // Fingerprint::Hex() of the stage's inputs
  std::string status;       // "done", "partial" (the tool exited 3) or "skipped"
  double seconds = 0;
  std::string finished_utc;           // ISO 8601
  std::vector<std::string> commands;  // the command lines run (for the record)
  Json details = Json::object();      // stage-specific notes
};

std::filesystem::path MarkerPath(const std::filesystem::path& stage_dir);
// The marker of `stage_dir`, or nothing when it is absent or unreadable (= not finished).
std::optional<StageMarker> ReadStageMarker(const std::filesystem::path& stage_dir);
void WriteStageMarker(const std::filesystem::path& stage_dir, const StageMarker& marker);
std::string UtcNow();

}  // namespace igi::pipeline
