#pragma once
// Options of igi-solve (docs/solve.md): the inverse global illumination solver of Yu, Debevec,
// Malik and Hawkins (SIGGRAPH 1999) followed by a joint refinement against the path tracer.
// Every field has a default, a unit and a flag of the same name (--pixel-stride, ...).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace igi::solver {

// The specular reflectance's colour: one ρs for every channel (kGrey: dielectrics, RADIANCE
// plastic) or one per channel (kRgb: metals).
enum class SpecularColour { kGrey, kRgb };
// "grey", "rgb" (the --specular-colour flag's spelling).
std::string_view SpecularColourName(SpecularColour colour);
std::optional<SpecularColour> SpecularColourFromName(std::string_view name);

// Which regions get an albedo map: kAuto (those whose albedo varies significantly across
// patches, or that declare UVs and vary), kAll (every region with an unknown albedo) or kNone.
enum class AlbedoMaps { kAuto, kAll, kNone };
// "auto", "all", "none" (the --albedo-maps flag's spelling).
std::string_view AlbedoMapsName(AlbedoMaps maps);
std::optional<AlbedoMaps> AlbedoMapsFromName(std::string_view name);

// Where the written albedo maps come from: kAuto (their own pass over the photos, every pixel at
// the stride, when the observations were drawn to a budget and are spaced more coarsely than the
// photos' pixels; else the observations), kAlways (the pass) or kNever (the observations).
enum class AlbedoMapPass { kAuto, kAlways, kNever };
// "auto", "always", "never" (the --albedo-map-pass flag's spelling).
std::string_view AlbedoMapPassName(AlbedoMapPass pass);
std::optional<AlbedoMapPass> AlbedoMapPassFromName(std::string_view name);

// How each refinement round updates the materials (SolveOptions::refine_update): kIndependent
// (each region refitted alone), kJoint (every unknown albedo and ρs at once) or kJointAlbedo
// (the albedos only, jointly).
enum class RefineUpdate { kIndependent, kJoint, kJointAlbedo };
// "independent", "joint", "joint_albedo" (the --refine-update flag's spelling).
std::string_view RefineUpdateName(RefineUpdate update);
std::optional<RefineUpdate> RefineUpdateFromName(std::string_view name);

// The photos' absolute scale (SolveOptions::photo_scale): kGiven (their values are radiance in
// the scene's units) or kSolve (one unknown factor shared by every photo, estimated).
enum class PhotoScaleMode { kGiven, kSolve };
// "given", "solve" (the --photo-scale flag's spelling).
std::string_view PhotoScaleModeName(PhotoScaleMode mode);
std::optional<PhotoScaleMode> PhotoScaleModeFromName(std::string_view name);

// The choice options as igi-solve's flags spell them, before they are parsed (SolveOptions::
// SetChoices); each default is the name of the option's default.
struct SolveChoiceFlags {
  std::string specular_colour = "grey";
  std::string albedo_maps = "auto";
  std::string albedo_map_pass = "auto";
  std::string refine_update = "joint";
  std::string photo_scale = "given";
};

