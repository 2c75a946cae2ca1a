#include "tools/pipeline/run_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "recon/scene.h"
#include "tools/common/html_report.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/pipeline/pipeline_internal.h"

namespace igi::pipeline {
namespace fs = std::filesystem;

namespace {

std::string Num(const Json& j, const char* fmt_spec = "{:.4g}") {
  if (j.is_number()) return fmt::format(fmt::runtime(fmt_spec), j.get<double>());
  if (j.is_array()) {
    std::vector<std::string> parts;
    for (const Json& v : j) parts.push_back(Num(v, fmt_spec));
    return "[" + fmt::format("{}", fmt::join(parts, ", ")) + "]";
  }
  return "—";
}

std::string WithSigma(const Json& fit, const std::string& key) {
  if (!fit.contains(key)) return "—";
  const std::string sigma = "sigma_" + key;
  return Num(fit[key]) + (fit.contains(sigma) ? " ± " + Num(fit[sigma], "{:.2g}") : "");
}

std::string PngUri(const Image& display) {
  return "data:image/png;base64," + Base64Encode(EncodePng(display));
}

std::string Figure(const Image& display, const std::string& caption) {
  return "<figure><img src=\"" + PngUri(display) + "\" alt=\"" + HtmlEscape(caption) +
         "\" width=\"" + std::to_string(std::min(display.width, 360)) + "\"><figcaption>" +
         HtmlEscape(caption) + "</figcaption></figure>\n";
}

void StagesSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Stages");
  std::vector<std::vector<std::string>> rows;
  for (const std::string& s : StageNames()) {
    const auto m = ReadStageMarker(out / s);
    const bool cpu =
        m && m->details.contains("cpu_seconds") && m->details["cpu_seconds"].is_number();
    const std::string status =
        m ? m->status : (s == StageNames().back() ? "writing this page" : "not finished");
    rows.push_back({s, status, m ? fmt::format("{:.1f}", m->seconds) : "",
                    cpu ? fmt::format("{:.1f}", m->details["cpu_seconds"].get<double>()) : "",
                    m ? m->finished_utc : ""});
  }
  page->Table({"stage", "status", "seconds", "CPU seconds", "finished (UTC)"}, rows);
}

void ResponseSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Camera response");
  const fs::path file = out / "01-response" / "response.json";
  if (!fs::exists(file)) {
    page->Note("No response curve: the photos were raw files or radiance maps (no LDR bracket).");
    return;
  }
  const Json r = ReadJsonFile(file);
  std::vector<HtmlReport::Series> series;
  const auto channels = r.value("channels", std::vector<std::string>{});
  for (size_t c = 0; c < r["g"].size(); ++c) {
    HtmlReport::Series s;
    s.name = c < channels.size() ? channels[c] : "channel " + std::to_string(c);
    for (size_t i = 0; i < r["g"][c].size(); ++i) {
      s.x.push_back(double(i));
      s.y.push_back(r["g"][c][i].get<double>());
    }
    series.push_back(s);
  }
  // Channels whose curves coincide on the plot (within 0.5 % of its range) are drawn as one,
  // named for all ("R = G" when equal to 1e-9, "R ≈ G" otherwise).
  double lo = INFINITY, hi = -INFINITY;
  for (const HtmlReport::Series& s : series) {
    for (double y : s.y) {
      lo = std::min(lo, y);
      hi = std::max(hi, y);
    }
  }
  for (size_t c = 1; c < series.size();) {
    const HtmlReport::Series& a = series[c - 1];
    bool same = a.y.size() == series[c].y.size();
    double diff = 0;
    for (size_t i = 0; same && i < a.y.size(); ++i)
      diff = std::max(diff, std::abs(a.y[i] - series[c].y[i]));
    if (!same || !(diff <= 0.005 * (hi - lo))) {
      ++c;
      continue;
    }
    series[c - 1].name += (diff < 1e-9 ? " = " : " ≈ ") + series[c].name;
    series.erase(series.begin() + long(c));
  }
  page->LinePlot("response g(level) = ln(exposure), method " + r.value("method", "?"), series,
                 "pixel level", "ln exposure");
}

