#include "solver/diagnose/diagnose.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <tuple>
#include <unordered_map>

#include "solver/diagnose/analysis_capture.h"
#include "solver/diagnose/diagnose_memory.h"
#include "solver/diagnose/effect.h"
#include "solver/diagnose/render_noise.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/inverse/scene_scale.h"
#include "solver/inverse/solve.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/memory.h"

namespace igi::diagnose {
namespace fs = std::filesystem;

namespace {

// Whether any material lacks a value for rendering (`key` empty) or lacks `key`.
bool HasUnknowns(const recon::Scene& scene, const std::string& key = "") {
  for (const recon::Material& m : scene.materials) {
    const std::vector<std::string> missing = m.MissingForRendering();
    if (key.empty() ? !missing.empty()
                    : std::find(missing.begin(), missing.end(), key) != missing.end()) {
      return true;
    }
  }
  return false;
}

struct ModelState {
  fs::path dir;
  fs::path model_file;  // the model's scene.json: the solved one, or the document as declared
  std::vector<std::string> solved_materials;  // the materials the document left without a value
  recon::Scene model;
  // The photos re-rendered (complete, except a trial's, rendered only where its held-out test
  // reads until it is applied: CompleteModel).
  Simulation sim;
  std::vector<PixelRecord> records;
  ResidualSums train, held;
};

// With the materials given, the values a step's refit solved (a found lobe's ρs and α, left to
// the solver by the step) are given from then on: each material the document left without a
// value takes the solved model's entry, so that later trials render it instead of solving it
// again.
void GiveSolvedValues(const ModelState& st, Json* declared) {
  const Json solved = recon::AbsoluteScenePaths(ReadJsonFile(st.model_file), st.dir);
  for (const std::string& name : st.solved_materials) {
    (*declared)["materials"][name] = solved["materials"][name];
  }
}

// Fits the declared document into `dir` (solves it when a material value is unknown: the
// materials the diagnosis solves, or a step's model left to the solver, such as a lobe found on a
// region whose albedo is given) and simulates it (only the pixels `only` marks, when given); with
// `with_records`, also builds its residual samples (only the kept model's are ever used; they
// need the complete simulation).
ModelState FitModel(const Json& declared, const MapMode& maps, const fs::path& dir,
                    const DiagnoseOptions& o, const PhotoSet& photos, bool with_records,
                    const PixelMasks* only = nullptr) {
  const auto t0 = std::chrono::steady_clock::now();
  ModelState st;
  st.dir = dir;
  fs::create_directories(dir);
  WriteJsonFile(dir / "declared.json", declared, 1);
  st.model_file = dir / "declared.json";
  const recon::Scene declared_scene = recon::LoadScene(st.model_file);
  for (const recon::Material& m : declared_scene.materials) {
    if (!m.MissingForRendering().empty()) st.solved_materials.push_back(m.name);
  }
  const bool solve = !st.solved_materials.empty();
  if (solve) {
    solver::SolveOptions so = o.solve;
    so.holdout_fraction = o.holdout_fraction;
    so.holdout_block_px = o.holdout_block_px;
    so.num_threads = o.num_threads;
    so.show_progress = false;
    so.albedo_maps = maps.maps;
    so.albedo_map_regions = maps.only;
    // Every pixel is an observation for the albedo maps' sake (DiagnoseOptions::solve); with
    // every albedo given (a lobe left to the solver) igi-solve's own stride does.
    if (!HasUnknowns(declared_scene, "rho_d")) {
      so.pixel_stride = std::max(so.pixel_stride, solver::SolveOptions{}.pixel_stride);
    }
    const solver::SolveSummary summary = solver::Solve(declared_scene, so, dir);
    solver::WriteSolveOutputs(summary, so, dir);
    st.model_file = dir / "scene.json";
  }
  recon::SceneLoadOptions lo;
  lo.require_complete_materials = true;
  st.model = recon::LoadScene(st.model_file, lo);
  const auto t1 = std::chrono::steady_clock::now();
  SimulatePhotos(st.model, o, o.seed, &st.sim, only);
  const auto t2 = std::chrono::steady_clock::now();
  if (with_records) st.records = BuildRecords(st.model, photos, st.sim.sims, o, &st.sim.variance);
  const auto t3 = std::chrono::steady_clock::now();
  using Seconds = std::chrono::duration<double>;
  spdlog::info(
      "igi-diagnose: {}: {}{:.1f} s simulating the photos{}{}", dir.filename().string(),
      solve ? fmt::format("{:.1f} s solving, ", Seconds(t1 - t0).count()) : "",
      Seconds(t2 - t1).count(), st.sim.Complete() ? "" : " (the held-out test's pixels)",
      with_records ? fmt::format(", {:.1f} s building records", Seconds(t3 - t2).count()) : "");
  const solver::PixelHoldout holdout{o.holdout_fraction, o.holdout_block_px, o.solve.holdout_seed};
  st.train = ResidualOverPhotos(photos, st.sim.sims, holdout, false);
  st.held = ResidualOverPhotos(photos, st.sim.sims, holdout, true);
  return st;
}

// Renders the pixels a trial's simulation lacks (it is being applied) and updates its residuals.
void CompleteModel(ModelState* st, const DiagnoseOptions& o, const PhotoSet& photos) {
  if (st->sim.Complete()) return;
  const auto t0 = std::chrono::steady_clock::now();
  SimulatePhotos(st->model, o, o.seed, &st->sim);
  spdlog::info("igi-diagnose: {}: {:.1f} s simulating the rest of the photos",
               st->dir.filename().string(),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  const solver::PixelHoldout holdout{o.holdout_fraction, o.holdout_block_px, o.solve.holdout_seed};
  st->train = ResidualOverPhotos(photos, st->sim.sims, holdout, false);
  st->held = ResidualOverPhotos(photos, st->sim.sims, holdout, true);
}

// Renders `st`'s model again, all of it, and rebuilds its records and residuals.
void RenderAgain(ModelState* st, const DiagnoseOptions& o, const PhotoSet& photos) {
  st->sim = Simulation{};
  SimulatePhotos(st->model, o, o.seed, &st->sim);
  st->records = BuildRecords(st->model, photos, st->sim.sims, o, &st->sim.variance);
  const solver::PixelHoldout holdout{o.holdout_fraction, o.holdout_block_px, o.solve.holdout_seed};
  st->train = ResidualOverPhotos(photos, st->sim.sims, holdout, false);
  st->held = ResidualOverPhotos(photos, st->sim.sims, holdout, true);
}

// The held-out gain of `after` over `before` (share of the squared error) and its significance
// with the held-out blocks as independent units (BlockGainZ; blocks the step left exactly as they
// were — same seed, same model there — do not count). Each pixel's squared error is counted less
// its simulation's Monte Carlo variance (ModelState::sim_var), so that a model whose render is
// merely less noisy earns nothing (the demo's false ambient_light step: an exact ambient term and
// lower albedos cut its 16-spp renders' variance by a third, which read as a 2–6 % gain).
// `only` (when given) selects the blocks (photo, block x, block y) that count, and the z is then
// the signed-rank z of their pixels' gains (SignedRankZ: a pose error's edges) or their blocks'
// BlockGainZ, Bonferroni-combined (EitherZ).
// With `pixel_units` false, `only` just selects the blocks and the z is BlockGainZ over them.
std::pair<double, double> HeldOutGain(const PhotoSet& photos, const ModelState& before_state,
                                      const ModelState& after_state, const solver::PixelHoldout& h,
                                      const BlockFilter& only = nullptr, bool pixel_units = true) {
  const std::vector<Image>& before = before_state.sim.sims;
  const std::vector<Image>& after = after_state.sim.sims;
  auto var = [](const ModelState& s, size_t i, size_t k) {
    const std::vector<Image>& v = s.sim.variance;
    return i < v.size() && k < v[i].pixels.size() ? double(v[i].pixels[k]) : 0.0;
  };
  // Per block: gain and error before.
  std::unordered_map<int64_t, std::pair<double, double>> gain;
  double total_before = 0, total_gain = 0;
  std::vector<double> pixel_gains;
  for (size_t i = 0; i < before.size(); ++i) {
    const Image& rec = photos.recorded[i];
    for (int y = 0; y < rec.height; ++y) {
      for (int x = 0; x < rec.width; ++x) {
        if (photos.valid[i].at(x, y, 0) < 0.5f || !h.HeldOut(int(i), x, y)) continue;
        if (only && !only(i, x / h.block_px, y / h.block_px)) continue;
        double g = 0, e = 0;
        for (int c = 0; c < 3; ++c) {
          const double p = rec.at(x, y, c), b = before[i].at(x, y, c), a = after[i].at(x, y, c);
          if (!std::isfinite(a) || !std::isfinite(b)) continue;
          const size_t k = (size_t(y) * before[i].width + x) * before[i].channels + c;
          // The error before stays raw (the gain's scale and the blocks' weights); the gain is
          // the change of squared error less the change of the renders' variance.
          const double eb = (b - p) * (b - p), ea = (a - p) * (a - p);
          e += eb;
          g += eb - ea - (var(before_state, i, k) - var(after_state, i, k));
        }
        if (only) pixel_gains.push_back(g);
        auto& acc = gain[(int64_t(i) << 40) + (int64_t(y / h.block_px) << 20) + x / h.block_px];
        acc.first += g;
        acc.second += e;
        total_before += e;
        total_gain += g;
      }
    }
  }
  std::vector<std::pair<double, double>> changed;
  for (const auto& [k, ge] : gain) {
    if (ge.second > 0 && ge.first != 0) changed.push_back(ge);
  }
  if (only && pixel_units) {
    // Edge blocks: the signed-rank z of their pixels' gains, or their blocks' BlockGainZ, which
    // counts a gain concentrated on a few sharp edges where it is (a 1.2-pixel turn of a view of
    // the RADIANCE room: held-out residual² down 13 %, the pixels' z 1.5).
    const double gain_share = total_before > 0 ? total_gain / total_before : 0;
    return {gain_share, EitherZ(SignedRankZ(pixel_gains), BlockGainZ(changed))};
  }
  if (changed.size() < 2 || !(total_before > 0)) return {0, 0};
  return {total_gain / total_before, BlockGainZ(changed)};
}

// The white part of the residual, from differences of horizontally adjacent valid pixels on the
// same photo: what no smooth model can explain (photo noise plus render noise).
double NoiseFloor(const PhotoSet& photos, const std::vector<Image>& sims) {
  double num = 0, den = 0;
  for (size_t i = 0; i < sims.size(); ++i) {
    const Image& rec = photos.recorded[i];
    for (int y = 0; y < rec.height; ++y) {
      for (int x = 0; x + 1 < rec.width; ++x) {
        if (photos.valid[i].at(x, y, 0) < 0.5f || photos.valid[i].at(x + 1, y, 0) < 0.5f) continue;
        for (int c = 0; c < 3; ++c) {
          const double e1 = sims[i].at(x, y, c) - rec.at(x, y, c);
          const double e2 = sims[i].at(x + 1, y, c) - rec.at(x + 1, y, c);
          if (!std::isfinite(e1) || !std::isfinite(e2)) continue;
          num += 0.5 * (e1 - e2) * (e1 - e2);
          den +=
              0.5 * (rec.at(x, y, c) * rec.at(x, y, c) + rec.at(x + 1, y, c) * rec.at(x + 1, y, c));
        }
      }
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0;
}

// The grid of a trial's fitted pixels (HeldOutTestMasks): every kTrialGrid-th pixel in x and y.
constexpr int kTrialGrid = 8;

// `sims` where `trial` (a trial's partial simulation) is rendered, NaN elsewhere.
std::vector<Image> RenderedPart(const std::vector<Image>& sims, const std::vector<Image>& trial) {
  std::vector<Image> out = sims;
  for (size_t i = 0; i < out.size() && i < trial.size(); ++i) {
    Image& im = out[i];
    for (int y = 0; y < im.height; ++y) {
      for (int x = 0; x < im.width; ++x) {
        if (std::isfinite(trial[i].at(x, y, 0))) continue;
        for (int c = 0; c < im.channels; ++c) {
          im.at(x, y, c) = std::numeric_limits<float>::quiet_NaN();
        }
      }
    }
  }
  return out;
}

// The fitted pixels' residual of `sims` over the grid of kTrialGrid where `trial` is rendered
// (ResidualOverPhotos' sums, on those pixels only).
ResidualSums GridResidual(const PhotoSet& photos, const std::vector<Image>& sims,
                          const std::vector<Image>& trial, const solver::PixelHoldout& holdout) {
  ResidualSums s;
  for (size_t i = 0; i < sims.size() && i < trial.size(); ++i) {
    const Image& rec = photos.recorded[i];
    for (int y = 0; y < rec.height; y += kTrialGrid) {
      for (int x = 0; x < rec.width; x += kTrialGrid) {
        if (photos.valid[i].at(x, y, 0) < 0.5f || holdout.HeldOut(int(i), x, y) ||
            !std::isfinite(trial[i].at(x, y, 0))) {
          continue;
        }
        s.AddPixel(rec, sims[i], x, y);
      }
    }
  }
  return s;
}

Image ResidualImage(const PhotoSet& photos, const std::vector<Image>& sims, size_t i) {
  const Image& rec = photos.recorded[i];
  Image out(rec.width, rec.height, 3);
  for (int y = 0; y < rec.height; ++y) {
    for (int x = 0; x < rec.width; ++x) {
      const bool ok = photos.valid[i].at(x, y, 0) > 0.5f;
      for (int c = 0; c < 3; ++c) {
        const float d = sims[i].at(x, y, c) - rec.at(x, y, c);
        out.at(x, y, c) = ok && std::isfinite(d) ? d : 0.0f;
      }
    }
  }
  return out;
}

// Residual per (photo, region) on the held-out records, against the noise floor.
Json Unexplained(const ModelState& st, double floor) {
  struct Acc {
    double err = 0, photo = 0;
    int n = 0;
  };
  std::map<std::pair<int, int>, Acc> acc;
  for (const PixelRecord& r : st.records) {
    Acc& a = acc[{r.photo, r.region}];
    a.err += double((r.sim - r.recorded).squaredNorm());
    a.photo += double(r.recorded.squaredNorm());
    ++a.n;
  }
  Json out = Json::array();
  for (const auto& [key, a] : acc) {
    if (a.n < 20 || !(a.photo > 0)) continue;
    const double rel = std::sqrt(a.err / a.photo);
    if (rel < 1.5 * floor) continue;
    out.push_back({{"where", fmt::format("photo {}, region {}",
                                         st.model.photos[key.first].file.filename().string(),
                                         st.model.materials[key.second].name)},
                   {"residual", rel},
                   {"samples", a.n}});
  }
  std::sort(out.begin(), out.end(), [](const Json& a, const Json& b) {
    return a["residual"].get<double>() > b["residual"].get<double>();
  });
  if (out.size() > 12) out.erase(out.begin() + 12, out.end());
  return out;
}

// Surface cell for the albedo nuisance of regions with maps: the scene's length scale / 96
// (igi-solve's patch size).
double CellSize(const recon::Scene& model) {
  const double scale = solver::MeasureSceneScale(model).scale_m;
  return scale > 0 ? std::max(1e-3, scale / 96) : 0.05;
}

// The photo whose held-out residual the step reduced most (for the report's images).
size_t MostImprovedPhoto(const PhotoSet& photos, const std::vector<Image>& before,
                         const std::vector<Image>& after) {
  size_t best = 0;
  double best_gain = -1e300;
  for (size_t i = 0; i < before.size(); ++i) {
    double g = 0;
    const Image& rec = photos.recorded[i];
    for (size_t k = 0; k < rec.pixels.size(); ++k) {
      const double p = rec.pixels[k], b = before[i].pixels[k], a = after[i].pixels[k];
      if (std::isfinite(a) && std::isfinite(b) && photos.valid[i].pixels[k / 3] > 0.5f) {
        g += (b - p) * (b - p) - (a - p) * (a - p);
      }
    }
    if (g > best_gain) best_gain = g, best = i;
  }
  return best;
}

// Diagnoses `scene` as it is (the analysis capture, when the photos were reduced).
DiagnosisSummary DiagnoseCapture(const recon::Scene& scene, DiagnoseOptions o,
                                 const fs::path& out_dir) {
  DiagnosisSummary sum;
  PhotoSet photos = LoadPhotoSet(scene);  // valid pixels; a step may mask more
  const bool solve = HasUnknowns(scene);
  sum.solved = solve;
  Json declared = recon::AbsoluteScenePaths(scene.document, scene.dir);
  const solver::PixelHoldout holdout{o.holdout_fraction, o.holdout_block_px, o.solve.holdout_seed};
  // A trial's refit is rendered only where its held-out test reads (and on a sparse grid for its
  // fitted pixels' residual), and completed only when it is applied: most trials are rejected
  // (or lose to a better one), and their renders were most of a diagnosis's time.
  const PixelMasks test_masks = HeldOutTestMasks(scene, holdout, kTrialGrid);

  // Albedo maps are themselves a model to earn: the baseline (when solving) has constant
  // albedos per region, so that a map cannot absorb an effect of the image or the lights before
  // it is found; an effect's step (albedo_texture) adds them.
  MapMode maps{solve ? solver::AlbedoMaps::kNone : solver::AlbedoMaps::kAuto, {}};
  spdlog::info("igi-diagnose: fitting the baseline model{}", solve ? " (solving materials)" : "");
  ModelState st = FitModel(declared, maps, out_dir / "steps" / "00-baseline", o, photos, true);
  const int spp_max = MaxSpp(o, photos);
  if (spp_max > o.spp) {
    // The paths the tests can afford: the baseline rendered again at the paths chosen from the
    // photos' noise, and every later render at them.
    const RenderNoise noise = ChooseSpp(photos, st.sim, o.spp, spp_max, o.render_noise_share);
    sum.render_noise = RenderNoiseJson(noise, o.render_noise_share);
    spdlog::info(
        "igi-diagnose: photo noise {:.3f}, render noise {:.3f} at {} paths per pixel: rendering "
        "at {}",
        std::sqrt(noise.photo), std::sqrt(noise.render), noise.spp_measured, noise.spp);
    if (noise.spp > o.spp) {
      o.spp = noise.spp;
      RenderAgain(&st, o, photos);
    }
  }
  sum.baseline_residual = st.train.Relative();
  sum.baseline_held_out = st.held.Relative();
  spdlog::info("igi-diagnose: baseline residual {:.4f} (held out {:.4f})", sum.baseline_residual,
               sum.baseline_held_out);
  const std::vector<std::unique_ptr<Effect>> effects = MakeEffects();
  // The albedo nuisance's cell, from the baseline's geometry (the steps add no room to it).
  const double cell = CellSize(st.model);
  // The current model as the effects see it.
  auto view = [&]() {
    return DiagnosisModel{scene,   st.model, declared, photos, st.sim.sims, st.records,
                          holdout, o,        maps,     solve,  cell,        out_dir};
  };
  std::vector<std::string> kept_effects, rejected;
  int attempt = 0;
  // A candidate's trial, recorded, not yet applied.
  struct Trial {
    DiagnosisStep step;
    Json next;     // the refitted document
    MapMode maps;  // its albedo maps
    ModelState state;
    double gain = 0;
    // The photos' valid pixels after the step, when it changes them.
    std::optional<PhotoSet> photos;
  };
  // Refits with candidate `c` as its effect plans the trial, and judges the held-out residual.
  auto try_step = [&](CandidateResult c) {
    spdlog::info("igi-diagnose: trying {} (predicted held-out gain {:.1f}%, z {:.1f})", c.effect,
                 100 * c.Gain(), c.z);
    Effect* effect = FindEffect(effects, c.effect);
    const DiagnosisModel m = view();
    Trial t;
    TrialPlan plan = effect->PlanTrial(&c, m);
    t.next = std::move(plan.document);
    t.maps = std::move(plan.maps);
    t.photos = std::move(plan.photos);
    DiagnosisStep& ds = t.step;
    ds.residual_before = st.train.Relative();
    ds.held_out_before = st.held.Relative();
    ds.model_dir = out_dir / "steps" / fmt::format("{:02d}-{}", ++attempt, c.effect);
    const PhotoSet& ph = t.photos ? *t.photos : photos;
    try {
      t.state = FitModel(t.next, t.maps, ds.model_dir, o, ph, false, &test_masks);
    } catch (const Error& e) {
      ds.verdict = std::string("the refit failed: ") + e.what();
      ds.candidate = std::move(c);
      return t;
    }
    if (std::optional<Refinement> r = effect->Refine(c, t.next, t.state.model, t.state.sim, m)) {
      try {
        ModelState refined =
            FitModel(r->document, t.maps, ds.model_dir / "refined", o, ph, false, &test_masks);
        c = std::move(r->candidate);
        t.next = std::move(r->document);
        t.state = std::move(refined);
        ds.model_dir = t.state.dir;
      } catch (const Error& err) {
        spdlog::warn("igi-diagnose: {}'s refined refit failed: {}", c.effect, err.what());
      }
    }
    // Until the step is applied (settle), the fitted pixels' residual is over the grid of
    // HeldOutTestMasks only, before and after alike.
    ds.residual_before = GridResidual(ph, st.sim.sims, t.state.sim.sims, holdout).Relative();
    ds.residual_after = GridResidual(ph, t.state.sim.sims, t.state.sim.sims, holdout).Relative();
    ds.held_out_after = t.state.held.Relative();
    // The gain is over every held-out block; its significance over the effect's scope.
    const HeldOutScope scope = effect->Scope(c, m);
    HeldOutOutcome outcome;
    std::tie(outcome.gain, outcome.z) = HeldOutGain(ph, st, t.state, holdout);
    if (scope.blocks) {
      outcome.z = HeldOutGain(ph, st, t.state, holdout, scope.blocks, scope.pixel_units).second;
    }
    const Judgement j = effect->Judge(c, outcome, scope, o);
    t.gain = j.gain;
    ds.z = j.z;
    ds.kept = j.kept;
    ds.verdict = j.verdict;
    spdlog::info("igi-diagnose: {} {}", c.effect, ds.verdict);
    if (ds.kept) effect->DescribeKept(&c, t.state.model);
    ds.candidate = std::move(c);
    return t;
  };
  // The step's residual images (photo where it helped most), and, for the step applied, the
  // complete simulation and the fitted pixels' residual over all of them.
  auto finish = [&](Trial& t, bool applied) {
    DiagnosisStep& ds = t.step;
    const PhotoSet& ph = t.photos ? *t.photos : photos;
    if (applied) {
      CompleteModel(&t.state, o, ph);
      ds.residual_before = st.train.Relative();
      ds.residual_after = t.state.train.Relative();
    } else {
      ds.residual_pixels = fmt::format("every {}th pixel", kTrialGrid);
    }
    if (t.state.sim.sims.empty()) return;  // the refit failed
    const size_t img = MostImprovedPhoto(photos, st.sim.sims, t.state.sim.sims);
    ds.image_photo = scene.photos[img].file.filename().string();
    // A step not applied is shown where it is rendered (its held-out test's pixels), before and
    // after alike.
    const std::vector<Image> before =
        applied ? st.sim.sims : RenderedPart(st.sim.sims, t.state.sim.sims);
    ds.residual_before_image = ResidualImage(photos, before, img);
    ds.residual_after_image = ResidualImage(ph, t.state.sim.sims, img);
  };
  // Applies the best of `trials` that passed; records the others. Returns whether one was kept.
  auto settle = [&](std::vector<Trial>& trials) {
    int best = -1;
    for (int i = 0; i < int(trials.size()); ++i) {
      if (trials[i].step.kept && (best < 0 || trials[i].gain > trials[best].gain)) best = i;
    }
    for (int i = 0; i < int(trials.size()); ++i) finish(trials[i], i == best);
    for (int i = 0; i < int(trials.size()); ++i) {
      DiagnosisStep& ds = trials[i].step;
      // A step that passed but explained less than the best stays a candidate of the next round
      // (two hidden effects: both pass the first round, one is applied, the other comes next).
      if (ds.kept && i != best) {
        ds.kept = false;
        ds.verdict +=
            fmt::format("; not applied: {} explained more", trials[best].step.candidate.effect);
        continue;
      }
      (i == best ? kept_effects : rejected).push_back(ds.candidate.Key());
    }
    if (best >= 0) {
      // A verdict is on a model: once a step changes it, the candidates rejected so far are
      // judged again (an effect fitted while a bigger one was unmodelled — vignetting beside a
      // photo's exposure — can earn its place once that one is in the model).
      rejected.clear();
      if (trials[best].photos) photos = std::move(*trials[best].photos);
      declared = std::move(trials[best].next);
      st = std::move(trials[best].state);
      if (!solve) GiveSolvedValues(st, &declared);
      st.records = BuildRecords(st.model, photos, st.sim.sims, o, &st.sim.variance);
      maps = trials[best].maps;
    }
    for (Trial& t : trials) sum.steps.push_back(std::move(t.step));
    return best >= 0;
  };
  // Tries candidate `c` alone and applies it when it passes.
  auto try_alone = [&](CandidateResult c) {
    std::vector<Trial> one;
    one.push_back(try_step(std::move(c)));
    return settle(one);
  };
  for (int step = 0; step < o.max_steps; ++step) {
    // The candidates tried alone before the round's others (a missing object before any albedo
    // map; a texture before any smooth effect, on every model until it is found).
    for (const auto& e : effects) {
      if (std::optional<CandidateResult> c = e->TryFirst(view(), step)) try_alone(std::move(*c));
    }
    std::vector<std::string> excluded = kept_effects;
    excluded.insert(excluded.end(), rejected.begin(), rejected.end());
    const KeyFilter allowed = [&](const std::string& key) {
      return std::find(excluded.begin(), excluded.end(), key) == excluded.end();
    };
    CandidateContext cx{st.model, declared, solve, cell, o.holdout_block_px};
    cx.photos = &photos;
    cx.sims = &st.sim.sims;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<CandidateResult> cands = EvaluateCandidates(effects, cx, st.records, excluded);
    for (const auto& e : effects) {
      if (std::optional<CandidateResult> c = e->Locate(view(), allowed)) {
        cands.push_back(std::move(*c));
      }
    }
    sum.last_candidates = cands;
    spdlog::info("igi-diagnose: {} candidates evaluated in {:.1f} s", cands.size(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    // By the predicted relative gain, the two best of different effects first (RankForTrials).
    std::vector<CandidateResult*> ranked =
        RankForTrials(cands, o.candidate_min_gain, o.candidate_min_z);
    for (const CandidateResult* c : ranked) {
      spdlog::debug("igi-diagnose: candidate {} predicted held-out gain {:.1f}%, z {:.1f}",
                    c->effect, 100 * c->Gain(), c->z);
    }
    std::vector<Trial> trials;
    for (size_t k = 0; k < ranked.size() && int(k) < o.max_tries; ++k) {
      trials.push_back(try_step(*ranked[k]));
      const bool any =
          std::any_of(trials.begin(), trials.end(), [](const Trial& t) { return t.step.kept; });
      if (trials.size() >= 2 && any) break;
    }
    bool kept = settle(trials);
    // The last resort of a round none of whose candidates passed.
    for (const auto& e : effects) {
      if (kept) break;
      if (std::optional<CandidateResult> c = e->TryLast(view())) kept = try_alone(std::move(*c));
    }
    if (!kept) break;
  }
  sum.final_residual = st.train.Relative();
  sum.final_held_out = st.held.Relative();
  sum.noise_floor = NoiseFloor(photos, st.sim.sims);
  sum.unexplained = Unexplained(st, sum.noise_floor);
  sum.final_model_dir = st.dir;
  sum.final_scene = recon::RelativeScenePaths(
      recon::AbsoluteScenePaths(ReadJsonFile(st.model_file), st.dir), out_dir);
  if (!scene.photos.empty()) {
    Image render = st.sim.sims[0];
    sum.final_images = {{photos.recorded[0], "photo " + scene.photos[0].file.filename().string()},
                        {render, "re-render of the improved model"},
                        {ResidualImage(photos, st.sim.sims, 0), "residual (render − photo)"}};
  }
  return sum;
}

}  // namespace

DiagnosisSummary Diagnose(const recon::Scene& scene, const DiagnoseOptions& o,
                          const fs::path& out_dir) {
  o.Validate();
  const auto start = std::chrono::steady_clock::now();
  // The memory plan before anything is read or written: the solves get what the diagnosis
  // itself does not hold.
  const DiagnoseMemoryPlan memory = PlanDiagnoseMemory(scene, o);
  DiagnoseOptions inner = o;
  inner.solve.memory_budget = memory.solve_budget_bytes / kGiB;
  const AnalysisCapture capture =
      ReduceCapture(scene, recon::AbsoluteScenePaths(scene.document, scene.dir),
                    o.analysis_megapixels, out_dir / "analysis", o.show_progress);
  DiagnosisSummary sum;
  if (!capture.reduced) {
    sum = DiagnoseCapture(scene, inner, out_dir);
  } else {
    for (const auto& [name, r] : capture.cameras) {
      spdlog::info("igi-diagnose: camera {}'s photos analysed as {}x{} blocks' means ({}x{})", name,
                   r.factor, r.factor, r.width, r.height);
    }
    sum = DiagnoseCapture(recon::LoadScene(capture.scene_file), inner, out_dir);
    // The improved scene names the declared photos and intrinsics: what was fitted on the
    // reduced capture holds at full size.
    sum.final_scene = recon::RelativeScenePaths(
        AtDeclaredSize(recon::AbsoluteScenePaths(sum.final_scene, out_dir), scene), out_dir);
    sum.analysis = AnalysisCaptureJson(capture, o.analysis_megapixels);
  }
  sum.memory = DiagnoseMemoryJson(memory, PeakResidentBytes());
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return sum;
}

}  // namespace igi::diagnose
