// Calibration and HDR for igi.calib and igi.hdr: igi-calib response and intrinsics, igi-hdr's merge
// and its linear raw decode. Each takes its executable's flags, parsed, checked and run by the same
// library code as the executable (calib/calib_flags.h, hdr/hdr_flags.h), so a bad value raises the
// line the executable prints and a merge equals igi-hdr's. Files are
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
#include "calib/calib_flags.h"
#include "calib/camera_file.h"
#include "calib/intrinsics.h"
#include "calib/response_curve.h"
#include "calib/response_plot.h"
#include "calib/response_recovery.h"
#include "hdr/hdr_flags.h"
#include "hdr/raw_decode.h"
#include "python/src/bindings.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

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
         const std::vector<std::string>& args) {
        CLI::App app;
        calib::ResponseFlags flags;
        calib::AddResponseFlags(app, &flags);
        ParseArguments(app, "igi-calib response", args);
        const calib::ResponseOptions options = calib::FinishResponseFlags(flags);
        const ImageList list = SplitImages(images);
        const calib::Bracket bracket = LoadResponseBracket(list, metadata, bits, flags.exposures);
        std::vector<std::string> names;
        for (const fs::path& path : list.paths) names.push_back(path.string());
        if (list.paths.empty()) names = bracket.names;
        py::gil_scoped_release release;
        const calib::ResponseSummary summary = calib::RecoverResponse(bracket, options);
        return PyResponse{summary.curve, calib::ResponseInfo(names, bracket, summary, options),
                          ""};
      },
      py::arg("images"), py::arg("metadata"), py::arg("bits"), py::arg("args"),
      "igi-calib response with its flags: the curve and response.json's info.");
  m.def(
      "_intrinsics",
      [](const std::vector<fs::path>& images, const std::vector<std::string>& args) {
        CLI::App app;
        calib::IntrinsicsFlags flags;
        calib::AddIntrinsicsFlags(app, &flags);
        ParseArguments(app, "igi-calib intrinsics", args);
        const calib::IntrinsicsOptions options = calib::FinishIntrinsicsFlags(flags);
        py::gil_scoped_release release;
        return calib::CalibrateIntrinsics(images, options).camera;
      },
      py::arg("images"), py::arg("args"),
      "igi-calib intrinsics with its flags: the camera.json content.");
  m.def(
      "_merge",
      [](const py::list& images, const std::vector<py::dict>& metadata, int bits,
         const PyResponse* curve, const std::vector<std::string>& args, int threads) {
        CLI::App app;
        hdr::HdrFlags flags;
        hdr::AddHdrFlags(app, &flags);
        ParseArguments(app, "igi-hdr", args);
        flags.merge.num_threads = threads;
        hdr::FinishHdrFlags(&flags);
        if (curve) {
          flags.input.curve = curve->curve;
          flags.input.curve_source =
              curve->source.empty() ? "recovered (" + curve->curve.method + ")" : curve->source;
        }
        const ImageList list = SplitImages(images);
        std::optional<calib::Bracket> arrays;
        if (!list.arrays.empty()) {
          arrays = BracketFromArrays(list.arrays, metadata, bits, flags.input.exposures);
        }
        const fs::path out = flags.out;
        fs::path mask = flags.mask_out;
        if (mask.empty() && !out.empty()) mask = hdr::DefaultMaskPath(out);
        hdr::HdrInput input;
        hdr::MergedBracket merged;
        {
          py::gil_scoped_release release;
          // The corrections first: a colour matrix fitted to raw camera RGB sets how raw files
          // decode.
          const hdr::RadianceCorrection correction(flags.camera, flags.colour);
          flags.input.raw = correction.RawInputOptions(flags.input.raw);
          if (arrays) {
            input = hdr::HdrInputFromBracket(std::move(*arrays), flags.input);
          } else {
            hdr::HdrInputOptions options = flags.input;
            options.headers_only = !out.empty() && !flags.whole_images;
            input = hdr::LoadHdrInput(list.paths, options);
          }
          hdr::CheckCorrection(input, correction);
          merged = hdr::MergeHdrInput(input, flags, correction, out, mask);
          if (!merged.radiance) {  // merged band by band into the files
            merged.radiance = ReadImage(out);
            merged.radiance->metadata = merged.radiance_metadata;
            merged.mask = ReadImage(mask, 1);
            merged.mask->metadata.clear();
          }
        }
        for (size_t j = 0; j < merged.shifts.size(); ++j) {
          if (merged.shifts[j].dx == 0 && merged.shifts[j].dy == 0) continue;
          spdlog::info("{}: aligned by ({}, {}) px", input.names[j], merged.shifts[j].dx,
                       merged.shifts[j].dy);
        }
        py::dict counts;
        counts["saturated_pixels"] = merged.saturated_pixels;
        counts["black_pixels"] = merged.black_pixels;
        counts["response"] = input.response_source;
        py::dict radiance_metadata = MetadataToDict(merged.radiance->metadata);
        return py::make_tuple(PixelsToArray(std::move(*merged.radiance)), radiance_metadata,
                              PixelsToArray(std::move(*merged.mask)), counts);
      },
      py::arg("images"), py::arg("metadata"), py::arg("bits"), py::arg("curve").none(true),
      py::arg("args"), py::arg("threads"),
      "igi-hdr with its flags: (radiance, its metadata, mask, counts); writes OUT and its mask "
      "when OUT is given.");
  m.def(
      "_decode_raw",
      [](const fs::path& path, const std::string& raw_white_balance, const std::string& raw_color,
         bool half_size) {
        hdr::RawDecodeOptions options;
        options.half_size = half_size;
        options = hdr::ParseRawChoices(raw_white_balance, raw_color, options);
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
