// Calibration and HDR for igi.calib and igi.hdr: igi-calib response and intrinsics, igi-hdr's merge
// and its linear raw decode. Each takes its executable's options under the flags' names, parsed
// and validated by the same library functions (ParseLambda, ResponseOptions::Validate,
// MergeOptions::Validate, ...), so a bad value raises the line the executable prints. Files are
// written by the libraries' own writers (response.json, camera.json, the radiance map and its
// mask), atomically, after every check has passed. The GIL is released while the work runs.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "calib/bracket.h"
#include "calib/camera_file.h"
#include "calib/intrinsics.h"
#include "calib/response_curve.h"
#include "calib/response_plot.h"
#include "calib/response_recovery.h"
#include "hdr/align.h"
#include "hdr/correction.h"
#include "hdr/hdr_input.h"
#include "hdr/merge.h"
#include "hdr/merge_stream.h"
#include "hdr/raw_decode.h"
#include "python/src/bindings.h"
#include "tools/common/error.h"
#include "tools/common/json.h"
#include "tools/common/strings.h"

namespace igi::python {
namespace {

namespace fs = std::filesystem;

// A response curve with the "info" igi-calib response writes beside it (null when none).
struct PyResponse {
  calib::ResponseCurve curve;
  Json info;
  std::string source;  // the response.json it was read from; empty when recovered in memory
};

// The images of a bracket as Python gave them: all file paths or all arrays.
struct ImageList {
  std::vector<fs::path> paths;
  std::vector<py::array> arrays;
};

ImageList SplitImages(const py::list& images) {
  ImageList list;
  for (const py::handle item : images) {
    if (py::isinstance<py::str>(item)) {
      list.paths.emplace_back(item.cast<std::string>());
    } else {
      list.arrays.push_back(py::array::ensure(item));
      if (!list.arrays.back()) {
        throw InputError(DescribeProblem("images", "", py::str(py::type::of(item)),
                                         "must be file paths or arrays"));
      }
    }
  }
  if (!list.paths.empty() && !list.arrays.empty()) {
    throw InputError(DescribeProblem("images", "", "paths and arrays",
                                     "a bracket is all file paths or all arrays"));
  }
  return list;
}

// --exposures and --exposure-file exclude each other, as on igi-calib's and igi-hdr's command
// lines; both empty takes the times from the images' metadata.
calib::ExposureSource Exposures(const std::string& list, const std::string& file) {
  if (!list.empty() && !file.empty()) {
    throw InputError(DescribeProblem("--exposures", "", list, "excludes --exposure-file"));
  }
  return {list, file};
}

// An image's metadata given from Python, for its exposure time; values of other types are left
// out (nothing here reads them).
ImageMetadata Metadata(const py::dict& metadata) {
  ImageMetadata out;
  for (const auto& [key, value] : metadata) {
    const std::string name = py::str(key);
    if (py::isinstance<py::bool_>(value)) continue;
    if (py::isinstance<py::int_>(value)) out[name] = value.cast<int64_t>();
    if (py::isinstance<py::float_>(value)) out[name] = value.cast<double>();
    if (py::isinstance<py::str>(value)) out[name] = value.cast<std::string>();
  }
  return out;
}

// One array of a bracket as normalised levels: uint8 and uint16 are levels (their bits), floats
// are levels / (2^bits - 1) already. *bits gets the array's bits (0 for floats).
Image LevelsFromArray(const py::array& array, const std::string& name, int* bits) {
  if (array.ndim() != 2 && array.ndim() != 3) {
    throw InputError(DescribeProblem(name, "shape", std::to_string(array.ndim()) + " dimensions",
                                     "must be (H, W) or (H, W, C)"));
  }
  const int height = int(array.shape(0)), width = int(array.shape(1));
  const int channels = array.ndim() == 3 ? int(array.shape(2)) : 1;
  if (height < 1 || width < 1 || channels < 1 || channels > 8) {
    throw InputError(DescribeProblem(name, "shape", "", "needs pixels and 1 to 8 channels"));
  }
  float scale = 1.0f;
  if (py::isinstance<py::array_t<uint8_t>>(array)) {
    *bits = 8;
    scale = 1.0f / 255.0f;
  } else if (py::isinstance<py::array_t<uint16_t>>(array)) {
    *bits = 16;
    scale = 1.0f / 65535.0f;
  } else if (array.dtype().kind() == 'f') {
    *bits = 0;
  } else {
    throw InputError(DescribeProblem(name, "dtype", py::str(array.dtype()),
                                     "must be uint8 or uint16 levels, or float normalised levels"));
  }
  const auto values = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  Image image(width, height, channels);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = values.data()[i] * scale;
  return image;
}

// A bracket given as arrays (named "images[i]"), of one kind: 8- or 16-bit levels, or float
// normalised levels with `bits` 8 or 16 saying how they were quantised. Exposure times from
// `source`, else each image's metadata ("ExposureTime"), checked as LoadBracket checks them.
calib::Bracket BracketFromArrays(const std::vector<py::array>& arrays,
                                 const std::vector<py::dict>& metadata, int bits,
                                 const calib::ExposureSource& source) {
  if (arrays.size() < 2) {
    throw InputError(DescribeProblem("images", "", std::to_string(arrays.size()),
                                     "a bracket needs at least 2 images"));
  }
  calib::Bracket bracket;
  std::vector<ImageMetadata> exif;
  for (size_t i = 0; i < arrays.size(); ++i) {
    bracket.names.push_back("images[" + std::to_string(i) + "]");
    int array_bits = 0;
    bracket.images.push_back(LevelsFromArray(arrays[i], bracket.names.back(), &array_bits));
    if (array_bits == 0) array_bits = bits;
    if (array_bits != 8 && array_bits != 16) {
      throw InputError(DescribeProblem(bracket.names.back(), "bits", std::to_string(bits),
                                       "float levels need bits=8 or bits=16"));
    }
    if (i == 0) bracket.bits_per_sample = array_bits;
    if (array_bits != bracket.bits_per_sample) {
      throw InputError(DescribeProblem(
          bracket.names.back(), "bits", std::to_string(array_bits),
          "must match images[0] (" + std::to_string(bracket.bits_per_sample) + " bits)"));
    }
    exif.push_back(i < metadata.size() ? Metadata(metadata[i]) : ImageMetadata());
  }
  calib::CheckSameShape(bracket.images, bracket.names);
  bracket.exposures_s = calib::ResolveExposures(source, bracket.names, exif);
  return bracket;
}

// The bracket of igi-calib response: its files loaded by LoadBracket, or its arrays.
calib::Bracket LoadResponseBracket(const ImageList& images, const std::vector<py::dict>& metadata,
                                   int bits, const calib::ExposureSource& source) {
  if (images.paths.empty()) return BracketFromArrays(images.arrays, metadata, bits, source);
  py::gil_scoped_release release;
  return calib::LoadBracket(images.paths, source);
}

// igi-calib response's options from its flags' values, parsed and validated as igi-calib does.
calib::ResponseOptions ParseResponseOptions(const std::string& method, const std::string& lambda,
                                            const std::string& black,
                                            calib::ResponseOptions options) {
  const auto parsed = calib::ResponseRecoveryMethodFromName(method);
  if (!parsed) {
    throw InputError(DescribeProblem("--method", "", method, "must be debevec or robertson"));
  }
  options.method = *parsed;
  options.lambda = calib::ParseLambda(lambda);
  options.black = calib::ParseBlack(black);
  options.Validate();
  return options;
}

// response.json's "info", as igi-calib response writes it.
Json ResponseInfo(const std::vector<std::string>& images, const calib::Bracket& bracket,
                  const calib::ResponseSummary& summary, const calib::ResponseOptions& options) {
  Json info;
  info["images"] = images;
  info["exposures_s"] = bracket.exposures_s;
  info["bits_per_sample"] = bracket.bits_per_sample;
  info["samples"] = summary.samples;
  info["equations"] = summary.equations;
  if (options.method == calib::ResponseRecoveryMethod::kDebevec) {
    info["lambda"] = summary.lambda;
    info["lambda_mode"] = options.lambda == calib::kLambdaAuto ? "auto" : "given";
  }
  if (options.method == calib::ResponseRecoveryMethod::kRobertson) {
    info["iterations"] = summary.iterations;
    info["converged"] = summary.converged;
  }
  info["rms_residual_ln"] = summary.rms_residual;
  info["black"] = summary.black;
  info["black_mode"] = options.black == calib::kBlackAuto ? "auto" : "given";
  return info;
}

PyResponse ReadResponse(const Json& document, const std::string& source) {
  PyResponse r;
  r.curve = calib::ResponseFromJson(document, source);
  if (document.is_object() && document.contains("info")) r.info = document["info"];
  r.source = source;
  return r;
}

// g(v) of every value of `values` (..., C), C the curve's channels (any shape for one curve).
py::array_t<double> LnExposures(const calib::ResponseCurve& curve, const py::array& values) {
  const auto in = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  const int channels = curve.num_channels();
  if (!in || (channels > 1 && (in.ndim() < 1 || in.shape(in.ndim() - 1) != channels))) {
    throw InputError(DescribeProblem(
        "values", "shape", "",
        "must be (..., " + std::to_string(channels) + "): one value per channel of the curve"));
  }
  py::array_t<double> out(std::vector<py::ssize_t>(in.shape(), in.shape() + in.ndim()));
  const double* src = in.data();
  double* dst = out.mutable_data();
  const size_t n = size_t(in.size());
  py::gil_scoped_release release;
  for (size_t i = 0; i < n; ++i) dst[i] = curve.LnExposure(int(i % size_t(channels)), src[i]);
  return out;
}

// "9x6" -> (9, 6), as igi-calib intrinsics reads --board.
void ParseBoard(const std::string& text, calib::IntrinsicsOptions* options) {
  const size_t x = text.find_first_of("xX");
  try {
    size_t used_cols = 0, used_rows = 0;
    if (x == std::string::npos) throw std::invalid_argument(text);
    options->board_cols = std::stoi(text.substr(0, x), &used_cols);
    options->board_rows = std::stoi(text.substr(x + 1), &used_rows);
    if (used_cols != x || used_rows != text.size() - x - 1) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw InputError(DescribeProblem("", "--board", text, "must be COLSxROWS, e.g. 9x6"));
  }
}

// camera.json's text for `camera`, as WriteCameraFile writes it: the library builds the document
// only while writing, so it is written into a private temporary folder and read back.
std::string CameraJsonText(const calib::CameraFile& camera) {
  std::string pattern = (fs::temp_directory_path() / "igi-camera-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    throw Error(DescribeProblem(pattern, "", "", "cannot create a temporary folder"));
  }
  const fs::path dir = pattern;
  std::ostringstream text;
  std::error_code ignored;
  try {
    calib::WriteCameraFile(dir / "camera.json", camera);
    text << std::ifstream(dir / "camera.json").rdbuf();
  } catch (...) {
    fs::remove_all(dir, ignored);
    throw;
  }
  fs::remove_all(dir, ignored);
  return text.str();
}

// igi-hdr's options, under its flags' names.
struct HdrArgs {
  hdr::HdrInputOptions input;         // --exposures, --exposure-file, --response, --linear, raw
  const PyResponse* curve = nullptr;  // a ResponseCurve object in place of --response
  hdr::MergeOptions merge;            // --weighting, --shot-noise, --read-noise, --saturated
  hdr::HdrStreamOptions stream;       // --band-rows
  std::optional<double> black;        // --black; absent = 0.02, raw input 0
  std::string weighting, raw_white_balance, raw_color;  // the choice flags as given
  std::string camera, colour, out, mask_out;
  bool align = false;
  bool whole_images = false;
};

// The raw decode choices, InputError "--FLAG: VALUE: RULE" for each bad one (as igi-hdr).
hdr::RawDecodeOptions ParseRawChoices(const std::string& white_balance, const std::string& color,
                                      hdr::RawDecodeOptions raw) {
  ProblemList problems;
  if (const auto wb = hdr::RawWhiteBalanceFromName(white_balance)) {
    raw.white_balance = *wb;
  } else {
    problems.Add("--raw-white-balance", "", white_balance, "must be camera or none");
  }
  if (const auto c = hdr::RawColorFromName(color)) {
    raw.color = *c;
  } else {
    problems.Add("--raw-color", "", color, "must be srgb or raw");
  }
  problems.ThrowIfAny();
  raw.Validate();
  return raw;
}

// igi-hdr's checks of its options, before anything is read.
void ValidateHdr(HdrArgs& a) {
  const auto weighting = hdr::MergeWeightingFromName(a.weighting);
  if (!weighting) {
    throw InputError(DescribeProblem("--weighting", "", a.weighting, "must be noise or hat"));
  }
  a.merge.weighting = *weighting;
  if (a.black) a.merge.black = *a.black;
  a.merge.Validate();
  a.input.raw = ParseRawChoices(a.raw_white_balance, a.raw_color, a.input.raw);
  a.stream.Validate();
  Exposures(a.input.exposures.list, a.input.exposures.file.string());
  if (!a.out.empty() && ToLower(fs::path(a.out).extension().string()) != ".exr") {
    throw InputError(DescribeProblem(a.out, "--out", fs::path(a.out).extension().string(),
                                     "radiance maps are written as OpenEXR (.exr)"));
  }
}

void CheckResponseChannels(const calib::ResponseCurve& response, const std::string& source,
                           int channels) {
  if (response.num_channels() != 1 && response.num_channels() != channels) {
    throw InputError(DescribeProblem(
        source, "channels", std::to_string(response.num_channels()),
        "must be 1 or the images' channel count (" + std::to_string(channels) + ")"));
  }
}

// A ResponseCurve object given in place of --response replaces the response of non-raw input
// (raw input is linear and takes none, as in igi-hdr).
void UseCurve(const PyResponse& curve, int channels, hdr::HdrInput* input) {
  if (input->raw) return;
  const std::string source =
      curve.source.empty() ? "recovered (" + curve.curve.method + ")" : curve.source;
  CheckResponseChannels(curve.curve, source, channels);
  input->response = curve.curve;
  input->response_source = source;
}

// The bracket's files loaded as igi-hdr loads them; with `headers_only` the pixels of 8/16-bit
// frames with a known response are left to a streamed merge.
hdr::HdrInput LoadFiles(const std::vector<fs::path>& paths, const HdrArgs& a, bool headers_only) {
  hdr::HdrInputOptions options = a.input;
  options.headers_only = headers_only;
  // A response object is known: no response.json to read, none to recover.
  if (a.curve) options.linear = true;
  hdr::HdrInput input = hdr::LoadHdrInput(paths, options);
  if (a.curve) {
    const int channels =
        input.headers_only ? ReadImageInfo(paths.front()).channels : input.images.front().channels;
    UseCurve(*a.curve, channels, &input);
  }
  return input;
}

// A bracket given as arrays, its response chosen as LoadHdrInput chooses it.
hdr::HdrInput InputFromBracket(calib::Bracket bracket, const HdrArgs& a) {
  hdr::HdrInput input;
  input.names = bracket.names;
  input.exposures_s = bracket.exposures_s;
  input.bits = bracket.bits_per_sample;
  const int channels = bracket.channels();
  if (a.curve) {
    UseCurve(*a.curve, channels, &input);
  } else if (!a.input.response.empty()) {
    input.response = calib::ReadResponseJson(a.input.response);
    input.response_source = a.input.response.string();
    CheckResponseChannels(input.response, input.response_source, channels);
  } else if (a.input.linear) {
    input.response = calib::LinearResponse(bracket.levels(), channels);
    input.response_source = "linear";
  } else {
    input.response = calib::RecoverResponse(bracket, {}).curve;
    input.response_source = "recovered (debevec)";
  }
  input.images = std::move(bracket.images);
  return input;
}

void LogShifts(const hdr::HdrInput& input, const std::vector<hdr::PixelShift>& shifts) {
  for (size_t j = 0; j < shifts.size(); ++j) {
    if (shifts[j].dx == 0 && shifts[j].dy == 0) continue;
    spdlog::info("{}: aligned by ({}, {}) px", input.names[j], shifts[j].dx, shifts[j].dy);
  }
}

struct Merged {
  Image radiance;  // linear radiance, the response's units
  Image mask;      // 1 = good, 0 = saturated or black in every exposure
  int64_t saturated_pixels = 0;
  int64_t black_pixels = 0;
  std::string response_source;
};

ImageMetadata RadianceMetadata(const hdr::HdrInput& input, const hdr::MergeOptions& merge) {
  ImageMetadata metadata;
  metadata["igi:response"] = input.response_source;
  metadata["igi:weighting"] = std::string(hdr::MergeWeightingName(merge.weighting));
  return metadata;
}

// igi-hdr's merge of whole images: aligned, merged, corrected, written when asked.
Merged MergeWhole(hdr::HdrInput& input, const hdr::MergeOptions& merge, const HdrArgs& a,
                  const hdr::RadianceCorrection& correction, const fs::path& mask) {
  if (a.align) {
    const auto shifts =
        hdr::ComputeMtbShifts(input.images, hdr::MedianExposureFrame(input.exposures_s));
    LogShifts(input, shifts);
    for (size_t j = 0; j < shifts.size(); ++j) {
      if (shifts[j].dx != 0 || shifts[j].dy != 0) {
        input.images[j] = hdr::ShiftImage(input.images[j], shifts[j]);
      }
    }
  }
  hdr::MergeResult result =
      hdr::MergeBracket(input.images, input.exposures_s, input.response, merge);
  Merged m{std::move(result.radiance), std::move(result.mask), result.saturated_pixels,
           result.black_pixels, input.response_source};
  correction.Apply(m.radiance.pixels.data(), 0, m.radiance.height, m.radiance.width,
                   m.radiance.channels);
  for (const auto& [key, value] : RadianceMetadata(input, merge)) m.radiance.metadata[key] = value;
  if (!a.out.empty()) WriteImage(a.out, m.radiance);
  if (!mask.empty()) {
    WriteImageOptions mask_options;
    mask_options.type = PixelType::kUInt8;
    WriteImage(mask, m.mask, mask_options);
  }
  return m;
}

// igi-hdr's merge band by band into OUT and its mask, which are then read back.
Merged MergeStreamed(const hdr::HdrInput& input, const hdr::MergeOptions& merge, const HdrArgs& a,
                     const hdr::RadianceCorrection& correction, const fs::path& mask) {
  std::vector<hdr::PixelShift> shifts;
  if (a.align) {
    shifts = hdr::ComputeMtbShifts(hdr::ReadGreyFrames(input.paths, a.stream),
                                   hdr::MedianExposureFrame(input.exposures_s));
    LogShifts(input, shifts);
  }
  hdr::StreamOutputs outputs;
  outputs.radiance = a.out;
  outputs.radiance_metadata = RadianceMetadata(input, merge);
  outputs.mask = mask;
  outputs.correction = correction;
  const hdr::StreamMergeSummary summary = hdr::MergeBracketStreamed(
      input.paths, input.exposures_s, shifts, input.response, merge, a.stream, outputs);
  Merged m{ReadImage(a.out), ReadImage(mask, 1), summary.saturated_pixels, summary.black_pixels,
           input.response_source};
  m.radiance.metadata = outputs.radiance_metadata;
  m.mask.metadata.clear();
  return m;
}

// igi-hdr's Run for one bracket (files, or arrays already in `arrays`). Needs no GIL.
Merged RunMerge(const std::vector<fs::path>& paths, std::optional<calib::Bracket>& arrays,
                HdrArgs& a) {
  // The corrections first: a colour matrix fitted to raw camera RGB sets how raw files decode.
  const hdr::RadianceCorrection correction(a.camera, a.colour);
  a.input.raw = correction.RawInputOptions(a.input.raw);
  const bool stream = !a.out.empty() && !a.whole_images;
  hdr::HdrInput input =
      arrays ? InputFromBracket(std::move(*arrays), a) : LoadFiles(paths, a, stream);
  const std::string first = input.names.front();
  if (input.headers_only) {
    const ImageInfo info = ReadImageInfo(input.paths.front());
    correction.Check(first, info.width, info.height, info.channels, input.raw);
  } else {
    const Image& image = input.images.front();
    correction.Check(first, image.width, image.height, image.channels, input.raw);
  }
  hdr::MergeOptions merge = a.merge;
  merge.bits = input.bits;
  // Raw data has its black level subtracted: only a zero value carries no signal.
  if (input.raw && !a.black) merge.black = 0.0;
  fs::path mask = a.mask_out;
  if (mask.empty() && !a.out.empty()) {
    mask = fs::path(a.out).replace_filename(fs::path(a.out).stem().string() + "_mask.png");
  }
  return input.headers_only ? MergeStreamed(input, merge, a, correction, mask)
                            : MergeWhole(input, merge, a, correction, mask);
}

void AddResponseCurve(py::module_& m) {
  py::class_<PyResponse>(m, "_ResponseCurve")
      .def_static(
          "load",
          [](const fs::path& path) {
            py::gil_scoped_release release;
            return ReadResponse(ReadJsonFile(path), path.string());
          },
          py::arg("path"), "Reads response.json (strict: InputError naming the file and key).")
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source) {
            PyResponse r = ReadResponse(ParseJson(text, source), source);
            r.source.clear();
            return r;
          },
          py::arg("text"), py::arg("source"), "A response.json document held as text.")
      .def(
          "document",
          [](const PyResponse& r) { return calib::ResponseToJson(r.curve, r.info).dump(); },
          "response.json's text as igi-calib writes it (g rounded to 1e-7).")
      .def(
          "save",
          [](const PyResponse& r, const fs::path& path, const fs::path& plot) {
            py::gil_scoped_release release;
            calib::WriteResponseJson(path, r.curve, r.info);
            if (!plot.empty()) calib::WriteResponsePlot(plot, r.curve);
          },
          py::arg("path"), py::arg("plot"), "Writes response.json (and the SVG plot) atomically.")
      .def(
          "ln_exposure",
          [](const PyResponse& r, const py::array& values) { return LnExposures(r.curve, values); },
          py::arg("values"), "g(v): ln exposure of normalised values (..., C).")
      .def_property_readonly("method", [](const PyResponse& r) { return r.curve.method; })
      .def_property_readonly("levels", [](const PyResponse& r) { return r.curve.levels; })
      .def_property_readonly("channels", [](const PyResponse& r) { return r.curve.channels; })
      .def_property_readonly("source", [](const PyResponse& r) { return r.source; })
      .def_property_readonly("g", [](const PyResponse& r) {
        py::array_t<double> g({py::ssize_t(r.curve.num_channels()), py::ssize_t(r.curve.levels)});
        for (size_t c = 0; c < r.curve.g.size(); ++c) {
          std::copy(r.curve.g[c].begin(), r.curve.g[c].end(),
                    g.mutable_data() + c * size_t(r.curve.levels));
        }
        return g;
      });
}

