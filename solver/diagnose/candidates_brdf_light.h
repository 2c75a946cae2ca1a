#pragma once
// The candidates of three effects of CONTRACT.md §6 that change reflected or received light:
//
// anisotropic_reflection — a glossy region whose highlight is stretched along a surface
//   direction. Studied in the region's tangent frame (the azimuth of the half vector around the
//   normal): the region's lobe ρs·S(α) is replaced by k·ρs·S_aniso(t, αx, αy), with the tangent t
//   (an angle in the plane of the region's highlight-weighted mean normal) and the two roughnesses
//   searched on a grid and refined, and k linear. Named only when the anisotropic lobe explains
//   clearly more than the best isotropic one.
//
// light_source_extent — a point (or small sphere) light that is really a larger sphere of the
//   same intensity. Studied at shadow and highlight edges: the light's direct term for a sphere
//   of radius r (its solid angle sampled with shadow rays through the model's geometry, the same
//   samples for every r) minus the current one is the change, with a free amplitude; r is
//   searched on a grid and refined.
//
// ambient_light — light from no declared source, the same from every direction: what a unit
//   "ambient" light adds at each record (rendered: the point's ρd and the room's bounces of it)
//   with a free RGB radiance.
//
// All follow candidates.h: fitted by a ResidualFitter on the fitted records, scored on the
// held-out ones, with apply() writing the fitted model into the declared scene document.

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/residual_fit.h"

namespace igi {

// anisotropic_reflection of region `region` (a ward / ward_gmd model, with or without _fresnel,
// and complete values in cx.model). apply() switches the region to the *_aniso model with the
// fitted "tangent"; "alpha_x"/"alpha_y" and a scaled "rho_s" are written where the declared
// region had those values (otherwise igi-solve fits them, given the tangent).
CandidateResult AnisotropicReflection(const CandidateContext& cx, const ResidualFitter& f,
                                      int region);

// light_source_extent of light `light` (point or sphere) in cx.model. apply() makes it a
// "sphere" light at its position with the fitted radius and the same intensity
// (radiance = intensity / (π r²)).
// The radius is searched on `search`'s records when given (a subsample of f's), then fitted and
// scored on f's.
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

// ambient_light: apply() adds an "ambient" light of the fitted radiance to every lighting.
CandidateResult AmbientLight(const CandidateContext& cx, const ResidualFitter& f);

}  // namespace igi
