#pragma once
// DIR/manifest.jsonl (docs/file-formats.md): append-only, one JSON object per frame,
// written after the frame's file is complete, each line flushed to disk before
// the next frame. Keys: file (relative to DIR), camera, exposure_us, gain,
// pixel_format, timestamp (ISO 8601 UTC), and igi's additions: bracket, frame,
// requested_exposure_us, frame_id, camera_timestamp_ns, width, height,
// significant_bits (raw imports: iso, black_level, white_level, source).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tools/common/json.h"

namespace igi::capture {

struct ManifestEntry {
  std::string file;  // relative to the output folder: "frames/…"
  std::string camera;
  double exposure_us = 0.0;
  std::optional<double> gain;  // null when unknown
  std::string pixel_format;
  std::string timestamp;  // ISO 8601 UTC; empty when unknown (written as null)
  int bracket = 0;
  int frame = 0;
  Json extra = Json::object();  // further keys, written after the fixed ones
};

Json ManifestEntryToJson(const ManifestEntry& entry);

// Appends one line with a single write (a crash of this process loses nothing
// written); `durable` also flushes it to disk (fsync) before returning, which
// survives a power cut.
void AppendManifest(const std::filesystem::path& manifest_path, const ManifestEntry& entry,
                    bool durable = true);

// Flushes everything written to the file system holding `path` to disk
// (syncfs); for the end of a run that wrote without `durable`.
void SyncFileSystem(const std::filesystem::path& path);

struct ManifestContents {
  std::vector<ManifestEntry> entries;
  // A last line cut short (a crash while appending) is skipped, not an error.
  bool truncated_last_line = false;
};

// Reads every line strictly; a malformed complete line is an InputError naming
// the line.
ManifestContents ReadManifest(const std::filesystem::path& manifest_path);

// "2025-01-31T12:00:00.123456Z" from ns since the Unix epoch.
std::string FormatTimestamp(uint64_t unix_ns);

}  // namespace igi::capture
