#include "calib/bracket.h"

#include <fmt/format.h>

#include "calib/exposure_times.h"
#include "tools/common/error.h"

namespace igi::calib {

std::vector<double> ResolveExposures(const ExposureSource& source,
                                     const std::vector<std::string>& names,
                                     const std::vector<ImageMetadata>& metadata) {
  std::vector<double> exposures;
  std::string where = "EXIF";
  if (!source.list.empty()) {
    exposures = ParseExposureList(source.list);
    where = "--exposures";
  } else if (!source.file.empty()) {
    exposures = ReadExposureFile(source.file);
    where = source.file.string();
  } else {
    for (size_t i = 0; i < names.size(); ++i) {
      exposures.push_back(ExposureFromMetadata(metadata[i], names[i]));
    }
  }
  ValidateExposures(exposures, names, where);
  return exposures;
}

void CheckSameShape(const std::vector<Image>& images, const std::vector<std::string>& names) {
  ProblemList problems;
  for (size_t i = 1; i < images.size(); ++i) {
    if (images[i].width != images[0].width || images[i].height != images[0].height ||
        images[i].channels != images[0].channels) {
      problems.Add(names[i], "size",
                   fmt::format("{}x{}x{}", images[i].width, images[i].height, images[i].channels),
                   fmt::format("every image of a bracket must have the size of {} ({}x{}x{})",
                               names[0], images[0].width, images[0].height, images[0].channels));
    }
  }
  problems.ThrowIfAny();
}

Bracket LoadBracketHeaders(const std::vector<std::filesystem::path>& paths,
                           const ExposureSource& source, int* channels) {
  Bracket bracket;
  if (paths.size() < 2) {
    throw InputError(DescribeProblem(paths.empty() ? "" : paths[0].string(), "images",
                                     fmt::format("{}", paths.size()),
                                     "a bracket needs at least 2 images"));
  }
  ProblemList problems;
  std::vector<ImageMetadata> metadata;
  std::vector<ImageInfo> infos;
  for (const auto& path : paths) {
    const std::string name = path.string();
    bracket.names.push_back(name);
    try {
      const ImageInfo info = ReadImageInfo(path);
      const int bits = info.type == PixelType::kUInt8    ? 8
                       : info.type == PixelType::kUInt16 ? 16
                                                         : 0;
      if (bits == 0) {
        problems.Add(name, "pixel type", fmt::format("{} bits", info.bits_per_sample),
                     "bracket images must be 8- or 16-bit integer levels");
        continue;
      }
      if (infos.empty()) bracket.bits_per_sample = bits;
      if (bits != bracket.bits_per_sample) {
        problems.Add(
            name, "pixel type", fmt::format("{} bits", bits),
            fmt::format("must match {} ({} bits)", bracket.names[0], bracket.bits_per_sample));
        continue;
      }
      metadata.push_back(info.metadata);
      infos.push_back(info);
    } catch (const Error& e) {
      problems.Append(e);
    }
  }
  problems.ThrowIfAny();
  for (size_t i = 1; i < infos.size(); ++i) {
    if (infos[i].width != infos[0].width || infos[i].height != infos[0].height ||
        infos[i].channels != infos[0].channels) {
      problems.Add(
          bracket.names[i], "size",
          fmt::format("{}x{}x{}", infos[i].width, infos[i].height, infos[i].channels),
          fmt::format("every image of a bracket must have the size of {} ({}x{}x{})",
                      bracket.names[0], infos[0].width, infos[0].height, infos[0].channels));
    }
  }
  problems.ThrowIfAny();
  bracket.exposures_s = ResolveExposures(source, bracket.names, metadata);
  *channels = infos[0].channels;
  return bracket;
}

Bracket LoadBracket(const std::vector<std::filesystem::path>& paths, const ExposureSource& source) {
  int channels = 0;
  Bracket bracket = LoadBracketHeaders(paths, source, &channels);
  ProblemList problems;
  for (const auto& path : paths) {
    try {
      bracket.images.push_back(ReadImage(path));
    } catch (const Error& e) {
      problems.Append(e);
    }
  }
  problems.ThrowIfAny();
  CheckSameShape(bracket.images, bracket.names);  // the pixels as read, against the headers'
  return bracket;
}

}  // namespace igi::calib