// The calibrations the HDR stage applied (from its marker's details).
void CalibrationSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Camera calibration");
  const auto marker = ReadStageMarker(out / "02-hdr");
  std::vector<std::vector<std::string>> rows;
  if (marker && marker->details.contains("vignetting")) {
    const Json& v = marker->details["vignetting"];
    const double k1 = v["k1"].get<double>(), k2 = v["k2"].get<double>();
    rows.push_back(
        {"vignetting 1 + k1 r² + k2 r⁴ (divided out)",
         fmt::format("k1 {:.4f}, k2 {:.4f} (corner {:+.1f} %)", k1, k2, 100 * (k1 + k2)),
         fmt::format("{}, RMS {:.2f} %", v.value("method", "?"), 100 * v.value("rms_ln", 0.0)),
         v.value("file", "")});
  }
  if (marker && marker->details.contains("colour")) {
    const Json& c = marker->details["colour"];
    std::vector<std::string> matrix;
    for (const Json& row : c["matrix"]) matrix.push_back(Num(row, "{:.3f}"));
    rows.push_back({"colour: camera RGB → linear sRGB (applied)",
                    fmt::format("{}", fmt::join(matrix, " ")),
                    fmt::format("ColorChecker, {} input, ΔE2000 mean {:.2f}, max {:.2f}",
                                c.value("input", "?"), c.value("delta_e2000_mean", 0.0),
                                c.value("delta_e2000_max", 0.0)),
                    c.value("file", "")});
  }
  const auto solve = ReadStageMarker(out / "04-solve");
  if (solve && solve->details.contains("lights")) {
    const Json& l = solve->details["lights"];
    const auto names = l["names"].get<std::vector<std::string>>();
    rows.push_back({"lights (replace the scene's)", fmt::format("{}", fmt::join(names, ", ")),
                    "igi-calib lights", l.value("file", "")});
  }
  if (rows.empty()) {
    page->Note(
        "No calibration was applied: no camera.json with a vignetting, no colour.json and no "
        "lights.json (igi-calib vignetting, colour, lights).");
    return;
  }
  page->Table({"calibration", "values", "measured by", "file"}, rows);
}

void CamerasSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Registered cameras");
  const fs::path scene_file = out / "03-register" / "scene.json";
  const fs::path report_file = out / "03-register" / "register" / "report.json";
  if (!fs::exists(scene_file) || !fs::exists(report_file)) {
    page->Note("No registration stage: the cameras were given in the scene (--hdr-photos).");
    return;
  }
  const Json report = ReadJsonFile(report_file);
  std::map<std::string, std::string> rms;
  for (const Json& r : report["registered"]) {
    rms[fs::path(r["file"].get<std::string>()).stem().string()] =
        fmt::format("{:.2f} px ({} points)", r["reprojection_rms_px"].get<double>(),
                    r["observations"].get<int>());
  }
  recon::SceneLoadOptions load;
  load.load_geometry = load.check_images = false;
  const recon::Scene scene = recon::LoadScene(scene_file, load);
  std::vector<std::vector<std::string>> rows;
  for (const recon::Camera& c : scene.cameras) {
    const Eigen::Vector3d centre = c.CenterInWorld();
    const Eigen::Vector3d forward =
        c.cam_from_world.rotation.conjugate() * Eigen::Vector3d(0, 0, 1);
    rows.push_back({c.name,
                    fmt::format("{:.3f}, {:.3f}, {:.3f}", centre.x(), centre.y(), centre.z()),
                    fmt::format("{:.3f}, {:.3f}, {:.3f}", forward.x(), forward.y(), forward.z()),
                    fmt::format("{:.1f}", c.params.empty() ? 0.0 : c.params[0]), rms[c.name]});
  }
  page->Table(
      {"camera", "centre (scene frame, m)", "viewing direction", "fx (px)", "reprojection RMS"},
      rows);
  if (report.contains("unregistered") && !report["unregistered"].empty()) {
    page->Note("Not registered: " + report["unregistered"].dump(), "warning");
  }
  if (report.contains("alignment")) {
    page->Paragraph("Alignment to the scene: " + report["alignment"].value("method", "?") +
                    ", scale " + Num(report["alignment"].value("scale", Json())));
  }
}

void ParametersSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Recovered materials");
  const fs::path file = out / "04-solve" / "report.json";
  if (!fs::exists(file)) {
    page->Note("The solve stage has not finished.", "error");
    return;
  }
  const Json report = ReadJsonFile(file);
  const bool refined = report["stages"]["refined"].value("accepted", false);
  std::vector<std::vector<std::string>> rows;
  for (const Json& r : report["regions"]) {
    const Json& fit = refined && r["refined"].value("fitted", true) ? r["refined"] : r["paper"];
    rows.push_back({r.value("name", "?"), r.value("status", "?"), WithSigma(fit, "rho_d"),
                    WithSigma(fit, "rho_s"), WithSigma(fit, "alpha"),
                    fit.contains("relative_rms") ? Num(fit["relative_rms"]) : "—",
                    std::to_string(r.value("observations", 0))});
  }
  page->Table(
      {"region", "status", "ρd (mean) ± σ", "ρs ± σ", "α ± σ", "fit rel. RMS", "observations"},
      rows);
  page->Paragraph(std::string("Values of the ") +
                  (refined ? "path-traced refinement" : "paper's stage") + "; render residual " +
                  Num(report["stages"][refined ? "refined" : "paper"]["render_residual"]) +
                  ". Full solver report: 04-solve/report.html.");
}

