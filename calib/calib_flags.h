#pragma once
// igi-calib response's and igi-calib intrinsics' flags, defined once for the executable and for
// the Python package: igi.calib.response's and igi.calib.intrinsics' keyword arguments are these
// flags' names with '_' for '-', parsed and checked by the same code.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "calib/bracket.h"
#include "calib/intrinsics.h"
#include "calib/response_recovery.h"
#include "tools/common/json.h"

namespace igi::calib {

struct ResponseFlags {
  ExposureSource exposures;  // --exposures, --exposure-file; both empty = EXIF
  ResponseOptions options;   // --samples, --levels, --saturated, --max-iterations, ...
  // The choice flags as typed; FinishResponseFlags parses them into `options`.
  std::string method = "debevec";
  std::string lambda = "auto";
  std::string black = "auto";
};

// Adds igi-calib response's options, all but the images, --out and the plot's, to `app`.
void AddResponseFlags(CLI::App& app, ResponseFlags* flags);

// After parsing: the options with the choices parsed and validated (InputError
// "--FLAG: VALUE: RULE").
ResponseOptions FinishResponseFlags(const ResponseFlags& flags);

// response.json's "info" for a curve recovered from `bracket`, whose images are named `images`.
Json ResponseInfo(const std::vector<std::string>& images, const Bracket& bracket,
                  const ResponseSummary& summary, const ResponseOptions& options);

struct IntrinsicsFlags {
  IntrinsicsOptions options;  // --dictionary, --marker, --square, --fix-*, --subpix-window
  // The flags whose text FinishIntrinsicsFlags parses into `options`.
  std::string board;  // COLSxROWS
  std::string board_type = "chessboard";
  std::string model = "OPENCV";
};

// Adds igi-calib intrinsics' options, all but the images and --out, to `app`.
void AddIntrinsicsFlags(CLI::App& app, IntrinsicsFlags* flags);

// After parsing: the options with the board, its type and the model parsed and everything
// validated (InputError "--FLAG: VALUE: RULE").
IntrinsicsOptions FinishIntrinsicsFlags(const IntrinsicsFlags& flags);

}  // namespace igi::calib
