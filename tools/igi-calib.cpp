// igi-calib: camera calibration (its files: docs/file-formats.md). Subcommands, one per
// calibration:
//   igi-calib response IMAGES… (--exposures LIST | --exposure-file FILE | EXIF) --out response.json
//             [--method debevec|robertson] [--lambda auto|L] [--samples N] [--levels N]
//             [--black auto|B] [--plot FILE]
//   igi-calib intrinsics IMAGES… --board COLSxROWS --square METRES --out camera.json
//             [--board-type charuco --dictionary DICT_4X4_50 --marker METRES]
//             [--model PINHOLE|OPENCV|FULL_OPENCV] [--fix-aspect-ratio] [--zero-tangent-dist]
//             [--fix-principal-point]
//     Exit 3 (camera.json written) when the board was not found in some views; they are listed
//     in camera.json "rejected_views". Exit 1 when fewer than 3 views show the board.
//   igi-calib vignetting FLAT_FIELDS… --out camera.json [--camera camera.json]
//             [--response response.json | --linear]
//   igi-calib vignetting --scene scene.json --out camera.json [--camera camera.json]
//     The fall-off 1 + k1 r² + k2 r⁴ (calib/vignetting.h) from flat fields, or from the overlap of
//     a registered scene's photos; written into camera.json beside the intrinsics of --camera.
//   igi-calib colour IMAGE --chart REF.cie --out colour.json [--response response.json]
//             [--corners x0,y0,x1,y1,x2,y2,x3,y3] [--half-size]
//     The 3x3 camera RGB -> linear sRGB matrix from a ColorChecker 24 (calib/colour_chart.h);
//     raw photos are decoded linearly in the camera's own RGB. Exit 2 when no chart is found.
//   igi-calib lights --scene scene.json --sphere REGION|x,y,z,r [--sphere …] --out lights.json
//             [--photos LIST] [--target REGION --reflectance R[,G,B]]
//             [--type auto|point|directional] [--level F] [--saturated V]
//     Each lighting's light from the highlights on glossy spheres (calib/light_calibration.h):
//     a direction from one view, a position triangulated from several views or spheres; its
//     strength from a Lambertian target. Exit 2 (nothing written) when a photo shows no sphere.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "calib/bracket.h"
#include "calib/calib_flags.h"
#include "calib/colour_chart.h"
#include "calib/intrinsics.h"
#include "calib/light_calibration.h"
#include "calib/response_curve.h"
#include "calib/response_plot.h"
#include "calib/response_recovery.h"
#include "calib/vignetting.h"
#include "hdr/flat_field.h"
#include "hdr/raw_decode.h"
#include "recon/scene.h"
#include "solver/inverse/vignetting_overlap.h"
#include "solver/render/ray_scene.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace {

struct ResponseCommand {
  std::vector<std::string> images;
  std::string out;
  std::string plot;  // empty = OUT with the extension .svg
  bool no_plot = false;
  igi::calib::ResponseFlags flags;
};

CLI::App* AddResponseCommand(CLI::App& app, ResponseCommand* cmd) {
  CLI::App* sub =
      app.add_subcommand("response", "Recover the camera response curve from an exposure bracket");
  sub->add_option("images", cmd->images, "8- or 16-bit images of one bracket")->required();
  sub->add_option("--out", cmd->out, "Output response.json")->required();
  sub->add_option("--plot", cmd->plot, "Plot of the curves (SVG); default OUT with .svg");
  sub->add_flag("--no-plot", cmd->no_plot, "Do not write the plot");
  igi::calib::AddResponseFlags(*sub, &cmd->flags);
  return sub;
}