// Photo / re-render / residual for the photos rendered by the report stage (renders/photo_K.exr:
// the solved model as photo K records it).
void PhotosSection(const fs::path& out, int max_photos, HtmlReport* page) {
  page->Heading("Photos, re-renders of the solved model, residuals");
  if (!fs::exists(out / "04-solve" / "scene.json")) {
    page->Note("The solve stage has not finished.", "error");
    return;
  }
  recon::SceneLoadOptions load;
  load.load_geometry = load.check_images = false;
  const recon::Scene scene = recon::LoadScene(out / "04-solve" / "scene.json", load);
  const int n = std::min<int>(max_photos, int(scene.photos.size()));
  for (int k = 0; k < n; ++k) {
    const recon::Photo& p = scene.photos[k];
    const fs::path render_file = out / "06-report" / "renders" / fmt::format("photo_{}.exr", k);
    if (!fs::exists(render_file)) continue;
    // The render is at the photo's size or reduced by an integer factor (report_megapixels):
    // the photo and its mask are shown as the means of blocks of that factor.
    const Image render = ReadImage(render_file, 3);
    Image photo = ReadImage(scene.dir / p.file, 3);
    const int f = std::max(1, photo.width / std::max(1, render.width));
    photo = BlockMeans(photo, f);
    double exposure = 0;
    const Image photo_display = ToneMapSrgb(photo, 0, &exposure);
    std::string row = "<div class=\"row\">" +
                      Figure(photo_display, "photo " + p.file.filename().string()) +
                      Figure(ToneMapSrgb(render, exposure), "re-render (solved model)");
    if (render.width == photo.width && render.height == photo.height) {
      Image residual = render;
      // A block is valid when every pixel of it is.
      const std::optional<Image> mask =
          p.mask ? std::optional<Image>(BlockMeans(ReadImage(scene.dir / *p.mask, 1), f))
                 : std::nullopt;
      for (size_t i = 0; i < residual.pixels.size(); ++i) {
        const bool valid = !mask || mask->pixels[i / 3] > 1.0f - 1e-4f;
        const float d = render.pixels[i] - photo.pixels[i];
        residual.pixels[i] = valid && std::isfinite(d) ? d : 0.0f;
      }
      row += Figure(ResidualColours(residual), "residual render − photo (blue −, red +)");
    }
    page->RawHtml(row + "</div>\n");
  }
}

void RelitSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Relit renders (the solved model under each lighting)");
  const fs::path dir = out / "06-report" / "renders";
  std::vector<fs::path> files;
  if (fs::exists(dir)) {
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().filename().string().rfind("relit_", 0) == 0) files.push_back(e.path());
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    page->Note("No relit renders.", "warning");
    return;
  }
  std::string row = "<div class=\"row\">";
  double exposure = 0;
  for (const fs::path& f : files) {
    const Image image = ReadImage(f, 3);
    const Image display = ToneMapSrgb(image, exposure, exposure == 0 ? &exposure : nullptr);
    row += Figure(display, f.stem().string().substr(6));
  }
  page->RawHtml(row + "</div>\n");
}

void DiagnosisSection(const fs::path& out, HtmlReport* page) {
  page->Heading("Diagnosis");
  const fs::path file = out / "05-diagnose" / "diagnosis.json";
  if (!fs::exists(file)) {
    page->Note("No diagnosis: the stage was skipped or igi-diagnose did not write diagnosis.json.");
    return;
  }
  const Json d = ReadJsonFile(file);
  page->Paragraph("Metric: " + d.value("metric", "?") + ". Baseline residual " +
                  Num(d["baseline"].value("residual", Json())) + ", final " +
                  Num(d["final"].value("residual", Json())) + ".");
  std::vector<std::vector<std::string>> rows;
  for (const Json& s : d.value("steps", Json::array())) {
    rows.push_back(
        {s.value("effect", "?"), s.value("evidence", ""),
         s.contains("params") ? s["params"].dump() : "",
         Num(s.value("residual_before", Json())) + " → " + Num(s.value("residual_after", Json())),
         Num(s.value("held_out_before", Json())) + " → " + Num(s.value("held_out_after", Json()))});
  }
  page->Table({"effect", "evidence", "parameters", "residual", "held-out residual"}, rows);
  for (const Json& u : d.value("unexplained", Json::array())) {
    page->Note("Unexplained: " + u.dump(), "warning");
  }
}