void AddCameraFile(py::module_& m) {
  py::class_<calib::CameraFile>(m, "_CameraFile")
      .def_static(
          "load",
          [](const fs::path& path) {
            py::gil_scoped_release release;
            return calib::ReadCameraFile(path);
          },
          py::arg("path"), "Reads and validates camera.json.")
      .def(
          "document",
          [](const calib::CameraFile& camera) {
            py::gil_scoped_release release;
            return CameraJsonText(camera);
          },
          "camera.json's text as igi-calib writes it.")
      .def(
          "save",
          [](const calib::CameraFile& camera, const fs::path& path) {
            py::gil_scoped_release release;
            calib::WriteCameraFile(path, camera);
          },
          py::arg("path"), "Validates and writes camera.json atomically.");
}

}  // namespace

void AddCalibration(py::module_& m) {
  AddResponseCurve(m);
  AddCameraFile(m);
  m.def(
      "_response",
      [](const py::list& images, const std::vector<py::dict>& metadata, int bits,
         const std::string& exposures, const std::string& exposure_file, const std::string& method,
         const std::string& lambda, const std::string& black, int samples, int levels,
         double saturated, int max_iterations, double robertson_smoothing) {
        calib::ResponseOptions options;
        options.samples = samples;
        options.levels = levels;
        options.saturated = saturated;
        options.max_iterations = max_iterations;
        options.robertson_smoothing = robertson_smoothing;
        options = ParseResponseOptions(method, lambda, black, options);
        const calib::ExposureSource source = Exposures(exposures, exposure_file);
        const ImageList list = SplitImages(images);
        const calib::Bracket bracket = LoadResponseBracket(list, metadata, bits, source);
        std::vector<std::string> names;
        for (const fs::path& path : list.paths) names.push_back(path.string());
        if (list.paths.empty()) names = bracket.names;
        py::gil_scoped_release release;
        const calib::ResponseSummary summary = calib::RecoverResponse(bracket, options);
        return PyResponse{summary.curve, ResponseInfo(names, bracket, summary, options), ""};
      },
      py::arg("images"), py::arg("metadata"), py::arg("bits"), py::arg("exposures"),
      py::arg("exposure_file"), py::arg("method"), py::arg("lambda_"), py::arg("black"),
      py::arg("samples"), py::arg("levels"), py::arg("saturated"), py::arg("max_iterations"),
      py::arg("robertson_smoothing"), "igi-calib response: the curve and response.json's info.");
  m.def(
      "_intrinsics",
      [](const std::vector<fs::path>& images, const std::string& board,
         const std::string& board_type, const std::string& dictionary, double marker, double square,
         const std::string& model, bool fix_aspect_ratio, bool zero_tangent_dist,
         bool fix_principal_point, int subpix_window) {
        calib::IntrinsicsOptions options;
        ParseBoard(board, &options);
        const auto type = calib::BoardTypeFromName(board_type);
        if (!type) {
          throw InputError(
              DescribeProblem("", "--board-type", board_type, "must be chessboard or charuco"));
        }
        const auto camera_model = calib::ColmapCameraModelFromName(model);
        if (!camera_model) {
          throw InputError(
              DescribeProblem("", "--model", model, "must be PINHOLE, OPENCV or FULL_OPENCV"));
        }
        options.board_type = *type;
        options.model = *camera_model;
        options.dictionary = dictionary;
        options.marker_m = marker;
        options.square_m = square;
        options.fix_aspect_ratio = fix_aspect_ratio;
        options.zero_tangent_dist = zero_tangent_dist;
        options.fix_principal_point = fix_principal_point;
        options.subpix_window = subpix_window;
        options.Validate();
        py::gil_scoped_release release;
        return calib::CalibrateIntrinsics(images, options).camera;
      },
      py::arg("images"), py::arg("board"), py::arg("board_type"), py::arg("dictionary"),
      py::arg("marker"), py::arg("square"), py::arg("model"), py::arg("fix_aspect_ratio"),
      py::arg("zero_tangent_dist"), py::arg("fix_principal_point"), py::arg("subpix_window"),
      "igi-calib intrinsics: the camera.json content.");
  m.def(
      "_merge",
      [](const py::list& images, const std::vector<py::dict>& metadata, int bits,
         const std::string& response, const PyResponse* curve, const std::string& exposures,
         const std::string& exposure_file, bool linear, const std::string& weighting,
         double shot_noise, double read_noise, std::optional<double> black, double saturated,
         bool align, const std::string& camera, const std::string& colour,
         const std::string& raw_white_balance, const std::string& raw_color, bool half_size,
         int band_rows, bool whole_images, const std::string& out, const std::string& mask_out,
         int threads) {
        HdrArgs a;
        a.input.exposures = {exposures, exposure_file};
        a.input.response = response;
        a.input.linear = linear;
        a.input.raw.half_size = half_size;
        a.curve = curve;
        a.merge.shot_noise = shot_noise;
        a.merge.read_noise = read_noise;
        a.merge.saturated = saturated;
        a.merge.num_threads = threads;
        a.stream.band_rows = band_rows;
        a.black = black;
        a.weighting = weighting;
        a.raw_white_balance = raw_white_balance;
        a.raw_color = raw_color;
        a.camera = camera;
        a.colour = colour;
        a.out = out;
        a.mask_out = mask_out;
        a.align = align;
        a.whole_images = whole_images;
        ValidateHdr(a);
        const ImageList list = SplitImages(images);
        std::optional<calib::Bracket> arrays;
        if (!list.arrays.empty()) {
          arrays = BracketFromArrays(list.arrays, metadata, bits, a.input.exposures);
        }
        Merged merged;
        {
          py::gil_scoped_release release;
          merged = RunMerge(list.paths, arrays, a);
        }
        py::dict counts;
        counts["saturated_pixels"] = merged.saturated_pixels;
        counts["black_pixels"] = merged.black_pixels;
        counts["response"] = merged.response_source;
        py::dict radiance_metadata = MetadataToDict(merged.radiance.metadata);
        return py::make_tuple(PixelsToArray(std::move(merged.radiance)), radiance_metadata,
                              PixelsToArray(std::move(merged.mask)), counts);
      },
      py::arg("images"), py::arg("metadata"), py::arg("bits"), py::arg("response"),
      py::arg("curve").none(true), py::arg("exposures"), py::arg("exposure_file"),
      py::arg("linear"), py::arg("weighting"), py::arg("shot_noise"), py::arg("read_noise"),
      py::arg("black").none(true), py::arg("saturated"), py::arg("align"), py::arg("camera"),
      py::arg("colour"), py::arg("raw_white_balance"), py::arg("raw_color"), py::arg("half_size"),
      py::arg("band_rows"), py::arg("whole_images"), py::arg("out"), py::arg("mask_out"),
      py::arg("threads"),
      "igi-hdr: (radiance, its metadata, mask, counts); writes OUT and its mask when OUT is "
      "given.");
  m.def(
      "_decode_raw",
      [](const fs::path& path, const std::string& raw_white_balance, const std::string& raw_color,
         bool half_size) {
        hdr::RawDecodeOptions options;
        options.half_size = half_size;
        options = ParseRawChoices(raw_white_balance, raw_color, options);
        hdr::RawImage raw;
        {
          py::gil_scoped_release release;
          raw = hdr::DecodeRaw(path, options);
        }
        py::dict info;
        info["camera"] = raw.camera;
        info["exposure_s"] = raw.exposure_s;
        info["iso"] = raw.iso;
        info["aperture"] = raw.aperture;
        info["black_level"] = raw.black_level;
        info["white_level"] = raw.white_level;
        info["raw_bits"] = raw.raw_bits;
        py::dict metadata = MetadataToDict(raw.image.metadata);
        return py::make_tuple(PixelsToArray(std::move(raw.image)), metadata, info);
      },
      py::arg("path"), py::arg("raw_white_balance"), py::arg("raw_color"), py::arg("half_size"),
      "hdr::DecodeRaw: (linear RGB, 1 = white level; its metadata; the decode's levels).");
  m.def(
      "_calib_defaults",
      []() {
        const calib::ResponseOptions response;
        const calib::IntrinsicsOptions intrinsics;
        const hdr::MergeOptions merge;
        const hdr::HdrStreamOptions stream;
        py::dict d;
        d["response"] =
            py::dict(py::arg("samples") = response.samples, py::arg("levels") = response.levels,
                     py::arg("saturated") = response.saturated,
                     py::arg("max_iterations") = response.max_iterations,
                     py::arg("robertson_smoothing") = response.robertson_smoothing);
        d["intrinsics"] = py::dict(py::arg("dictionary") = intrinsics.dictionary,
                                   py::arg("marker") = intrinsics.marker_m,
                                   py::arg("subpix_window") = intrinsics.subpix_window);
        d["merge"] = py::dict(
            py::arg("shot_noise") = merge.shot_noise, py::arg("read_noise") = merge.read_noise,
            py::arg("saturated") = merge.saturated, py::arg("band_rows") = stream.band_rows);
        return d;
      },
      "The libraries' option defaults, which igi.calib's and igi.hdr's keywords repeat.");
}

}  // namespace igi::python