struct SolveOptions {
  // Observations: every pixel_stride-th pixel of each photo in x and y (>= 1).
  int pixel_stride = 2;
  // Memory budget in GiB (0 = the machine's memory less an eighth, at least 1 GiB less): the
  // solver estimates its peak before reading any photo and draws fewer observations to fit it
  // (solver/inverse/solve_memory.h), or stops with one line when even the fewest do not fit.
  double memory_budget = 0;
  // At most this many observations in all (0 = as many as the memory budget allows): where the
  // photos offer more, each region keeps its highlight candidates and fit samples (below) and
  // the rest is drawn evenly by a hash of photo and pixel (solver/inverse/observation_draw.h), each
  // drawn observation the mean of a block of pixels (max_observation_block). What a solve costs
  // is set by this, not by the photos' size: a room's fits (every region's highlight candidates
  // and fit samples, a few observations per patch) need a few hundred thousand; photos that
  // offer fewer are collected whole.
  int64_t max_observations = 300000;
  // Where observations are drawn (above), each class kept with probability p stands for the mean
  // of a block of up to this many stride cells on a side (⌊1/√p⌋; 1 = single pixels), so that
  // the pixels between the drawn ones average its noise (solver/inverse/observation_draw.h).
  int max_observation_block = 8;
  // Pixel values at or above this are clipped and ignored (scene radiance units); 0 = auto: a
  // photo whose maximum value is shared by 3 or more pixels is taken as clipped at that value.
  double saturation = 0;
  // Patch size, metres: 0 = auto (the scene's length scale / 96: its bounding-box diagonal, or
  // 3.5 mean free paths from the seen surfaces where that is shorter;
  // solver/inverse/scene_scale.h).
  double patch_size_m = 0;
  // Gathering at each observation and patch: samples per extended light (sphere, area; 1..1024)
  // and stratified hemisphere rays for the light arriving from other surfaces (0..4096). More:
  // less gathering noise, proportionally more gathering time.
  int light_samples = 16;
  int indirect_rays = 64;
  // Where an indirect ray meets a glossy surface, trace one more ray about its mirror direction
  // so that the surface's specular reflection of the rest of the room joins the light it sends
  // (solver/inverse/gather.h). Off (--specular-bounces false): glossy patches send only their
  // diffuse radiance and the direct light's highlight, and the surfaces they light gather too
  // little (measured: docs/solve.md).
  bool specular_bounces = true;
  // Sample each observation's direct light over its pixel's footprint on the surface (a pixel
  // records the mean over it; solver/inverse/gather.h GatherQuery::Footprint), with
  // footprint_samples points per delta light, and widen each observation's lobe by the spread of
  // the normals over that footprint (Observation::lobe_blur2: α² + the spread), so that a curved
  // glossy surface's highlight is not fitted as a rougher lobe. Off (--pixel-footprint false): at
  // the centre ray's point only, with the centre's normal.
  bool pixel_footprint = true;
  // With pixel_footprint: stratified points of the footprint per delta light (point, spot,
  // directional), >= 1; extended lights spread their light_samples over it.
  int footprint_samples = 4;
  // Radius (metres) over which the indirect irradiance of neighbouring observations of the same
  // surface is averaged to remove gathering noise; 0 = auto (the scene's length scale / 96, as
  // the patch size).
  double smoothing_radius_m = 0;
  // Adaptive smoothing, in [0, 10] (0 = off: every observation averages over
  // smoothing_radius_m): each observation's radius is this factor times the harmonic mean
  // distance of its indirect rays' hits (the validity radius of Ward's irradiance cache: the
  // irradiance changes on the scale of the nearby geometry), held within [1/4, 2] ×
  // smoothing_radius_m. Near a contact or a corner the light changes fast and the radius
  // shrinks; in the open it grows, averaging more of the gathering noise.
  double smoothing_accuracy = 0.3;
  // The paper's alternation (fit, recompute specular differences, refit): at most this many
  // rounds, 1..100.
  int max_iterations = 8;
  double tolerance = 2e-3;  // largest relative parameter change that counts as converged
  // kGrey (default): one ρs for all channels (dielectrics, RADIANCE plastic); kRgb: coloured
  // (metals).
  SpecularColour specular_colour = SpecularColour::kGrey;
  // Albedo maps: kAuto (default) for regions whose albedo varies significantly across patches
  // (or that declare UVs and vary), kAll for every region with an unknown albedo, kNone.
  AlbedoMaps albedo_maps = AlbedoMaps::kAuto;
  // With kAuto or kAll: only these regions (by name) get a map; empty: every region. (A
  // library option, used by igi-diagnose to give maps to the regions it found textured first.)
  std::vector<std::string> albedo_map_regions;
  double texel_size_m = 0;  // albedo map texel, metres; 0 = auto (the median pixel footprint)
  // Where the written albedo maps come from: kAuto (default; their own pass over the photos,
  // every pixel at the stride, when the observations were drawn to a budget and are spaced more
  // coarsely than the photos' pixels; else the observations), kAlways (the pass) or kNever (the
  // observations).
  AlbedoMapPass albedo_map_pass = AlbedoMapPass::kAuto;
  // A textured glossy region's ρs and α are fitted with each sample's albedo as the other photos
  // see that texel off their highlights (false: its patch's off-highlight albedo).
  bool held_out_albedo = true;
  // Every region's albedo is one value: the fits never take one per patch (an object of one paint,
  // such as the DiLiGenT ball, whose diffuse falls off unlike Lambert's toward the terminator;
  // per-patch albedos would take that fall-off as texture).
  bool uniform_albedo = false;
  // Fit samples per region: up to this many of the observations near a highlight (tanθh < 0.6
  // toward a light), drawn evenly by a hash of their photo and pixel; they carry a lobe's ρs
  // and α (>= 1). More: a steadier ρs and α where a faint lobe lies on a texture, for a longer
  // fit (measured: docs/solve.md).
  int max_highlight_samples = 100000;
  // ... and the rest (which mostly carry the albedo): this many in all, at least a third of it.
  int max_fit_samples = 6000;
  // Beyond the paper: re-render the light arriving at every observation with the full path
  // tracer and refit all parameters, `refine_iterations` times (0 = off; at most 20).
  int refine_iterations = 2;
  int refine_rays = 32;  // path-traced directions per observation in each refinement round
  // The same in the last round (1..4096), whose gather sets the written values: their Monte
  // Carlo noise is this round's (more: less noise, proportionally more time; measured:
  // docs/solve.md). A region with fewer than kFinalRoundRegionObservations observations gets
  // proportionally more (FinalRoundRays, up to 8×), so that every region's written values rest
  // on as many gathered directions as a region of that many observations.
  int refine_final_rays = 128;
  // How each refinement round updates the materials: kJoint (default), kJointAlbedo or
  // kIndependent. The rounds gather all indirect light from the model, so its albedos feed back
  // on themselves: a too bright model darkens the next fit. kIndependent: each region is
  // refitted alone (its albedo πL/E with E rendered at the current values), which can overshoot.
  // kJoint: the renderer also returns each gathered irradiance's derivative with respect to every
  // region's albedo, ρs and α (Renderer::ReflectedRadiance), and the round solves for every
  // unknown albedo and ρs at once so that the photos are matched with the light those new values
  // would send (a Newton step on the fixed point; α is refitted per region and its change enters
  // the others' light; albedo maps keep stage 1's texel detail, scaled to the new region means).
  // kJointAlbedo: the same for the albedos only. Measured: docs/solve.md.
  RefineUpdate refine_update = RefineUpdate::kJoint;
  // Share of each refinement round's albedo change that is applied, in (0, 1] (1 = the full
  // step). Smaller steps damp a round's swing about the answer where stage 1 is already right,
  // but correct a biased stage 1 more slowly (measured: docs/solve.md).
  double refine_albedo_step = 1.0;
  // The photos' absolute scale. kGiven (default): their values are radiance in the scene's units
  // (after each photo's exposure_scale). kSolve: one unknown factor k shared by every photo
  // (radiance maps from a recovered response are known up to a constant) is estimated from the
  // observed regions whose reflectance is given in full and diffuse (a reference target), before
  // the paper's stage (solver/inverse/photometric_scale.h); the solved scene.json multiplies every
  // photo's exposure_scale by k.
  PhotoScaleMode photo_scale = PhotoScaleMode::kGiven;
  // Seed of the random numbers of the gathering and the refinement's path tracing.
  uint64_t seed = 1;
  // Pixels left out of every fit (igi-diagnose measures its held-out residual on them): square
  // blocks of holdout_block_px, a `holdout_fraction` share of them in [0, 1) (0 = none), chosen
  // by holdout_seed.
  double holdout_fraction = 0;
  int holdout_block_px = 16;
  uint64_t holdout_seed = 7;
  int num_threads = 0;  // 0 = the process default
  // Progress bars on stderr (only when it is a terminal).
  bool show_progress = true;

  // Throws InputError naming the flag and the rule (a choice outside its enum: by its number).
  void Validate() const;
  // Sets the choice options from their flags' text, then validates as Validate does: one
  // InputError with every problem, a text that names no choice as "--FLAG: TEXT: must be ..."
  // in its place among them.
  void SetChoices(const SolveChoiceFlags& flags);
};

// The observation count from which a region's last refinement round gathers
// SolveOptions::refine_final_rays directions per observation.
inline constexpr int kFinalRoundRegionObservations = 1024;

// Directions per observation in the last refinement round for a region of `observations`
// observations: refine_final_rays × 1024 / observations, at least refine_final_rays and at most
// 8 times it (and 4096).
int FinalRoundRays(int refine_final_rays, int observations);

// kJoint (every region's ρd and ρs jointly, the α changes included) or kJointAlbedo (the
// albedos only).
constexpr bool IsJointUpdate(RefineUpdate update) {
  return update == RefineUpdate::kJoint || update == RefineUpdate::kJointAlbedo;
}

}  // namespace igi::solver
