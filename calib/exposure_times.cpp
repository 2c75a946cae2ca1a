#include "calib/exposure_times.h"

#include <fmt/format.h>

#include <cmath>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::calib {

double ParseExposureTime(const std::string& text, const std::string& source,
                         const std::string& key) {
  const std::string trimmed(Trim(text));
  std::optional<double> value;
  const size_t slash = trimmed.find('/');
  if (slash == std::string::npos) {
    value = ParseDouble(trimmed);
  } else {
    const auto num = ParseDouble(Trim(std::string_view(trimmed).substr(0, slash)));
    const auto den = ParseDouble(Trim(std::string_view(trimmed).substr(slash + 1)));
    if (num && den && *den != 0.0) value = *num / *den;
  }
  if (!value) {
    throw InputError(DescribeProblem(source, key, trimmed,
                                     "must be an exposure time in seconds (0.004 or 1/250)"));
  }
  if (!(*value > 0.0) || !std::isfinite(*value)) {
    throw InputError(DescribeProblem(source, key, trimmed, "exposure time must be > 0 s"));
  }
  return *value;
}

std::vector<double> ParseExposureList(const std::string& list) {
  std::vector<double> out;
  const std::vector<std::string> parts = SplitTokens(list, ",");
  for (size_t i = 0; i < parts.size(); ++i) {
    out.push_back(ParseExposureTime(parts[i], "--exposures", fmt::format("[{}]", i)));
  }
  return out;
}

std::vector<double> ReadExposureFile(const std::filesystem::path& path) {
  const std::string text = ReadFileToString(path);
  std::vector<double> out;
  size_t line_number = 0;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    ++line_number;
    start = end + 1;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    if (Trim(line).empty()) continue;
    out.push_back(ParseExposureTime(line, path.string(), fmt::format("line {}", line_number)));
  }
  return out;
}

double ExposureFromMetadata(const ImageMetadata& metadata, const std::string& image_name) {
  for (const char* key : {"ExposureTime", "Exif:ExposureTime"}) {
    const auto it = metadata.find(key);
    if (it == metadata.end()) continue;
    double value = 0.0;
    if (const auto* d = std::get_if<double>(&it->second)) value = *d;
    if (const auto* i = std::get_if<int64_t>(&it->second)) value = double(*i);
    if (const auto* s = std::get_if<std::string>(&it->second)) {
      return ParseExposureTime(*s, image_name, "ExposureTime");
    }
    if (value > 0.0 && std::isfinite(value)) return value;
    throw InputError(DescribeProblem(image_name, "ExposureTime", fmt::format("{}", value),
                                     "EXIF exposure time must be > 0 s"));
  }
  throw InputError(DescribeProblem(image_name, "ExposureTime", "missing",
                                   "no EXIF exposure time: give --exposures or --exposure-file"));
}

void ValidateExposures(const std::vector<double>& exposures_s,
                       const std::vector<std::string>& image_names, const std::string& source) {
  if (exposures_s.size() != image_names.size()) {
    throw InputError(DescribeProblem(
        source, "", fmt::format("{} exposure times", exposures_s.size()),
        fmt::format("must give one exposure time per image ({} images)", image_names.size())));
  }
  ProblemList problems;
  for (size_t i = 0; i < exposures_s.size(); ++i) {
    if (!(exposures_s[i] > 0.0) || !std::isfinite(exposures_s[i])) {
      problems.Add(image_names[i], "exposure", fmt::format("{}", exposures_s[i]),
                   "exposure time must be > 0 s");
    }
    for (size_t j = 0; j < i; ++j) {
      if (std::abs(exposures_s[i] - exposures_s[j]) <= 1e-3 * exposures_s[j]) {
        problems.Add(image_names[i], "exposure", fmt::format("{} s", exposures_s[i]),
                     fmt::format("duplicate exposure time (same as {})", image_names[j]));
      }
    }
  }
  problems.ThrowIfAny();
}

}  // namespace igi::calib