int RunResponse(const ResponseCommand& cmd) {
  const igi::calib::ResponseOptions options = igi::calib::FinishResponseFlags(cmd.flags);
  std::vector<std::filesystem::path> paths(cmd.images.begin(), cmd.images.end());
  const igi::calib::Bracket bracket = igi::calib::LoadBracket(paths, cmd.flags.exposures);
  const igi::calib::ResponseSummary summary = igi::calib::RecoverResponse(bracket, options);
  igi::calib::WriteResponseJson(cmd.out, summary.curve,
                                igi::calib::ResponseInfo(cmd.images, bracket, summary, options));
  std::string plot;
  if (!cmd.no_plot) {
    plot = cmd.plot.empty() ? std::filesystem::path(cmd.out).replace_extension(".svg").string()
                            : cmd.plot;
    igi::calib::WriteResponsePlot(plot, summary.curve);
  }
  std::printf("%s: %s response, %d levels, %d channels, %d samples%s%s\n", cmd.out.c_str(),
              summary.curve.method.c_str(), summary.curve.levels, summary.curve.num_channels(),
              summary.samples, plot.empty() ? "" : ", plot ", plot.c_str());
  return 0;
}

struct IntrinsicsCommand {
  std::vector<std::string> images;
  std::string out;
  igi::calib::IntrinsicsFlags flags;
};

CLI::App* AddIntrinsicsCommand(CLI::App& app, IntrinsicsCommand* cmd) {
  CLI::App* sub = app.add_subcommand(
      "intrinsics", "Calibrate focal length, principal point and distortion from chessboard views");
  sub->add_option("images", cmd->images, "Views of a planar chessboard")->required();
  sub->add_option("--out", cmd->out, "Output camera.json")->required();
  igi::calib::AddIntrinsicsFlags(*sub, &cmd->flags);
  return sub;
}

int RunIntrinsics(const IntrinsicsCommand& cmd) {
  const igi::calib::IntrinsicsOptions options = igi::calib::FinishIntrinsicsFlags(cmd.flags);
  std::vector<std::filesystem::path> paths(cmd.images.begin(), cmd.images.end());
  const igi::calib::IntrinsicsSummary summary = igi::calib::CalibrateIntrinsics(paths, options);
  const igi::calib::CameraFile& camera = summary.camera;
  igi::calib::WriteCameraFile(cmd.out, camera);
  std::printf("%s: %s %dx%d, fx %.3f fy %.3f cx %.3f cy %.3f, RMS %.4f px over %zu views\n",
              cmd.out.c_str(), std::string(igi::calib::ColmapCameraModelName(camera.model)).c_str(),
              camera.width, camera.height, camera.params[0], camera.params[1], camera.params[2],
              camera.params[3], camera.rms_px, camera.views.size());
  if (camera.rejected_views.empty()) return 0;
  std::vector<std::string> problems;
  for (const auto& view : camera.rejected_views) {
    problems.push_back(igi::DescribeProblem(view.file, "", "", view.reason + "; view rejected"));
  }
  throw igi::PartialError(problems);
}

struct VignettingCommand {
  std::vector<std::string> images;
  std::string scene;
  std::string camera;  // camera.json whose intrinsics are kept; empty = none
  std::string out;
  std::string response;
  bool linear = false;
  igi::solver::OverlapOptions overlap;
  bool free_exposures = false;
};

CLI::App* AddVignettingCommand(CLI::App& app, VignettingCommand* cmd) {
  CLI::App* sub = app.add_subcommand(
      "vignetting",
      "Measure the fall-off 1 + k1 r^2 + k2 r^4 from flat fields or from a scene's photos");
  auto* images = sub->add_option("images", cmd->images,
                                 "Flat fields: a lit diffuse target filling the frame, moved "
                                 "between photos (raw, 8/16-bit with a response, or float)");
  sub->add_option("--scene", cmd->scene,
                  "Measure from the overlap of this registered scene's photos instead")
      ->excludes(images);
  sub->add_option("--camera", cmd->camera,
                  "camera.json whose intrinsics (principal point) are kept in the output");
  sub->add_option("--out", cmd->out, "Output camera.json")->required();
  auto* response =
      sub->add_option("--response", cmd->response, "response.json of 8/16-bit flat fields");
  sub->add_flag("--linear", cmd->linear, "8/16-bit flat fields are linear")->excludes(response);
  sub->add_option("--samples", cmd->overlap.samples_per_photo,
                  "--scene: pixels traced per photo (a grid)")
      ->check(CLI::Range(64, 1 << 24))
      ->capture_default_str();
  sub->add_flag("--free-exposures", cmd->free_exposures,
                "--scene: fit each photo's exposure too (photos not of one radiance scale)");
  return sub;
}

