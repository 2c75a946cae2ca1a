// ambient_light (docs/diagnose-effects.md): light from no declared source, the same from every
// direction.

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"

namespace igi::diagnose {

namespace {

using Eigen::Vector3d;

// What an ambient light of unit radiance adds at each record, as the photo sees it: the radiance
// reflected toward the camera (ρd·1 at the point, plus what the room reflects of it: every bounce,
// rendered with the model's materials and no other light; emitters made black), times the photo's
// exposure scale and the camera's vignetting. 16 paths per record: the first vertex is exact for
// the diffuse term (the renderer evaluates ambient light exactly), the bounces are averaged.
std::vector<Eigen::Vector3f> UnitAmbientResponse(const recon::Scene& model,
                                                 const std::vector<PixelRecord>& records) {
  recon::Scene unit = model;
  recon::Light ambient;
  ambient.name = "unit_ambient";
  ambient.type = recon::LightType::kAmbient;
  ambient.radiance = Eigen::Vector3d::Ones();
  unit.lights = {ambient};
  unit.lightings = {recon::Lighting{"unit_ambient", {0}}};
  for (recon::Material& m : unit.materials) {
    if (m.brdf == recon::BrdfModel::kEmitter) m.brdf = recon::BrdfModel::kBlack;
  }
  const render::Renderer renderer(unit, 0);
  std::vector<Eigen::Vector3f> out(records.size(), Eigen::Vector3f::Zero());
  ParallelFor(0, int64_t(records.size()), [&](int64_t i) {
    const PixelRecord& r = records[i];
    const recon::Photo& photo = model.photos[r.photo];
    const recon::Camera& camera = model.cameras[photo.camera];
    const Eigen::Vector3d center = camera.CenterInWorld();
    const Eigen::Vector3d dir = r.position.cast<double>() - center;
    if (!(dir.norm() > 0)) return;
    const Eigen::Vector3d l = renderer.ReflectedRadiance(center, dir, 16, uint64_t(i) + 1);
    const double k =
        photo.exposure_scale * camera.VignettingFactor(Eigen::Vector2d(r.x + 0.5, r.y + 0.5));
    out[i] = (l * k).cast<float>();
  });
  return out;
}

// The first reflection alone of a unit ambient light at each record: the directional albedo of
// the point's BRDF (the record's ρd, its region's lobe) toward the camera, ∫ f cos θi dωi over the
// hemisphere (the ambient light is never occluded), times the photo's exposure scale and the
// camera's vignetting. 64 stratified BRDF samples (exact for the diffuse term).
std::vector<Eigen::Vector3f> UnitAmbientFirstReflection(const recon::Scene& model,
                                                        const std::vector<PixelRecord>& records) {
  constexpr int kSide = 8;
  std::vector<render::ShadingMaterial> materials;
  for (const recon::Material& m : model.materials)
    materials.push_back(render::MakeShadingMaterial(m));
  std::vector<Eigen::Vector3f> out(records.size(), Eigen::Vector3f::Zero());
  ParallelFor(0, int64_t(records.size()), [&](int64_t i) {
    const PixelRecord& r = records[i];
    if (r.region < 0 || r.region >= int(materials.size())) return;
    const render::ShadingMaterial& sm = materials[r.region];
    if (!recon::IsReflective(sm.model)) return;
    render::BrdfParams params = sm.params;
    params.rho_d = r.albedo.cast<double>();
    const Vector3d n = r.normal.cast<double>();
    const render::Frame frame = recon::IsAnisotropic(params.model) && sm.tangent
                                    ? render::Frame::FromNormalTangent(n, *sm.tangent)
                                    : render::Frame::FromNormal(n);
    const Vector3d wo = frame.ToLocal(r.view.cast<double>());
    render::Pcg32 rng(uint64_t(i) + 1, 17);
    Vector3d sum = Vector3d::Zero();
    for (int a = 0; a < kSide; ++a) {
      for (int b = 0; b < kSide; ++b) {
        const Eigen::Vector2d u((a + rng.UniformDouble()) / kSide,
                                (b + rng.UniformDouble()) / kSide);
        const render::BrdfSample smp = render::SampleBrdf(params, wo, rng.UniformDouble(), u);
        if (smp.Valid()) sum += smp.weight;
      }
    }
    const recon::Photo& photo = model.photos[r.photo];
    const recon::Camera& camera = model.cameras[photo.camera];
    const double k =
        photo.exposure_scale * camera.VignettingFactor(Eigen::Vector2d(r.x + 0.5, r.y + 0.5));
    out[i] = (sum * (k / (kSide * kSide))).cast<float>();
  });
  return out;
}

}  // namespace

CandidateResult AmbientLight(const CandidateContext& cx, const ResidualFitter& f) {
  CandidateResult out;
  out.effect = "ambient_light";
  // An ambient light of radiance L adds L times the unit light's response where it lands (the
  // point's ρd and what the lit room reflects of it), in shadow too. With the materials solved,
  // the first reflection only: the solve has put the ambient light's share of every surface's
  // radiance into its albedo, so the model's interreflections already carry the light the
  // ambient term sends around the room (an albedo too high by the factor k lights the others as
  // the true albedo under the lamp and the ambient light together); what the model lacks is the
  // ambient light's own reflection at the point, against which the re-solve then lowers the
  // albedos. The full response there counts the bounced light twice: on the suite's capture
  // it fitted 0.12 for the true 0.4.
  const bool first_only = f.nuisance();
  const std::vector<Eigen::Vector3f> response =
      first_only ? UnitAmbientFirstReflection(cx.model, f.records())
                 : UnitAmbientResponse(cx.model, f.records());
  const PixelRecord* first = f.records().data();
  // The response is rendered on its own paths: no part of the simulation's noise (a plain fit
  // would credit it with the noise of the sim it partly replaces when the albedos are refitted).
  const ResidualFit fit = f.FitNoiseFreeBasis(
      3, [&](const PixelRecord& r, int c, double* b) { b[c] = response[&r - first][c]; });
  if (fit.coef.size() == 0) return out;
  const Eigen::Vector3d radiance(fit.coef[0], fit.coef[1], fit.coef[2]);
  if (!(radiance.minCoeff() > 0)) {
    out.note = "the offset that fits is negative in some channel: not an ambient light";
    return out;
  }
  FillScores(fit, &out);
  out.params = {{"radiance", {radiance.x(), radiance.y(), radiance.z()}}};
  out.where = {{"photos", PhotoFiles(cx.model)}, {"frame", "surface (smooth offset)"}};
  out.num_params = 3;
  double mean_sim = 0;
  int n = 0;
  for (const PixelRecord& r : f.records()) mean_sim += r.sim.mean(), ++n;
  out.evidence = fmt::format(
      "a smooth offset proportional to the albedo everywhere, in shadow too, that no change of "
      "the albedos explains: the photos are brighter than the model by what an ambient light of "
      "radiance {:.4g} adds ({}; mean model radiance {:.4g}), light from no declared source",
      radiance.mean(),
      first_only ? "its first reflection, the solved albedos carrying its share of the room's "
                   "interreflections"
                 : "on each surface and through the room's bounces",
      n ? mean_sim / n : 0.0);
  out.valid = true;
  return out;
}

namespace {

class AmbientLightEffect final : public Effect {
 public:
  std::string Name() const override { return "ambient_light"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    if (allowed(Name())) tasks->push_back({[&cx, &f = in.fitter] { return AmbientLight(cx, f); }});
  }
  // A new "ambient" light (a name no light has) of the fitted radiance, in every lighting.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    doc->AddLightToEveryLighting("ambient",
                                 {{"type", "ambient"}, {"radiance", c.params.at("radiance")}});
  }
};

}  // namespace

std::unique_ptr<Effect> MakeAmbientLight() { return std::make_unique<AmbientLightEffect>(); }

}  // namespace igi::diagnose