// The exported scenes: per format, links to its files (relative to report.html) or the line its
// export failed with.
void ExportsSection(const fs::path& out, const Json& exports, HtmlReport* page) {
  page->Heading("The solved scene for other renderers");
  if (exports.empty()) {
    page->Note("No exports.", "warning");
    return;
  }
  std::string html = "<table><tr><th>format</th><th>files</th></tr>";
  for (const auto& [format, e] : exports.items()) {
    std::string cell;
    if (e.contains("error")) {
      cell = HtmlEscape("failed: " + e["error"].get<std::string>());
    } else {
      const std::string dir = e["dir"].get<std::string>();
      std::vector<std::string> files;
      if (fs::exists(out / dir)) {
        for (const auto& f : fs::directory_iterator(out / dir)) {
          if (f.is_regular_file()) files.push_back(f.path().filename().string());
        }
      }
      std::sort(files.begin(), files.end());
      for (const std::string& f : files) {
        cell += "<a href=\"" + HtmlEscape(dir + "/" + f) + "\">" + HtmlEscape(f) + "</a> ";
      }
    }
    html += "<tr><td>" + HtmlEscape(format) + "</td><td>" + cell + "</td></tr>";
  }
  page->RawHtml(html + "</table>\n");
}

}  // namespace

void WriteRunReport(const RunReportInputs& in) {
  HtmlReport page("igi-run report");
  page.Paragraph("Run folder: " + fs::absolute(in.out).string());
  StagesSection(in.out, &page);
  ResponseSection(in.out, &page);
  CalibrationSection(in.out, &page);
  CamerasSection(in.out, &page);
  ParametersSection(in.out, &page);
  PhotosSection(in.out, in.max_photos, &page);
  RelitSection(in.out, &page);
  DiagnosisSection(in.out, &page);
  ExportsSection(in.out, in.exports, &page);
  page.Write(in.out / "report.html");
}

namespace internal {

// Renders the solved scene: the first photos (their camera and lighting), and the first photo's
// camera under every lighting; then the page.
void ReportStage(const Context& ctx, StageRun* run) {
  const fs::path solved = ctx.Dir("04-solve") / "scene.json";
  recon::SceneLoadOptions load;
  load.load_geometry = load.check_images = false;
  const recon::Scene scene = recon::LoadScene(solved, load);
  const fs::path renders = run->dir() / "renders";
  fs::create_directories(renders);
  auto render = [&](const recon::Camera& cam, const recon::Lighting& l, const fs::path& file) {
    const int f = ReductionFactor(cam.width, cam.height, ctx.options.report_megapixels);
    std::vector<std::string> args = {solved.string(),
                                     "--camera",
                                     cam.name,
                                     "--lighting",
                                     l.name,
                                     "--spp",
                                     std::to_string(ctx.options.report_spp),
                                     "--width",
                                     std::to_string(cam.width / f),
                                     "--height",
                                     std::to_string(cam.height / f),
                                     "--out",
                                     file.string()};
    const auto threads = ThreadArgs(ctx);
    args.insert(args.end(), threads.begin(), threads.end());
    run->Tool("igi-render", args);
  };
  const int n = std::min<int>(ctx.options.report_photos, int(scene.photos.size()));
  for (int k = 0; k < n; ++k) {
    const recon::Photo& p = scene.photos[k];
    const fs::path file = renders / fmt::format("photo_{}.exr", k);
    render(scene.cameras[p.camera], scene.lightings[p.lighting], file);
    // The model as the photo records it (v = R(s · L), the render carrying the vignetting), so
    // that the figure and the residual compare like with like.
    if (p.exposure_scale != 1.0 || p.HasResponse()) {
      Image image = ReadImage(file);
      for (float& v : image.pixels) v = float(p.RecordedFromLinear(v * p.exposure_scale));
      WriteImage(file, image);
    }
  }
  if (!scene.photos.empty()) {
    const recon::Camera& cam = scene.cameras[scene.photos[0].camera];
    const int m = std::min<int>(ctx.options.report_lightings, int(scene.lightings.size()));
    for (int l = 0; l < m; ++l) {
      render(cam, scene.lightings[l], renders / ("relit_" + scene.lightings[l].name + ".exr"));
    }
  }
  // The solved scene for other renderers, each format in its own folder; a format that fails
  // is named on the page, the others kept.
  Json exports = Json::object();
  for (const char* format : {"radiance", "mitsuba", "gltf"}) {
    const fs::path dir = run->dir() / "export" / format;
    fs::remove_all(dir);
    try {
      run->Tool("igi-export", {solved.string(), "--format", format, "--out", dir.string()});
      exports[format] = {{"dir", fs::relative(dir, ctx.options.out).generic_string()}};
    } catch (const Error& e) {
      exports[format] = {{"error", e.Lines().front()}};
    }
  }
  run->details["exports"] = exports;
  WriteRunReport({ctx.options.out, ctx.options.report_photos, exports});
}

}  // namespace internal
}  // namespace igi::pipeline