int RunVignetting(const VignettingCommand& cmd) {
  if (cmd.images.empty() == cmd.scene.empty()) {
    throw igi::InputError("igi-calib vignetting: give either FLAT_FIELDS or --scene");
  }
  igi::calib::CameraFile camera;
  if (!cmd.camera.empty()) camera = igi::calib::ReadCameraFile(cmd.camera);
  // The photos' size becomes camera.json's; with --camera it must be the size stated there.
  const auto set_size = [&](const std::string& what, int width, int height) {
    if (!cmd.camera.empty() && (width != camera.width || height != camera.height)) {
      throw igi::InputError(igi::DescribeProblem(
          what, "", std::to_string(width) + "x" + std::to_string(height),
          "must be the size in " + cmd.camera + " (" + std::to_string(camera.width) + "x" +
              std::to_string(camera.height) + ")"));
    }
    camera.width = width;
    camera.height = height;
  };
  igi::calib::CameraVignetting result;
  if (!cmd.images.empty()) {
    igi::hdr::FlatFieldReadOptions read;
    if (!cmd.response.empty()) read.response = igi::calib::ReadResponseJson(cmd.response);
    if (cmd.linear) read.response = igi::calib::LinearResponse(65536, 1);
    std::vector<igi::calib::FlatField> fields;
    igi::ProblemList problems;
    for (const std::string& image : cmd.images) {
      try {
        fields.push_back(igi::hdr::ReadFlatField(image, read));
      } catch (const igi::InputError& e) {
        problems.Append(e);
      }
    }
    problems.ThrowIfAny();
    set_size(fields[0].name, fields[0].width, fields[0].height);
    const igi::calib::VignettingFit fit =
        igi::calib::FitFlatFields(fields, camera.principal_x_px(), camera.principal_y_px());
    result = {fit.vignetting, "flat_field", fit.rms_ln, fit.samples, fit.photos};
  } else {
    const igi::recon::Scene scene = igi::recon::LoadScene(cmd.scene);
    if (scene.photos.empty()) {
      throw igi::InputError(
          igi::DescribeProblem(cmd.scene, "photos", "none", "the overlap of photos needs photos"));
    }
    const igi::recon::Camera& first = scene.cameras[size_t(scene.photos[0].camera)];
    set_size(cmd.scene + ": cameras." + first.name, first.width, first.height);
    const igi::solver::OverlapPairs pairs = igi::solver::CollectOverlapPairs(scene, cmd.overlap);
    const igi::calib::VignettingFit fit =
        igi::calib::FitOverlap(pairs.pairs, int(scene.photos.size()), cmd.free_exposures);
    result = {fit.vignetting, "overlap", fit.rms_ln, fit.samples, fit.photos};
  }
  camera.vignetting = result;
  igi::calib::WriteCameraFile(cmd.out, camera);
  std::printf("%s: vignetting k1 %.4f k2 %.4f (corner %.1f %%) from %d %s (%d %s), RMS %.2f %%\n",
              cmd.out.c_str(), result.model.k1, result.model.k2,
              100 * (result.model.Factor(1.0) - 1), result.photos,
              result.method == "overlap" ? "photos" : "flat fields", result.samples,
              result.method == "overlap" ? "pairs" : "blocks", 100 * result.rms_ln);
  return 0;
}

struct ColourCommand {
  std::string image;
  std::string chart;
  std::string out;
  std::string response;         // response.json that linearises an 8/16-bit photo
  std::vector<double> corners;  // the patch grid's corners by hand: x0,y0,…,x3,y3
  bool half_size = false;
  igi::calib::PatchSamplingOptions sampling;
};

