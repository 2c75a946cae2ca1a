// report.html of igi-solve: the parameter table with uncertainties, convergence, highlight
// coverage, and photo / render / residual side by side (one self-contained page).
#include <fmt/format.h>

#include <cmath>

#include "solver/inverse/solve.h"
#include "tools/common/html_report.h"

namespace igi::solver {
namespace {

std::string Fmt(double v, int digits = 4) {
  return std::isfinite(v) ? fmt::format("{:.{}g}", v, digits) : "–";
}
std::string FmtPm(double v, double sigma) {
  return std::isfinite(sigma) ? fmt::format("{} ± {}", Fmt(v), Fmt(sigma, 2)) : Fmt(v);
}
std::string Rgb(const Eigen::Vector3d& v) {
  return fmt::format("({}, {}, {})", Fmt(v[0], 3), Fmt(v[1], 3), Fmt(v[2], 3));
}

void ParameterTable(HtmlReport* page, const SolveSummary& s) {
  std::vector<std::vector<std::string>> rows, classes;
  for (const RegionSolution& r : s.regions) {
    const render::BrdfParams& p = r.final_params;
    const RegionFitResult& f1 = r.stage1;
    const RegionFitResult& f2 = r.stage2;
    const bool spec = recon::HasSpecularLobe(p.model);
    std::string alpha1 = "", alpha2 = "";
    if (spec && recon::IsAnisotropic(p.model)) {
      alpha1 = fmt::format("{} / {}", Fmt(f1.alpha_x), Fmt(f1.alpha_y));
      alpha2 = fmt::format("{} / {}", FmtPm(f2.alpha_x, f2.sigma_alpha_x),
                           FmtPm(f2.alpha_y, f2.sigma_alpha_y));
    } else if (spec) {
      alpha1 = Fmt(f1.alpha);
      alpha2 = FmtPm(p.alpha, f2.sigma_alpha);
    }
    const bool fitted = f2.fitted;
    rows.push_back({r.name, std::string(recon::BrdfModelName(p.model)),
                    std::string(RegionStatusName(r.status)), std::to_string(r.observations),
                    fitted ? Rgb(f1.rho_d) : "", Rgb(p.rho_d),
                    spec && fitted ? Fmt(f1.rho_s.mean()) : "",
                    spec ? FmtPm(p.rho_s.mean(), f2.sigma_rho_s) : "", alpha1, alpha2,
                    fitted ? std::string(AlbedoModelName(f2.albedo_model)) : "",
                    fitted ? Fmt(f2.relative_rms, 3) : "", r.albedo_map_file});
    const std::string cls =
        r.status == RegionStatus::kSolved || r.status == RegionStatus::kKnown ? "good" : "bad";
    classes.push_back({"", "", cls});
  }
  page->Table({"region", "brdf", "status", "observations", "ρd paper", "ρd final", "ρs paper",
               "ρs final ± σ", "α paper", "α final ± σ", "albedo", "fit rel. RMS", "albedo map"},
              rows, classes);
}

void Convergence(HtmlReport* page, const SolveSummary& s) {
  HtmlReport::Series paper{"paper (image-based)", {}, {}}, refined{"refined (path traced)", {}, {}};
  HtmlReport::Series change{"largest relative change", {}, {}};
  int k = 0;
  for (const SolveIteration& it : s.history) {
    ++k;
    (it.stage == 1 ? paper : refined).x.push_back(k);
    (it.stage == 1 ? paper : refined).y.push_back(it.relative_rms);
    change.x.push_back(k);
    change.y.push_back(it.max_change);
  }
  page->LinePlot("fit residual per iteration (all regions' samples)", {paper, refined},
                 "iteration", "relative RMS");
  page->LinePlot("largest relative parameter change per iteration", {change}, "iteration",
                 "change", true);
}

void Coverage(HtmlReport* page, const SolveSummary& s) {
  if (s.coverage.empty()) {
    page->Paragraph("No region with an unknown specular lobe.");
    return;
  }
  std::vector<std::vector<std::string>> rows, classes;
  for (const RegionHighlightCoverage& c : s.coverage) {
    std::string where;
    for (const HighlightSuggestion& h : c.suggestions) where += fmt::format("{} ", h.text);
    rows.push_back({c.name, c.observed ? "yes" : "NO", std::to_string(c.highlight_pixels),
                    std::to_string(c.photos.size()), where});
    classes.push_back({"", c.observed ? "good" : "bad"});
    if (!c.observed) {
      page->Note(fmt::format("{}: no photo shows the highlight, so ρs and α cannot be recovered. {}",
                             c.name, where),
                 "warning");
    }
  }
  page->Table({"region", "highlight seen", "pixels", "photos", "where a camera would need to stand"},
              rows, classes);
}

}  // namespace

void WriteSolveReportHtml(const SolveSummary& s, const Json& /*report*/,
                          const std::filesystem::path& path) {
  HtmlReport page("igi-solve report");
  page.Paragraph(fmt::format(
      "{} regions, {} observations on {} patches (patch size {:.3g} m), {:.1f} s in all, {:.0f} % "
      "of it casting rays ({} rays). Stage 1 (Yu et al. 1999): {} iterations, {}. Stage 2 "
      "(path-traced joint refinement): {} rounds.",
      s.regions.size(), s.observations, s.patches, s.patch_size_m, s.seconds_total,
      s.seconds_total > 0 ? 100 * s.seconds_rays / s.seconds_total : 0.0, s.rays,
      s.stage1_iterations, s.message, s.stage2_iterations));
  page.Paragraph(fmt::format(
      "Render vs photo at the observed pixels (relative RMS, path traced with {} samples per "
      "pixel, render noise removed): paper stage {}, refined {}.",
      s.render_residual_spp, Fmt(s.stage1_render_residual), Fmt(s.stage2_render_residual)));
  if (!s.refinement_accepted) {
    page.Note("The refinement explained the photos worse than the paper stage; the paper stage's "
              "parameters are the result (both are in the table).",
              "warning");
  }
  if (!s.converged) page.Note(fmt::format("Stage 1 did not converge: {}", s.message), "warning");
  for (const RegionSolution& r : s.regions) {
    if (r.status == RegionStatus::kUnobserved) {
      page.Note(fmt::format("{}: no photo sees this region; its values are placeholders.", r.name),
                "error");
    }
  }
  page.Heading("Parameters");
  ParameterTable(&page, s);
  page.Heading("Convergence");
  Convergence(&page, s);
  page.Heading("Highlight coverage");
  Coverage(&page, s);
  page.Heading("Photos, renders and residuals");
  for (const PhotoResidual& r : s.residuals) {
    page.Heading(fmt::format("{}: relative RMS paper {}, refined {}", r.file, Fmt(r.stage1),
                             Fmt(r.stage2)),
                 3);
    page.ImageRow({{r.photo, "photo (observed pixels)"}, {r.render, "final model, rendered"}}, 0, 320);
    page.ResidualImage(r.residual, "render − photo", 0, 320);
  }
  bool maps = false;
  for (const RegionSolution& r : s.regions) {
    if (!r.albedo_map) continue;
    if (!maps) page.Heading("Albedo maps");
    maps = true;
    page.Image(*r.albedo_map, fmt::format("{} ({})", r.name, r.albedo_map_file), 1.0, 256);
  }
  page.Write(path);
}

}  // namespace igi::solver
