// igi-calib: camera calibration (CONTRACT.md §4). Subcommands, one per calibration:
//   igi-calib response IMAGES… (--exposures LIST | --exposure-file FILE | EXIF) --out response.json
//             [--method debevec|robertson] [--lambda auto|L] [--samples N] [--levels N] [--plot
//             FILE]
// (intrinsics and vignetting are added beside `response` as subcommands of their own.)
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/bracket.h"
#include "calib/response_plot.h"
#include "calib/response_recovery.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace {

struct ResponseCommand {
  std::vector<std::string> images;
  igi::calib::ExposureSource exposures;
  std::string out;
  std::string plot;  // empty = OUT with the extension .svg
  bool no_plot = false;
  std::string lambda = "auto";
  igi::calib::ResponseOptions options;
};

CLI::App* AddResponseCommand(CLI::App& app, ResponseCommand* cmd) {
  CLI::App* sub =
      app.add_subcommand("response", "Recover the camera response curve from an exposure bracket");
  sub->add_option("images", cmd->images, "8- or 16-bit images of one bracket")->required();
  auto* list = sub->add_option("--exposures", cmd->exposures.list,
                               "Exposure times in seconds, comma-separated (0.004 or 1/250)");
  sub->add_option("--exposure-file", cmd->exposures.file,
                  "File with one exposure time per line ('#' comments)")
      ->excludes(list);
  sub->add_option("--out", cmd->out, "Output response.json")->required();
  sub->add_option("--plot", cmd->plot, "Plot of the curves (SVG); default OUT with .svg");
  sub->add_flag("--no-plot", cmd->no_plot, "Do not write the plot");
  sub->add_option("--method", cmd->options.method, "debevec or robertson")
      ->check(CLI::IsMember({"debevec", "robertson"}));
  sub->add_option("--lambda", cmd->lambda,
                  "Debevec smoothness weight, or auto (default): the smallest whose curve is "
                  "reproducible to 0.2 % (split-half test)");
  sub->add_option("--samples", cmd->options.samples, "Debevec sample pixels (0 = auto)");
  sub->add_option("--levels", cmd->options.levels,
                  "Levels of the curve (0 = 256 for 8-bit, 1024 for 16-bit)");
  sub->add_option("--black", cmd->options.black,
                  "Normalised level at or below which a value is unusable (default 0.02)");
  sub->add_option("--saturated", cmd->options.saturated,
                  "Normalised level at or above which a value is unusable (default 0.98)");
  sub->add_option("--max-iterations", cmd->options.max_iterations, "Robertson iterations");
  sub->add_option("--robertson-smoothing", cmd->options.robertson_smoothing,
                  "Robertson: second-difference penalty on ln I (0 = none)");
  return sub;
}

int RunResponse(ResponseCommand cmd) {
  cmd.options.lambda = igi::calib::ParseLambda(cmd.lambda);
  cmd.options.Validate();
  std::vector<std::filesystem::path> paths(cmd.images.begin(), cmd.images.end());
  const igi::calib::Bracket bracket = igi::calib::LoadBracket(paths, cmd.exposures);
  const igi::calib::ResponseSummary summary = igi::calib::RecoverResponse(bracket, cmd.options);
  igi::Json info;
  info["images"] = cmd.images;
  info["exposures_s"] = bracket.exposures_s;
  info["bits_per_sample"] = bracket.bits_per_sample;
  info["samples"] = summary.samples;
  info["equations"] = summary.equations;
  if (cmd.options.method == "debevec") {
    info["lambda"] = summary.lambda;  // per channel
    info["lambda_mode"] = cmd.options.lambda == igi::calib::kLambdaAuto ? "auto" : "given";
  }
  if (cmd.options.method == "robertson") {
    info["iterations"] = summary.iterations;
    info["converged"] = summary.converged;
  }
  info["rms_residual_ln"] = summary.rms_residual;
  igi::calib::WriteResponseJson(cmd.out, summary.curve, info);
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("igi-calib: camera calibration (response curves)", "igi-calib");
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags);
  app.require_subcommand(1);
  ResponseCommand response;
  CLI::App* response_app = AddResponseCommand(app, &response);
  return igi::RunMain(app, flags, argc, argv, [&]() -> int {
    if (response_app->parsed()) return RunResponse(response);
    throw igi::InputError("no subcommand: use igi-calib response …");
  });
}
