#pragma once
// Exposure times of a bracket (docs/file-formats.md): an exposure file lists one time in seconds
// per line, as a decimal ("0.004") or a fraction ("1/250"), in the order of the images; '#' starts
// a comment. `--exposures` takes the same values comma-separated. Times can also come from the
// images' EXIF (ExposureTime).
//
// Bad input (a value that is not a positive time, a count that does not match the images, two
// images with the same time, an image without EXIF time) is an igi::InputError naming the file
// or image, the value and the rule.

#include <filesystem>
#include <string>
#include <vector>

#include "tools/common/image.h"

namespace igi::calib {

// Parses one time ("0.004", "1/250", "2"); throws InputError "SOURCE: KEY: VALUE: RULE".
double ParseExposureTime(const std::string& text, const std::string& source,
                         const std::string& key);

// Parses a comma-separated list ("1/250,1/60,0.1").
std::vector<double> ParseExposureList(const std::string& list);

// Reads an exposure file (one time per line, '#' comments, blank lines ignored).
std::vector<double> ReadExposureFile(const std::filesystem::path& path);

// The EXIF exposure time of an image's metadata ("ExposureTime", seconds), or throws
// InputError "IMAGE: ExposureTime: missing: RULE".
double ExposureFromMetadata(const ImageMetadata& metadata, const std::string& image_name);

// Checks `exposures_s` against `image_names`: the same count, every time > 0, no two equal
// (within 0.1 %). Throws InputError naming the image and the rule.
void ValidateExposures(const std::vector<double>& exposures_s,
                       const std::vector<std::string>& image_names, const std::string& source);

}  // namespace igi::calib