CLI::App* AddColourCommand(CLI::App& app, ColourCommand* cmd) {
  CLI::App* sub = app.add_subcommand(
      "colour", "Fit the camera RGB -> linear sRGB matrix from a photographed ColorChecker");
  sub->add_option("image", cmd->image,
                  "Photo of a ColorChecker 24: raw (decoded linearly), float (linear) or 8/16-bit "
                  "with --response")
      ->required();
  sub->add_option("--chart", cmd->chart, "The chart's reference values (ArgyllCMS .cie)")
      ->required();
  sub->add_option("--out", cmd->out, "Output colour.json")->required();
  sub->add_option("--response", cmd->response, "response.json of an 8/16-bit photo");
  sub->add_option("--corners", cmd->corners,
                  "The patch grid's outer corners by hand when it is not found, pixels "
                  "x,y of dark skin, bluish green, black, white (8 numbers)")
      ->delimiter(',')
      ->expected(8);
  sub->add_flag("--half-size", cmd->half_size, "Raw: 2x2 binning instead of demosaicing");
  sub->add_option("--inner-fraction", cmd->sampling.inner_fraction,
                  "Side of the square sampled in each patch, fraction of the patch (default 0.5)");
  sub->add_option("--trim-fraction", cmd->sampling.trim_fraction,
                  "Fraction of values dropped at each end before averaging (default 0.1)");
  return sub;
}

int RunColour(const ColourCommand& cmd) {
  namespace calib = igi::calib;
  cmd.sampling.Validate();
  const calib::ChartReference reference = calib::ReadChartReference(cmd.chart);
  calib::ColourFile colour;
  calib::ColourFitOptions fit_options;
  igi::hdr::RawDecodeOptions decode;
  decode.half_size = cmd.half_size;
  const bool raw = igi::hdr::IsRawFile(cmd.image);
  igi::Image image;
  if (raw) {  // the camera's own RGB: no white balance, no colour matrix
    decode.white_balance = igi::hdr::RawWhiteBalance::kNone;
    decode.color = igi::hdr::RawColor::kRaw;
    image = igi::hdr::DecodeRaw(cmd.image, decode).image;
    fit_options.clip_level = 1;
    colour.input = calib::ColourInput::kCameraRaw;
  } else {
    const igi::PixelType type = igi::ReadImageInfo(cmd.image).type;
    const bool integer = type == igi::PixelType::kUInt8 || type == igi::PixelType::kUInt16;
    if (integer == cmd.response.empty()) {
      throw igi::InputError(igi::DescribeProblem(
          cmd.image, "--response", cmd.response.empty() ? "none" : cmd.response,
          "an 8/16-bit photo needs one to be linearised; a float photo takes none"));
    }
    image = igi::ReadImage(cmd.image, 3);
    if (integer) {
      const calib::ResponseCurve curve = calib::ReadResponseJson(cmd.response);
      for (size_t i = 0; i < image.pixels.size(); ++i) {
        const int c = std::min(int(i % 3), curve.num_channels() - 1);
        image.pixels[i] = float(std::exp(curve.LnExposure(c, image.pixels[i])));
      }
    }
    colour.input = calib::ColourInput::kLinear;
  }
  std::optional<calib::ChartLocation> location;
  if (!cmd.corners.empty()) {
    location.emplace();
    for (int i = 0; i < 4; ++i) location->corners[i] = {cmd.corners[2 * i], cmd.corners[2 * i + 1]};
  } else {
    location = calib::FindColourChart(image);
  }
  if (!location) {
    throw igi::InputError(igi::DescribeProblem(
        cmd.image, "", "", "no ColorChecker found (give the patch grid's corners with --corners)"));
  }
  try {
    const std::vector<Eigen::Vector3d> patches =
        calib::SamplePatches(image, *location, cmd.sampling);
    const calib::ColourFit fit = calib::FitColourMatrix(patches, reference, fit_options);
    colour.matrix = fit.matrix;
    colour.exposure_scale = fit.exposure_scale;
    colour.delta_e2000 = fit.delta_e2000;
    if (raw) {  // the raw decoder's own colour as shot, and with the chart's grey balance
      decode.white_balance = igi::hdr::RawWhiteBalance::kCamera;
      decode.color = igi::hdr::RawColor::kSrgb;
      const std::vector<Eigen::Vector3d> as_shot = calib::SamplePatches(
          igi::hdr::DecodeRaw(cmd.image, decode).image, *location, cmd.sampling);
      auto at_best_exposure = [&](std::vector<Eigen::Vector3d> srgb) {
        const double scale = calib::BestExposureScale(srgb, reference);
        for (Eigen::Vector3d& v : srgb) v *= scale;
        return calib::EvaluateDeltaE(srgb, reference);
      };
      colour.as_shot_delta_e2000 = at_best_exposure(as_shot);
      colour.camera_matrix_delta_e2000 =
          at_best_exposure(calib::GreyBalancedDecoderColour(patches, as_shot));
    }
  } catch (igi::Error& e) {
    throw e.AddContext("chart in " + cmd.image);
  }
  colour.chart = std::filesystem::path(cmd.chart).filename().string();
  colour.image = std::filesystem::path(cmd.image).filename().string();
  calib::WriteColourFile(cmd.out, colour);
  std::printf("%s: camera RGB -> linear sRGB, DeltaE2000 mean %.2f max %.2f over 24 patches",
              cmd.out.c_str(), colour.delta_e2000.mean, colour.delta_e2000.max);
  if (colour.camera_matrix_delta_e2000 && colour.as_shot_delta_e2000) {
    std::printf("; raw decoder's matrix, grey-balanced: mean %.2f max %.2f, as shot: mean %.2f",
                colour.camera_matrix_delta_e2000->mean, colour.camera_matrix_delta_e2000->max,
                colour.as_shot_delta_e2000->mean);
  }
  std::printf("\n");
  return 0;
}

