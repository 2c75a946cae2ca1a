#include "capture/manifest.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi::capture {

Json ManifestEntryToJson(const ManifestEntry& entry) {
  Json json;
  json["file"] = entry.file;
  json["camera"] = entry.camera;
  json["exposure_us"] = entry.exposure_us;
  json["gain"] = entry.gain ? Json(*entry.gain) : Json(nullptr);
  json["pixel_format"] = entry.pixel_format;
  json["timestamp"] = entry.timestamp.empty() ? Json(nullptr) : Json(entry.timestamp);
  json["bracket"] = entry.bracket;
  json["frame"] = entry.frame;
  for (const auto& [key, value] : entry.extra.items()) json[key] = value;
  return json;
}

void AppendManifest(const std::filesystem::path& manifest_path, const ManifestEntry& entry,
                    bool durable) {
  const std::string line = ManifestEntryToJson(entry).dump();
  if (durable) {
    AppendLineDurable(manifest_path, line);
    return;
  }
  const int fd = ::open(manifest_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(manifest_path.string() + ": cannot append: " + std::strerror(errno));
  const std::string buffer = line + "\n";
  const ssize_t written = ::write(fd, buffer.data(), buffer.size());  // O_APPEND: one piece
  const int write_errno = errno;
  ::close(fd);
  if (written != ssize_t(buffer.size())) {
    throw Error(manifest_path.string() + ": cannot append: " + std::strerror(write_errno));
  }
}

void SyncFileSystem(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  ::syncfs(fd);
  ::close(fd);
}

namespace {

ManifestEntry ParseLine(const std::string& line, const std::string& source) {
  const Json json = ParseJson(line, source);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(json, source, &problems);
  ManifestEntry entry;
  entry.file = root["file"].NonEmptyString().value_or("");
  entry.camera = root["camera"].String().value_or("");
  entry.exposure_us = root["exposure_us"].Number(NumberRule::Positive()).value_or(0);
  if (root["gain"].present()) entry.gain = root["gain"].Number();
  entry.pixel_format = root["pixel_format"].String().value_or("");
  if (root["timestamp"].present()) entry.timestamp = root["timestamp"].String().value_or("");
  entry.bracket = int(root["bracket"].Integer(NumberRule::NonNegative()).value_or(0));
  entry.frame = int(root["frame"].Integer(NumberRule::NonNegative()).value_or(0));
  problems.ThrowIfAny();
  for (const auto& [key, value] : json.items()) {
    static const char* kFixed[] = {"file",         "camera",    "exposure_us", "gain",
                                   "pixel_format", "timestamp", "bracket",     "frame"};
    bool fixed = false;
    for (const char* name : kFixed) fixed = fixed || key == name;
    if (!fixed) entry.extra[key] = value;
  }
  return entry;
}

}  // namespace

ManifestContents ReadManifest(const std::filesystem::path& manifest_path) {
  ManifestContents contents;
  const std::string text = ReadFileToString(manifest_path);
  size_t start = 0;
  int line_number = 0;
  while (start < text.size()) {
    ++line_number;
    const size_t end = text.find('\n', start);
    if (end == std::string::npos) {  // no newline: the append was cut short
      contents.truncated_last_line = true;
      break;
    }
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    contents.entries.push_back(
        ParseLine(line, manifest_path.string() + ":" + std::to_string(line_number)));
  }
  return contents;
}

std::string FormatTimestamp(uint64_t unix_ns) {
  const std::time_t seconds = std::time_t(unix_ns / 1000000000u);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}.{:06d}Z", utc.tm_year + 1900,
                     utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec,
                     int((unix_ns % 1000000000u) / 1000u));
}

}  // namespace igi::capture
