// diagnosis.json (docs/file-formats.md) and report.html of igi-diagnose.
#include <fmt/format.h>

#include "solver/diagnose/diagnose.h"
#include "tools/common/atomic_file.h"
#include "tools/common/html_report.h"

namespace igi::diagnose {
namespace fs = std::filesystem;

namespace {

Json Num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json CandidateJson(const CandidateResult& c) {
  Json j = {{"effect", c.effect}, {"valid", c.valid}};
  if (!c.note.empty()) j["note"] = c.note;
  if (!c.valid) return j;
  j["params"] = c.params;
  j["predicted_held_out_gain"] = Num(c.Gain());
  j["z"] = Num(c.z);
  return j;
}

}  // namespace

Json DiagnosisJson(const DiagnosisSummary& s, const DiagnoseOptions& o) {
  Json j;
  j["format"] = "igi-diagnosis";
  j["version"] = 1;
  j["metric"] = "relative RMS residual over valid pixels of all photos";
  j["baseline"] = {{"residual", Num(s.baseline_residual)},
                   {"held_out_residual", Num(s.baseline_held_out)}};
  Json steps = Json::array(), rejected = Json::array();
  for (const DiagnosisStep& d : s.steps) {
    Json step = {{"effect", d.candidate.effect},
                 {"evidence", d.candidate.evidence},
                 {"where", d.candidate.where},
                 {"params", d.candidate.params},
                 {"residual_before", Num(d.residual_before)},
                 {"residual_after", Num(d.residual_after)},
                 {"held_out_before", Num(d.held_out_before)},
                 {"held_out_after", Num(d.held_out_after)},
                 {"num_params", d.candidate.num_params < 0 ? Json("per texel")
                                                           : Json(d.candidate.num_params)},
                 {"z", Num(d.z)},
                 {"verdict", d.verdict}};
    if (!d.residual_pixels.empty()) step["residual_pixels"] = d.residual_pixels;
    (d.kept ? steps : rejected).push_back(std::move(step));
  }
  j["steps"] = steps;
  j["final"] = {{"residual", Num(s.final_residual)}, {"held_out_residual", Num(s.final_held_out)}};
  j["unexplained"] = s.unexplained;
  // igi additions.
  j["noise_floor"] = Num(s.noise_floor);
  j["noise_floor_method"] =
      "white part of the residual: differences of horizontally adjacent valid pixels";
  j["rejected_steps"] = rejected;
  Json last = Json::array();
  for (const CandidateResult& c : s.last_candidates) last.push_back(CandidateJson(c));
  j["last_candidates"] = last;
  j["materials_solved"] = s.solved;
  j["held_out"] = {{"fraction", o.holdout_fraction},
                   {"block_px", o.holdout_block_px},
                   {"rule", fmt::format("a step is kept when the held-out residual² falls by "
                                        ">= {:.0f}% and >= {:.1f} standard errors",
                                        100 * o.min_gain, o.min_z)}};
  if (!s.analysis.is_null()) j["analysis"] = s.analysis;
  if (!s.memory.is_null()) j["memory"] = s.memory;
  if (!s.render_noise.is_null()) j["render_noise"] = s.render_noise;
  j["seconds"] = Num(s.seconds);
  return j;
}

void WriteDiagnosisOutputs(const DiagnosisSummary& s, const DiagnoseOptions& o,
                           const fs::path& out_dir) {
  fs::create_directories(out_dir);
  WriteJsonFile(out_dir / "diagnosis.json", DiagnosisJson(s, o), 1);
  HtmlReport page("igi-diagnose report");
  page.Paragraph(fmt::format(
      "Residual (relative RMS over valid pixels): baseline {:.4f} (held out {:.4f}) → final "
      "{:.4f} (held out {:.4f}); noise floor estimate {:.4f}. Materials {}.",
      s.baseline_residual, s.baseline_held_out, s.final_residual, s.final_held_out,
      s.noise_floor, s.solved ? "solved with igi-solve at every step" : "as declared"));
  std::vector<std::vector<std::string>> rows, classes;
  for (const DiagnosisStep& d : s.steps) {
    rows.push_back({d.candidate.effect, d.candidate.evidence, d.candidate.params.dump(),
                    fmt::format("{:.4f} → {:.4f}{}", d.residual_before, d.residual_after,
                                d.residual_pixels.empty() ? "" : " (" + d.residual_pixels + ")"),
                    fmt::format("{:.4f} → {:.4f}", d.held_out_before, d.held_out_after),
                    d.verdict});
    classes.push_back({"", "", "", "", d.kept ? "good" : "bad", ""});
  }
  page.Heading("Steps");
  if (rows.empty()) {
    page.Note("No effect improved the held-out residual significantly: nothing was added.");
  } else {
    page.Table({"effect", "evidence", "parameters", "residual", "held out", "verdict"}, rows,
               classes);
  }
  for (const DiagnosisStep& d : s.steps) {
    if (d.residual_before_image.width == 0) continue;
    page.Heading(d.candidate.effect + (d.kept ? " (kept)" : " (rejected)"), 3);
    page.Paragraph("Residual (render − photo) of " + d.image_photo +
                   " before and after the step, same colour scale" +
                   (d.residual_pixels.empty()
                        ? std::string(".")
                        : std::string(", where the step's held-out test reads (a step not "
                                      "applied is rendered only there).")));
    double scale = 0;
    for (float v : d.residual_before_image.pixels) scale = std::max(scale, double(std::abs(v)));
    page.ResidualImage(d.residual_before_image, "before", scale * 0.5, 320);
    page.ResidualImage(d.residual_after_image, "after", scale * 0.5, 320);
  }
  page.Heading("The improved model");
  if (!s.final_images.empty()) {
    page.ImageRow({s.final_images[0], s.final_images[1]}, 0, 320);
    page.ResidualImage(s.final_images[2].first, s.final_images[2].second, 0, 320);
  }
  page.Heading("What remains");
  if (s.unexplained.empty()) {
    page.Paragraph("No photo/region residual exceeds 1.5× the noise floor estimate.");
  } else {
    std::vector<std::vector<std::string>> un;
    for (const Json& u : s.unexplained) {
      un.push_back({u["where"].get<std::string>(), fmt::format("{:.4f}", u["residual"].get<double>())});
    }
    page.Table({"where", "residual"}, un);
  }
  page.Heading("Candidates of the last round");
  std::vector<std::vector<std::string>> cand;
  for (const CandidateResult& c : s.last_candidates) {
    cand.push_back({c.effect, c.valid ? fmt::format("{:.1f}%", 100 * c.Gain()) : "-",
                    c.valid ? fmt::format("{:.1f}", c.z) : "-", c.valid ? c.params.dump() : c.note});
  }
  page.Table({"effect", "predicted held-out gain", "z", "parameters or note"}, cand);
  page.Write(out_dir / "report.html");
  WriteJsonFile(out_dir / "scene.json", s.final_scene, 1);
}

}  // namespace igi::diagnose