struct LightsCommand {
  std::string scene;
  std::vector<std::string> spheres;  // each a region of the scene, or "x,y,z,radius" (metres)
  std::vector<std::string> photos;   // the photos that show the spheres; empty = all
  std::string target;                // region of a Lambertian target; empty = emission kept
  std::vector<double> reflectance;   // the target's reflectance: grey or RGB
  std::string type = "auto";         // checked against auto|point|directional when parsed
  std::string out;
  igi::calib::HighlightOptions highlight;
};

CLI::App* AddLightsCommand(CLI::App& app, LightsCommand* cmd) {
  CLI::App* sub = app.add_subcommand(
      "lights",
      "Light directions or positions from highlights on glossy spheres, intensities "
      "from a diffuse target of known reflectance");
  sub->add_option("--scene", cmd->scene, "scene.json with the cameras, photos and lightings")
      ->required();
  sub->add_option("--sphere", cmd->spheres,
                  "A glossy sphere: a region of the scene's mesh (a sphere is fitted to its "
                  "vertices) or x,y,z,radius in metres; repeat for several spheres")
      ->required();
  sub->add_option("--photos", cmd->photos,
                  "The photos showing the spheres, as scene.json names them (default: all)")
      ->delimiter(',');
  auto* target = sub->add_option("--target", cmd->target,
                                 "Region of a Lambertian target that gives each light's strength");
  sub->add_option("--reflectance", cmd->reflectance, "The target's reflectance, grey or R,G,B")
      ->delimiter(',')
      ->needs(target);
  sub->add_option("--type", cmd->type,
                  "auto (the scene light's kind), point (triangulated) or directional")
      ->check(CLI::IsMember({"auto", "point", "directional"}));
  sub->add_option("--out", cmd->out, "Output lights.json")->required();
  sub->add_option("--level", cmd->highlight.level,
                  "Highlight threshold, fraction from the sphere's median to its peak (0.2)");
  sub->add_option("--saturated", cmd->highlight.saturated,
                  "Value at which a channel is clipped, e.g. 1 for photos from 8/16-bit files "
                  "(default: none)");
  sub->add_option("--min-contrast", cmd->highlight.min_contrast,
                  "Least peak / median luminance of a highlight (3)");
  return sub;
}

