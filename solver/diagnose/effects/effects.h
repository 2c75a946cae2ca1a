#pragma once
// The effects igi-diagnose models (docs/diagnose-effects.md), one file each in this folder, and
// the fits their files expose for tests. Each candidate fit studies the residual of the current
// model in the frame where its physics shows itself, fits a model of it on the fitted (not
// held-out) records, and predicts the residual it would leave on the held-out ones (candidates.h).
// Fits are linear in their amplitudes; nonlinear parameters (a response exponent, an emission axis,
// a lobe width) are searched on a grid, with the global scale free as a nuisance where the
// materials are solved (the refit's albedos absorb it).
//
// An effect's Write puts a candidate's params into the scene document; the params name
// everything it writes, so diagnosis.json's steps say what each did to the scene.

#include <memory>
#include <vector>

#include "solver/diagnose/effect.h"
#include "solver/diagnose/residual_fit.h"

namespace igi::diagnose {

// ---------------------------------------------------------------- the effects (MakeEffects)
std::unique_ptr<Effect> MakeMissingGeometry();        // missing_geometry.cpp
std::unique_ptr<Effect> MakeAlbedoTexture();          // albedo_texture.cpp
std::unique_ptr<Effect> MakeExposureScale();          // exposure_scale.cpp
std::unique_ptr<Effect> MakeVignetting();             // vignetting.cpp
std::unique_ptr<Effect> MakeCameraResponse();         // camera_response.cpp
std::unique_ptr<Effect> MakeAmbientLight();           // ambient_light.cpp
std::unique_ptr<Effect> MakeLightEmissionProfile();   // light_emission_profile.cpp
std::unique_ptr<Effect> MakeLightIntensity();         // light_intensity.cpp
std::unique_ptr<Effect> MakeLightSourceExtent();      // light_source_extent.cpp
std::unique_ptr<Effect> MakeSpecularLobeShape();      // specular_lobe_shape.cpp
std::unique_ptr<Effect> MakeFresnel();                // fresnel.cpp
std::unique_ptr<Effect> MakeAnisotropicReflection();  // anisotropic_reflection.cpp
std::unique_ptr<Effect> MakePoseError();              // pose_error.cpp
std::unique_ptr<Effect> MakeSpecularReflection();     // specular_reflection.cpp
std::unique_ptr<Effect> MakeDiffuseShape();           // diffuse_shape.cpp

// ---------------------------------------------------------------- their fits
// exposure_scale: one scale per photo, relative to its lighting's photos (materials solved) or
// to the photo at the median (one light alone in every photo), or free.
CandidateResult ExposureScale(const CandidateContext& cx, const ResidualFitter& f);

// vignetting: an image-fixed radial fall-off 1 + k1 r² + k2 r², the same in every photo.
CandidateResult Vignetting(const CandidateContext& cx, const ResidualFitter& f);

// camera_response: the photos follow the model's value through a power about a reference,
// ref·(v/ref)^e (photo_model.h). The exponent is searched on the residual with a fit corrected
// for the renders' noise in the model's value (ResidualFitter::FitNoisyBasis).
CandidateResult Response(const CandidateContext& cx, const ResidualFitter& f);

// light_emission_profile for light `light` (index into model.lights): the light's direct term
// becomes cos^n of the angle from an axis (a "spot" with a cos_power profile). The axis and n are
// searched with a camera response as a nuisance (so that a response the photos also hide does not
// bend them) and scored without it. The search runs on `search`'s records when given (a subsample
// of the fitter's), the final fit and its scores on the fitter's.
CandidateResult EmissionProfile(const CandidateContext& cx, const ResidualFitter& f, int light,
                                const RecordSubset* search = nullptr);

// light_intensity of light `light`: a scale of its direct term (and of everything in the photos
// its light alone makes), outside the records where its size shows.
CandidateResult LightIntensity(const CandidateContext& cx, const ResidualFitter& f, int light);

// specular_reflection for `region` (declared diffuse): a Ward lobe whose ρs and α best explain
// the residual. Written as brdf "ward", with the fitted ρs and α where the region's albedo is
// declared (nothing is solved then), without them otherwise (igi-solve fits them).
CandidateResult SpecularReflection(const CandidateContext& cx, const ResidualFitter& f, int region);

// specular_lobe_shape (the region's isotropic lobe for another of kLobeShapes: ward, ward_gmd,
// beckmann, ggx; the one that explains most) and fresnel (a Ward lobe -> *_fresnel) on glossy
// region `region`: the change of its specular term. With the materials given (the refit keeps
// ρs and α) the alternative lobe less the current one at the same values, with an amplitude that
// must stay near 1; with them solved (the refit re-solves ρs and α) the current lobe is replaced
// by the alternative at a searched α' with a free ρs scale, and credited only with what it
// explains beyond the current model re-fitted the same way. fresnel also searches the index.
CandidateResult LobeChange(const CandidateContext& cx, const ResidualFitter& f, int region,
                           bool fresnel);

// diffuse_shape on `regions` (Lambert's diffuse term; one shape for all): Oren–Nayar's term or
// the coated base's in its place, whichever explains more (params "to"). With the materials
// solved, the direct light's diffuse reflection is split into Lambert's column per region and
// the shape's own column, credited with what the latter explains beyond re-fitted albedos, σ
// from the fitted ratio B/A (OrenNayarSigmaOfRatio); with them given, the change ρd·((A − 1)·E +
// B·G)/π at a grid of σ, or ρd·(C − E)/π, with its amplitude near 1.
CandidateResult DiffuseShape(const CandidateContext& cx, const ResidualFitter& f,
                             const std::vector<int>& regions);
// The σ whose Oren–Nayar B(σ)/A(σ) is `b_over_a` (0 when it is not positive, 1 beyond B/A at 1).
double OrenNayarSigmaOfRatio(double b_over_a);

// The colourless specular factor S of isotropic model `model` at roughness `alpha`
// (solver/render/brdf.h), for a record's world-frame normal, view and light directions.
double IsotropicLobe(recon::BrdfModel model, double alpha, const Eigen::Vector3f& n,
                     const Eigen::Vector3f& wo, const Eigen::Vector3f& wi);

// anisotropic_reflection of region `region` (a ward / ward_gmd model, with or without _fresnel,
// and complete values in cx.model): a glossy region whose highlight is stretched along a surface
// direction. Studied in the region's tangent frame (the azimuth of the half vector around the
// normal): the region's lobe ρs·S(α) is replaced by k·ρs·S_aniso(t, αx, αy), with the tangent t
// (an angle in the plane of the region's highlight-weighted mean normal) and the two roughnesses
// searched on a grid and refined, and k linear. Named only when the anisotropic lobe explains
// clearly more than the best isotropic one. Written as the *_aniso model with the fitted
// "tangent"; "alpha_x"/"alpha_y" and a scaled "rho_s" where the declared region had those values
// (otherwise igi-solve fits them, given the tangent).
CandidateResult AnisotropicReflection(const CandidateContext& cx, const ResidualFitter& f,
                                      int region);

// light_source_extent of light `light` (point or sphere): a source that is really a larger
// sphere of the same intensity. Studied at shadow and highlight edges: the light's direct term
// for a sphere of radius r (its solid angle sampled with shadow rays through the model's
// geometry, the same samples for every r) minus the current one is the change, with a free
// amplitude; r is searched on a grid (on `search`'s records when given) and refined. Written as a
// "sphere" light at its position with the fitted radius and the same intensity
// (radiance = intensity / (π r²)).
CandidateResult LightSourceExtent(const CandidateContext& cx, const ResidualFitter& f, int light,
                                  const RecordSubset* search = nullptr);

// Per record: whether light `light` (point or sphere) made a sphere of the largest radius
// light_source_extent tries changes the record's direct term by more than that candidate's
// threshold (kMinChange of the model's value): a penumbra at a shadow edge or a highlight, where
// the light's size shows. All false for other light types. light_intensity leaves these out: a
// source larger than declared darkens the lit side of every penumbra and the peak of every
// highlight, where a point model's basis is large, and brightens the shadowed side, where it is
// small, so a fit of its intensity there reads the extent as a weaker light.
std::vector<bool> WhereLightSizeShows(const CandidateContext& cx,
                                      const std::vector<PixelRecord>& records, int light);

// ambient_light: light from no declared source, the same from every direction: what a unit
// "ambient" light adds at each record (rendered: the point's ρd and the room's bounces of it)
// with a free RGB radiance. Written as an "ambient" light of the fitted radiance in every
// lighting.
CandidateResult AmbientLight(const CandidateContext& cx, const ResidualFitter& f);

}  // namespace igi::diagnose
