#include "calib/calib_flags.h"

#include <stdexcept>

#include "tools/common/error.h"

namespace igi::calib {

void AddResponseFlags(CLI::App& app, ResponseFlags* flags) {
  CLI::Option* list = app.add_option("--exposures", flags->exposures.list,
                                     "Exposure times in seconds, comma-separated (0.004 or 1/250)");
  app.add_option("--exposure-file", flags->exposures.file,
                 "File with one exposure time per line ('#' comments)")
      ->excludes(list);
  app.add_option("--method", flags->method, "debevec or robertson");
  app.add_option("--lambda", flags->lambda,
                 "Debevec smoothness weight, or auto (default): the smallest whose curve is "
                 "reproducible to 0.2 % (split-half test)");
  app.add_option("--samples", flags->options.samples, "Debevec sample pixels (0 = auto)");
  app.add_option("--levels", flags->options.levels,
                 "Levels of the curve (0 = 256 for 8-bit, 1024 for 16-bit)");
  app.add_option("--black", flags->black,
                 "Normalised level at or below which a value is unusable, or auto (default): "
                 "each channel's black floor, at least 0.02");
  app.add_option("--saturated", flags->options.saturated,
                 "Normalised level at or above which a value is unusable (default 0.98)");
  app.add_option("--max-iterations", flags->options.max_iterations, "Robertson iterations");
  app.add_option("--robertson-smoothing", flags->options.robertson_smoothing,
                 "Robertson: second-difference penalty on ln I (0 = none)");
}

ResponseOptions FinishResponseFlags(const ResponseFlags& flags) {
  ResponseOptions options = flags.options;
  const auto method = ResponseRecoveryMethodFromName(flags.method);
  if (!method) {
    throw InputError(DescribeProblem("--method", "", flags.method, "must be debevec or robertson"));
  }
  options.method = *method;
  options.lambda = ParseLambda(flags.lambda);
  options.black = ParseBlack(flags.black);
  options.Validate();
  return options;
}

Json ResponseInfo(const std::vector<std::string>& images, const Bracket& bracket,
                  const ResponseSummary& summary, const ResponseOptions& options) {
  Json info;
  info["images"] = images;
  info["exposures_s"] = bracket.exposures_s;
  info["bits_per_sample"] = bracket.bits_per_sample;
  info["samples"] = summary.samples;
  info["equations"] = summary.equations;
  if (options.method == ResponseRecoveryMethod::kDebevec) {
    info["lambda"] = summary.lambda;  // per channel
    info["lambda_mode"] = options.lambda == kLambdaAuto ? "auto" : "given";
  }
  if (options.method == ResponseRecoveryMethod::kRobertson) {
    info["iterations"] = summary.iterations;
    info["converged"] = summary.converged;
  }
  info["rms_residual_ln"] = summary.rms_residual;
  info["black"] = summary.black;  // per channel
  info["black_mode"] = options.black == kBlackAuto ? "auto" : "given";
  return info;
}

void AddIntrinsicsFlags(CLI::App& app, IntrinsicsFlags* flags) {
  app.add_option("--board", flags->board,
                 "chessboard: inner corners COLSxROWS, e.g. 9x6; charuco: squares X x Y, e.g. 5x7")
      ->required();
  app.add_option("--board-type", flags->board_type, "chessboard (default) or charuco");
  app.add_option("--dictionary", flags->options.dictionary,
                 "charuco: OpenCV ArUco dictionary (default DICT_4X4_50)");
  app.add_option("--marker", flags->options.marker_m, "charuco: side of a marker in metres");
  app.add_option("--square", flags->options.square_m, "Side of one square in metres")->required();
  app.add_option("--model", flags->model, "PINHOLE, OPENCV (default) or FULL_OPENCV");
  app.add_flag("--fix-aspect-ratio", flags->options.fix_aspect_ratio, "Constrain fx = fy");
  app.add_flag("--zero-tangent-dist", flags->options.zero_tangent_dist, "Constrain p1 = p2 = 0");
  app.add_flag("--fix-principal-point", flags->options.fix_principal_point,
               "Keep the principal point at the image centre");
  app.add_option("--subpix-window", flags->options.subpix_window,
                 "Half window of the sub-pixel corner refinement (pixels)");
}

IntrinsicsOptions FinishIntrinsicsFlags(const IntrinsicsFlags& flags) {
  IntrinsicsOptions options = flags.options;
  const std::string& text = flags.board;
  const size_t x = text.find_first_of("xX");
  try {
    size_t used_cols = 0;
    size_t used_rows = 0;
    if (x == std::string::npos) throw std::invalid_argument(text);
    options.board_cols = std::stoi(text.substr(0, x), &used_cols);
    options.board_rows = std::stoi(text.substr(x + 1), &used_rows);
    if (used_cols != x || used_rows != text.size() - x - 1) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw InputError(DescribeProblem("", "--board", text, "must be COLSxROWS, e.g. 9x6"));
  }
  const auto type = BoardTypeFromName(flags.board_type);
  if (!type) {
    throw InputError(
        DescribeProblem("", "--board-type", flags.board_type, "must be chessboard or charuco"));
  }
  const auto model = ColmapCameraModelFromName(flags.model);
  if (!model) {
    throw InputError(
        DescribeProblem("", "--model", flags.model, "must be PINHOLE, OPENCV or FULL_OPENCV"));
  }
  options.board_type = *type;
  options.model = *model;
  options.Validate();
  return options;
}

}  // namespace igi::calib