// The spheres of --sphere: given, or fitted to a region's vertices.
std::vector<igi::calib::Sphere> LightSpheres(const LightsCommand& cmd,
                                             const igi::recon::Scene& scene) {
  std::vector<igi::calib::Sphere> spheres;
  for (const std::string& text : cmd.spheres) {
    igi::calib::Sphere sphere;
    sphere.name = text;
    if (text.find(',') != std::string::npos) {
      std::vector<double> v;
      std::stringstream in(text);
      for (std::string part; std::getline(in, part, ',');) {
        char* end = nullptr;
        v.push_back(std::strtod(part.c_str(), &end));
        if (end == part.c_str() || *end != '\0') v.push_back(NAN);
      }
      if (v.size() != 4 || !std::isfinite(v[0] + v[1] + v[2] + v[3]) || !(v[3] > 0)) {
        throw igi::InputError(
            igi::DescribeProblem("", "--sphere", text, "must be a region or x,y,z,radius (> 0)"));
      }
      sphere.center = {v[0], v[1], v[2]};
      sphere.radius = v[3];
    } else {
      const int region = scene.FindMaterial(text);
      std::vector<Eigen::Vector3d> points;
      for (size_t t = 0; region >= 0 && t < scene.mesh.num_triangles(); ++t) {
        if (scene.mesh.triangle_region[t] != region) continue;
        for (int k = 0; k < 3; ++k)
          points.push_back(scene.mesh.positions[size_t(scene.mesh.triangles[t][k])].cast<double>());
      }
      const auto fit = igi::calib::FitSphere(points);
      if (!fit || fit->fit_rms > 0.01 * fit->radius) {
        throw igi::InputError(igi::DescribeProblem(
            cmd.scene, "--sphere", text,
            region < 0 ? "no such region" : "the region's vertices are not on a sphere (1 %)"));
      }
      sphere = *fit;
      sphere.name = text;
    }
    spheres.push_back(sphere);
  }
  return spheres;
}

// The lit pixels of the target region in photo `p` under the calibrated light `light_index`.
std::vector<igi::calib::TargetSample> TargetSamples(const igi::recon::Scene& scene, size_t p,
                                                    const igi::render::RayScene& rays, int region,
                                                    const igi::Image& image,
                                                    const igi::calib::CalibratedLight& light,
                                                    double saturated) {
  const igi::recon::Photo& photo = scene.photos[p];
  const igi::recon::Camera& camera = scene.cameras[size_t(photo.camera)];
  std::optional<igi::Image> mask;
  if (photo.mask) mask = igi::ReadImage(*photo.mask, 1);
  std::vector<igi::calib::TargetSample> samples;
  const Eigen::Vector3d eye = camera.CenterInWorld();
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (mask && mask->at(x, y) <= 0) continue;
      const Eigen::Vector2d px(x + 0.5, y + 0.5);
      const auto hit = rays.TraceSurface(eye, camera.WorldRayFromImg(px));
      if (!hit || hit->region != region) continue;
      const Eigen::Vector3d to_light =
          light.position ? Eigen::Vector3d(light.position->position - hit->position)
                         : light.direction->to_light;
      const double distance = light.position ? to_light.norm() : INFINITY;
      const Eigen::Vector3d origin = hit->position + hit->n_geo * rays.ray_epsilon();
      if (rays.Occluded(origin, to_light.normalized(), distance, 0)) continue;
      igi::calib::TargetSample s{Eigen::Vector3d::Zero(), hit->position, hit->n_s};
      const double scale = photo.exposure_scale * camera.VignettingFactor(px);
      bool clipped = false;
      for (int c = 0; c < 3; ++c) {
        clipped = clipped || image.at(x, y, c) >= saturated;
        s.radiance[c] = photo.LinearFromRecorded(image.at(x, y, c)) / scale;
      }
      if (!clipped) samples.push_back(s);
    }
  }
  return samples;
}

