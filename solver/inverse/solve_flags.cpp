#include "solver/inverse/solve_flags.h"

namespace igi::solver {

void AddSolveFlags(CLI::App& app, SolveFlags* flags) {
  SolveOptions& o = flags->options;
  SolveChoiceFlags& c = flags->choices;
  app.add_option("--pixel-stride", o.pixel_stride, "use every Nth pixel in x and y")
      ->capture_default_str();
  app.add_option("--memory-budget", o.memory_budget,
                 "memory budget in GiB (0 = the machine's memory less a margin): fewer "
                 "observations are drawn to fit it, or the solve stops with one line")
      ->capture_default_str();
  app.add_option(
         "--max-observations", o.max_observations,
         "at most this many observations (0 = as many as the memory budget allows); each region "
         "keeps its fit samples and highlight candidates within half of them, the rest is drawn "
         "evenly")
      ->capture_default_str();
  app.add_option("--max-observation-block", o.max_observation_block,
                 "where observations are drawn, each stands for the mean of a block of up to "
                 "this many stride cells on a side (1 = single pixels)")
      ->capture_default_str();
  app.add_option("--saturation", o.saturation, "clipping value of the photos (0 = auto)")
      ->capture_default_str();
  app.add_option("--patch-size-m", o.patch_size_m, "patch size in metres (0 = auto)")
      ->capture_default_str();
  app.add_option("--light-samples", o.light_samples, "samples per extended light and point")
      ->capture_default_str();
  app.add_option("--indirect-rays", o.indirect_rays, "hemisphere rays per point")
      ->capture_default_str();
  app.add_option("--smoothing-radius-m", o.smoothing_radius_m,
                 "radius for averaging indirect irradiance (0 = auto)")
      ->capture_default_str();
  app.add_option("--smoothing-accuracy", o.smoothing_accuracy,
                 "adaptive smoothing: radius = this x the harmonic mean distance of the "
                 "indirect rays' hits, within [1/4, 2] x the radius (0 = fixed radius)")
      ->capture_default_str();
  app.add_option("--max-iterations", o.max_iterations, "iterations of the paper's alternation")
      ->capture_default_str();
  app.add_option("--tolerance", o.tolerance, "relative parameter change that ends iterating")
      ->capture_default_str();
  app.add_option("--specular-colour", c.specular_colour, "grey or rgb specular reflectance")
      ->capture_default_str();
  app.add_option("--albedo-maps", c.albedo_maps, "auto, all or none")->capture_default_str();
  app.add_option("--albedo-map-pass", c.albedo_map_pass,
                 "albedo maps from their own pass over the photos at every pixel of the stride: "
                 "auto (when the observations were drawn to a budget), always or never")
      ->capture_default_str();
  app.add_option("--texel-size-m", o.texel_size_m, "albedo texel in metres (0 = auto)")
      ->capture_default_str();
  app.add_option("--max-highlight-samples", o.max_highlight_samples,
                 "per region, the observations near a highlight fitted (drawn evenly when there "
                 "are more; they carry the lobe's rho_s and alpha)")
      ->capture_default_str();
  app.add_option("--max-fit-samples", o.max_fit_samples,
                 "per region, the other observations fitted (they mostly carry the albedo)")
      ->capture_default_str();
  app.add_option("--refine-iterations", o.refine_iterations,
                 "rounds of the path-traced joint refinement (0 = the paper's method only)")
      ->capture_default_str();
  app.add_option("--refine-rays", o.refine_rays, "path-traced directions per observation")
      ->capture_default_str();
  app.add_option("--refine-final-rays", o.refine_final_rays,
                 "path-traced directions per observation in the last refinement round (a region "
                 "of fewer than 1024 observations gets proportionally more, up to 8x)")
      ->capture_default_str();
  app.add_option("--refine-update", c.refine_update,
                 "stage 2's update: independent (each region refitted with the light the "
                 "current model sends), joint (every region's albedo and ρs at once, with the "
                 "renderer's derivatives of that light with respect to each region's albedo, "
                 "ρs and α) or joint_albedo (the albedos only)")
      ->capture_default_str();
  app.add_option("--refine-albedo-step", o.refine_albedo_step,
                 "share of each refinement round's albedo change applied (1 = full step)")
      ->capture_default_str();
  app.add_option("--pixel-footprint", o.pixel_footprint,
                 "sample each observation's direct light over the surface its pixel covers and "
                 "widen its lobe by the normals' spread there (true), or use its centre ray's "
                 "point and normal only (false)")
      ->capture_default_str();
  app.add_option("--specular-bounces", o.specular_bounces,
                 "gathering follows glossy surfaces' reflection of the room (true) or takes only "
                 "their diffuse radiance and the lights' highlights (false)")
      ->capture_default_str();
  app.add_option("--photo-scale", c.photo_scale,
                 "given (photos in the scene's radiance units) or solve (one factor for all "
                 "photos, from the regions of known diffuse reflectance)")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
}

SolveOptions FinishSolveFlags(const SolveFlags& flags, int threads, bool show_progress) {
  SolveOptions o = flags.options;
  o.num_threads = threads;
  o.show_progress = show_progress;
  o.SetChoices(flags.choices);
  return o;
}

}  // namespace igi::solver
