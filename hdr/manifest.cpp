#include "hdr/manifest.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/json.h"
#include "tools/common/strings.h"

namespace igi::hdr {
namespace {

std::string SafeName(const std::string& s) {
  std::string out;
  for (char ch : s) out += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-') ? ch : '_';
  return out.empty() ? "camera" : out;
}

// Parses one line; reports problems (with the line's key path) and returns false when bad.
bool ParseFrame(const Json& object, const std::string& source, const std::filesystem::path& dir,
                int line, ProblemList* problems, ManifestFrame* frame) {
  const size_t before = problems->size();
  const JsonCursor root = JsonCursor::Root(object, source, problems);
  if (!object.is_object()) {
    root.Problem("each line must be a JSON object");
    return false;
  }
  frame->line = line;
  if (const auto file = root["file"].NonEmptyString()) frame->file = dir / *file;
  if (const auto camera = root["camera"].NonEmptyString()) frame->camera = *camera;
  if (const auto us = root["exposure_us"].Number(NumberRule::Positive())) {
    frame->exposure_s = *us * 1e-6;
  }
  // "gain" and "timestamp" are required keys whose value may be null: igi-capture writes null
  // where the camera or the raw file does not record them (frames of unknown gain share gain 0).
  const JsonCursor gain = root["gain"];
  if (gain.raw() == nullptr) {
    gain.Problem("required key is missing");
  } else if (gain.present()) {
    if (const auto g = gain.Number(NumberRule::Any())) frame->gain = *g;
  }
  if (const auto format = root["pixel_format"].String()) frame->pixel_format = *format;
  if (root["timestamp"].raw() == nullptr) root["timestamp"].Problem("required key is missing");
  const JsonCursor bracket = root["bracket"];
  if (bracket.IsString()) {
    frame->bracket = bracket.raw()->get<std::string>();
  } else if (bracket.present() && bracket.raw()->is_number_integer()) {
    frame->bracket = std::to_string(bracket.raw()->get<int64_t>());
  } else if (bracket.present()) {
    bracket.Problem("must be a string or an integer");
  }
  return problems->size() == before;
}

}  // namespace

std::vector<ManifestBracket> ReadManifest(const std::filesystem::path& path) {
  const std::string text = ReadFileToString(path);
  const std::filesystem::path dir = path.parent_path();
  ProblemList problems;
  std::vector<ManifestBracket> brackets;
  size_t start = 0;
  int line = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    const bool unterminated = end == std::string::npos;
    if (unterminated) end = text.size();
    const std::string content(Trim(std::string_view(text).substr(start, end - start)));
    start = end + 1;
    ++line;
    if (content.empty()) continue;
    const std::string source = fmt::format("{}: line {}", path.string(), line);
    ManifestFrame frame;
    try {
      if (!ParseFrame(ParseJson(content, source), source, dir, line, &problems, &frame)) continue;
    } catch (const Error& e) {
      // igi-capture appends whole lines: a last line without its newline that is not JSON was
      // cut short by a capture that stopped mid-write, and lists no frame.
      if (unterminated) {
        spdlog::warn("{}: the last line was cut short (a capture stopped mid-write): skipped",
                     source);
        continue;
      }
      problems.Append(e);
      continue;
    }
    auto it = std::find_if(brackets.begin(), brackets.end(), [&](const ManifestBracket& b) {
      return b.camera == frame.camera && b.gain == frame.gain && b.bracket == frame.bracket;
    });
    if (it == brackets.end()) {
      brackets.push_back({frame.camera, frame.gain, frame.bracket, {}, ""});
      it = brackets.end() - 1;
    }
    it->frames.push_back(std::move(frame));
  }
  if (brackets.empty() && problems.empty()) {
    problems.Add(path.string(), "", "no frames", "the manifest must list at least one frame");
  }
  problems.ThrowIfAny();
  for (ManifestBracket& b : brackets) {
    b.label = SafeName(b.camera);
    bool gains_differ = false;
    for (const ManifestBracket& other : brackets) {
      gains_differ |= other.camera == b.camera && other.gain != b.gain;
    }
    if (gains_differ) b.label += fmt::format("_g{}", b.gain);
    if (!b.bracket.empty()) {
      b.label.push_back('_');
      b.label.append(SafeName(b.bracket));
    }
  }
  return brackets;
}

}  // namespace igi::hdr