// One lighting's light from its photos' rays (a direction, or a triangulated position) and,
// with a target region, its strength; its scene entry updated. Throws InputError.
igi::calib::CalibratedLight CalibrateLighting(const LightsCommand& cmd,
                                              const igi::recon::Scene& scene, int li,
                                              const std::vector<igi::calib::LightRay>& rays,
                                              const std::vector<size_t>& photos, int target,
                                              const Eigen::Vector3d& rho) {
  namespace calib = igi::calib;
  using igi::recon::LightType;
  const igi::recon::Lighting& lighting = scene.lightings[size_t(li)];
  const igi::recon::Light& light = scene.lights[size_t(lighting.lights[0])];
  calib::CalibratedLight cl;
  cl.name = light.name;
  cl.lighting = lighting.name;
  cl.entry = scene.document["lights"][light.name];
  cl.rays = rays;
  const bool directional =
      cmd.type == "directional" || (cmd.type == "auto" && light.type == LightType::kDirectional);
  const bool same = directional == (light.type == LightType::kDirectional);
  if (light.type == LightType::kArea || light.type == LightType::kAmbient ||
      (target >= 0 && light.type == LightType::kSpot) || (!same && target < 0)) {
    throw igi::InputError(igi::DescribeProblem(
        cmd.scene, "lights." + light.name, std::string(igi::recon::LightTypeName(light.type)),
        "cannot be calibrated as " + std::string(directional ? "directional" : "point") +
            " from highlights" + (target < 0 ? " without --target" : "")));
  }
  if (directional) {
    cl.direction = calib::AverageDirection(rays);
    if (!same) cl.entry = {{"type", "directional"}};
    cl.entry["direction"] = {-cl.direction->to_light.x(), -cl.direction->to_light.y(),
                             -cl.direction->to_light.z()};
  } else {
    cl.position = calib::TriangulateRays(rays, light.name);
    const Eigen::Vector3d& x = cl.position->position;
    if (!same) cl.entry = {{"type", "point"}};
    cl.entry[light.type == LightType::kSphere ? "center" : "position"] = {x.x(), x.y(), x.z()};
  }
  if (target >= 0) {
    igi::render::RayScene ray_scene(scene, li);
    std::vector<calib::TargetSample> samples;
    for (size_t p : photos) {
      const auto more =
          TargetSamples(scene, p, ray_scene, target, igi::ReadImage(scene.photos[p].file, 3), cl,
                        cmd.highlight.saturated);
      samples.insert(samples.end(), more.begin(), more.end());
    }
    cl.emission = directional ? calib::DirectionalIrradianceFromTarget(
                                    samples, -cl.direction->to_light, rho, light.name)
                              : calib::PointIntensityFromTarget(samples, cl.position->position, rho,
                                                                light.name);
    Eigen::Vector3d v = cl.emission->value;
    if (light.type == LightType::kSphere) v /= std::numbers::pi * light.radius * light.radius;
    cl.entry[directional                        ? "irradiance"
             : light.type == LightType::kSphere ? "radiance"
                                                : "intensity"] = {v.x(), v.y(), v.z()};
  }
  return cl;
}

