#pragma once
// The shared fixture of igi-diagnose's concealed-data tests: an igi-synth capture that
// hides one effect scene.json does not declare, igi-diagnose on it, and the "floor" — the residual
// of the TRUE model (truth/scene.json plus the photo effects of truth.json) rendered the same way
// over the same pixels.
//
// Size (CI): 4 cameras of 160×120, photos at 64 paths per pixel, a point lamp (its glossy
// reflections are sampled by next-event estimation only, so the photos carry no fireflies),
// materials given (so no solve; the full suite with unknown materials is
// bench/diagnose/run_concealed_suite.sh). igi-diagnose re-renders at 128 paths per pixel with
// held-out blocks of 8 pixels, on 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/json.h"

namespace igi::test {

// The paths fixed at 128 (--spp-max 0): the cases' figures were measured so, and the cap of the
// default at this size (0.08 MP analysed) would allow thousands.
inline const std::string kConcealedDiagnoseFlags =
    " --spp 128 --spp-max 0 --holdout-block-px 8 --threads 2 --quiet";

// Writes an igi-synth capture into dir/capture hiding `effect` ("NAME[:k=v,...]", several joined
// by '+'; empty: none), with `synth_extra` added to igi-synth's flags (the capture's design).
// With `materials_given` false the scene leaves every material value out (igi-synth's default
// unknowns) and igi-diagnose solves them at every step.
inline std::filesystem::path SynthesizeConcealed(const std::filesystem::path& dir,
                                                 const std::string& effect, int seed,
                                                 const std::string& synth_extra = "",
                                                 bool materials_given = true) {
  const std::filesystem::path capture = dir / "capture";
  std::string args = "--out " + Quote(capture.string()) +
                     " --cameras 4 --width 160 --height 120 --spp 64 --lamp point" +
                     std::string(materials_given ? " --unknowns none" : "") +
                     " --threads 2 --quiet --seed " + std::to_string(seed) + synth_extra;
  for (size_t begin = 0; begin < effect.size();) {
    const size_t end = std::min(effect.find('+', begin), effect.size());
    args += " --effect " + effect.substr(begin, end - begin);
    begin = end + 1;
  }
  const RunResult r = RunTool("igi-synth", args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return capture;
}

// Runs igi-diagnose on `scene` into `out` (kConcealedDiagnoseFlags + `extra`) and returns its
// diagnosis.json (an empty object when it failed).
inline Json RunDiagnose(const std::filesystem::path& scene, const std::filesystem::path& out,
                        const std::string& extra = "") {
  const RunResult r =
      RunTool("igi-diagnose", Quote(scene.string()) + " --out " + Quote(out.string()) +
                                  kConcealedDiagnoseFlags + extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return Json::object();
  return ReadJsonFile(out / "diagnosis.json");
}

// The true model: truth/scene.json's geometry, materials and lights with the photos (and masks) of
// `photos_of` (a scene document whose paths are relative to its folder; default: the capture's
// scene.json), and the photo effects of truth.json declared in the contract's (igi's) keys.
// Written to truth/true_model.json, with absolute photo paths.
inline std::filesystem::path WriteTrueModel(const std::filesystem::path& capture,
                                            std::filesystem::path photos_of = {}) {
  namespace fs = std::filesystem;
  if (photos_of.empty()) photos_of = capture / "scene.json";
  auto absolute = [](const fs::path& p) { return fs::absolute(p).lexically_normal().string(); };
  Json truth_scene = ReadJsonFile(capture / "truth" / "scene.json");
  Json photos = ReadJsonFile(photos_of)["photos"];
  for (Json& p : photos) {
    for (const char* key : {"file", "mask"}) {
      if (p.contains(key) && p[key].is_string()) {
        p[key] = absolute(photos_of.parent_path() / p[key].get<std::string>());
      }
    }
  }
  const Json truth = ReadJsonFile(capture / "truth.json");
  for (const Json& e : truth["effects"]) {
    const std::string name = e["effect"];
    const Json& params = e["params"];
    if (name == "vignetting") {
      for (auto& [n, cam] : truth_scene["cameras"].items()) {
        cam["vignetting"] = {{"k1", params["k1"]}, {"k2", params["k2"]}};
      }
    } else if (name == "exposure_scale") {
      const std::string file = absolute(capture / params["photo"].get<std::string>());
      for (Json& p : photos) {
        if (p["file"] == file) p["exposure_scale"] = params["scale"];
      }
    } else if (name == "camera_response") {
      for (Json& p : photos) {
        p["response"] = {{"exponent", params["exponent"]}, {"reference", params["reference"]}};
      }
    }
  }
  truth_scene["photos"] = photos;
  const fs::path out = capture / "truth" / "true_model.json";
  WriteJsonFile(out, truth_scene);
  return out;
}

// The floor: the baseline residual of the true model (WriteTrueModel) with no step, into `out`.
inline double FloorResidual(const std::filesystem::path& true_model,
                            const std::filesystem::path& out) {
  const Json d = RunDiagnose(true_model, out, " --max-steps 0");
  return d.contains("baseline") ? d["baseline"]["residual"].get<double>() : 0.0;
}

struct ConcealedOutcome {
  Json diagnosis;
  double floor = 0;
};

// Synthesizes a capture hiding `effect` (empty: none; `synth_extra`: more igi-synth flags),
// diagnoses it, measures the floor, calls `inspect` (when given) with the diagnosis folder, and
// removes everything (unless the environment variable IGI_CONCEALED_KEEP names a folder:
// everything is moved there, for study).
// `materials_given` false: the materials are solved (SynthesizeConcealed), igi-diagnose without
// stage 2 (--refine-iterations 0, as the full suite).
inline ConcealedOutcome DiagnoseConcealed(
    const std::string& effect, int seed,
    const std::function<void(const std::filesystem::path& diag_dir)>& inspect = nullptr,
    const std::string& synth_extra = "", bool materials_given = true) {
  const std::filesystem::path dir =
      UniqueTempDir("igi_concealed_" + (effect.empty() ? std::string("none") : effect));
  const std::filesystem::path capture =
      SynthesizeConcealed(dir, effect, seed, synth_extra, materials_given);
  ConcealedOutcome o;
  o.diagnosis = RunDiagnose(capture / "scene.json", dir / "diag",
                            materials_given ? "" : " --refine-iterations 0");
  if (inspect) inspect(dir / "diag");
  o.floor = FloorResidual(WriteTrueModel(capture), dir / "floor");
  // The figures a reader of the log needs to see how near a bound a run came (the folders are
  // removed below).
  if (o.diagnosis.contains("final") && o.floor > 0) {
    std::string kept;
    for (const Json& s : o.diagnosis["steps"]) {
      kept += (kept.empty() ? "" : ", ") + s["effect"].get<std::string>();
    }
    const double fin = o.diagnosis["final"]["residual"].get<double>();
    std::printf("[concealed %s seed %d] kept: %s; baseline %.4f, final %.4f, floor %.4f: %.3fx\n",
                effect.empty() ? "none" : effect.c_str(), seed, kept.empty() ? "-" : kept.c_str(),
                o.diagnosis["baseline"]["residual"].get<double>(), fin, o.floor, fin / o.floor);
  }
  if (const char* keep = std::getenv("IGI_CONCEALED_KEEP"); keep != nullptr && *keep != 0) {
    const std::filesystem::path to = std::filesystem::path(keep) / dir.filename();
    std::filesystem::create_directories(to.parent_path());
    std::filesystem::copy(dir, to, std::filesystem::copy_options::recursive);
  }
  std::filesystem::remove_all(dir);
  return o;
}

// The final residual comes within 1.2× the floor and below the baseline.
inline void ExpectReachesTheFloor(const ConcealedOutcome& o) {
  const Json& d = o.diagnosis;
  ASSERT_TRUE(d.contains("final")) << d.dump(1);
  const double final_residual = d["final"]["residual"];
  EXPECT_LE(final_residual, 1.2 * o.floor)
      << "baseline " << d["baseline"]["residual"] << ", floor " << o.floor;
  EXPECT_LT(final_residual, d["baseline"]["residual"].get<double>());
}

}  // namespace igi::test