int RunLights(const LightsCommand& cmd) {
  namespace calib = igi::calib;
  cmd.highlight.Validate();
  if (!cmd.target.empty() && cmd.reflectance.size() != 1 && cmd.reflectance.size() != 3) {
    throw igi::InputError("--reflectance: must be given with --target, one number or R,G,B");
  }
  Eigen::Vector3d rho = Eigen::Vector3d::Ones();
  for (int c = 0; c < 3 && !cmd.reflectance.empty(); ++c) {
    rho[c] = cmd.reflectance[std::min(size_t(c), cmd.reflectance.size() - 1)];
    if (!(rho[c] > 0 && rho[c] <= 1)) throw igi::InputError("--reflectance: must be in (0, 1]");
  }
  const igi::recon::Scene scene = igi::recon::LoadScene(cmd.scene);
  const int target = cmd.target.empty() ? -1 : scene.FindMaterial(cmd.target);
  if (!cmd.target.empty() && target < 0) {
    throw igi::InputError(
        igi::DescribeProblem(cmd.scene, "--target", cmd.target, "no such region"));
  }
  const std::vector<calib::Sphere> spheres = LightSpheres(cmd, scene);
  // Every photo's rays, by lighting.
  std::map<int, std::vector<size_t>> photos_of;
  std::map<int, std::vector<calib::LightRay>> rays_of;
  igi::ProblemList problems;
  for (size_t p = 0; p < scene.photos.size(); ++p) {
    const std::string name = scene.document["photos"][p]["file"].get<std::string>();
    if (!cmd.photos.empty() &&
        std::find(cmd.photos.begin(), cmd.photos.end(), name) == cmd.photos.end())
      continue;
    const igi::recon::Photo& photo = scene.photos[p];
    const igi::recon::Camera& camera = scene.cameras[size_t(photo.camera)];
    const calib::SphereView view{
        camera.CenterInWorld(),
        [&](const Eigen::Vector2d& px) { return camera.WorldRayFromImg(px); },
        [&](const Eigen::Vector3d& x) { return camera.ImgFromWorld(x); }};
    const igi::Image image = igi::ReadImage(photo.file, 3);
    std::optional<igi::Image> mask;
    if (photo.mask) mask = igi::ReadImage(*photo.mask, 1);
    photos_of[photo.lighting].push_back(p);
    for (const calib::Sphere& sphere : spheres) {
      try {
        rays_of[photo.lighting].push_back(calib::MeasureLightRay(
            image, mask ? &*mask : nullptr, sphere, view, cmd.highlight, name));
      } catch (const igi::InputError& e) {
        problems.Append(e);
      }
    }
  }
  problems.ThrowIfAny();
  if (rays_of.empty()) throw igi::InputError("--photos: none of the scene's photos was named");
  std::vector<calib::CalibratedLight> lights;
  for (const auto& [li, rays] : rays_of) {
    const igi::recon::Lighting& lighting = scene.lightings[size_t(li)];
    if (lighting.lights.size() != 1) {
      problems.Add(cmd.scene, "lightings." + lighting.name,
                   std::to_string(lighting.lights.size()) + " lights",
                   "a lighting calibrated from highlights must hold one light");
      continue;
    }
    try {
      lights.push_back(CalibrateLighting(cmd, scene, li, rays, photos_of[li], target, rho));
    } catch (const igi::InputError& e) {
      problems.Append(e);
    }
  }
  problems.ThrowIfAny();
  calib::WriteLightsFile(cmd.out, spheres, lights);
  size_t views = 0;
  for (const calib::CalibratedLight& l : lights) views += l.rays.size();
  std::printf("%s: %zu light(s) from %zu highlight(s) on %zu sphere(s)%s\n", cmd.out.c_str(),
              lights.size(), views, spheres.size(),
              cmd.target.empty() ? "" : ", strengths from the target");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "igi-calib: camera calibration (response curves, intrinsics, vignetting, colour, lights)",
      "igi-calib");
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags, /*computes=*/true);
  app.require_subcommand(1);
  ResponseCommand response;
  CLI::App* response_app = AddResponseCommand(app, &response);
  IntrinsicsCommand intrinsics;
  CLI::App* intrinsics_app = AddIntrinsicsCommand(app, &intrinsics);
  ColourCommand colour;
  CLI::App* colour_app = AddColourCommand(app, &colour);
  VignettingCommand vignetting;
  CLI::App* vignetting_app = AddVignettingCommand(app, &vignetting);
  LightsCommand lights;
  CLI::App* lights_app = AddLightsCommand(app, &lights);
  return igi::RunMain(app, flags, argc, argv, [&]() -> int {
    if (response_app->parsed()) return RunResponse(response);
    if (intrinsics_app->parsed()) return RunIntrinsics(intrinsics);
    if (colour_app->parsed()) return RunColour(colour);
    if (vignetting_app->parsed()) return RunVignetting(vignetting);
    if (lights_app->parsed()) return RunLights(lights);
    throw igi::InputError(
        "no subcommand: use igi-calib response|intrinsics|vignetting|colour|lights …");
  });
}
