// The refinement's light, path-traced through the model (solver/inverse/refine_stage.h).
#include "solver/inverse/refine_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "solver/inverse/solve_options.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::solver {
namespace {

Eigen::Vector3d FaceNormalToward(const recon::TriangleMesh& mesh, int triangle,
                                 const Eigen::Vector3d& v) {
  const Eigen::Vector3d fn = mesh.FaceNormal(triangle).cast<double>();
  return fn.dot(v) >= 0 ? fn : -fn;
}

uint64_t Mix(uint64_t a, uint64_t b) {
  uint64_t x = a * 0x9e3779b97f4a7c15ULL ^ (b + 0x632be59bd9b4e019ULL + (a << 6) + (a >> 2));
  x ^= x >> 31;
  x *= 0xbf58476d1ce4e5b9ULL;
  return x ^ (x >> 29);
}

}  // namespace

RenderCost RenderIncident(const StageData& d, const recon::Scene& model,
                          const std::vector<double>& ray_epsilon, const MaterialEstimate& materials,
                          uint64_t round, LightModel* out) {
  const auto start = std::chrono::steady_clock::now();
  const recon::Scene& scene = d.scene;
  const SolveOptions& options = d.options;
  const ObservationSet& obs = d.obs;
  LightModel& light = *out;
  std::vector<std::unique_ptr<render::Renderer>> renderers(scene.lightings.size());
  for (size_t l = 0; l < scene.lightings.size(); ++l) {
    if (light.lightings[l].active) renderers[l] = std::make_unique<render::Renderer>(model, int(l));
  }
  std::atomic<uint64_t> rays{0};
  // The joint update also needs the derivatives of each region's fitted light with respect to
  // every region's parameters (the same paths: the light itself does not change), summed over
  // the region's fit observations (JointSums). They are summed per chunk of observations (a
  // partition that depends on the count only) and the chunks added in order, so the sums do
  // not depend on the threads.
  const bool joint = IsJointUpdate(options.refine_update);
  const size_t num_regions = materials.size();
  const size_t row = num_regions * render::Renderer::kDerivativeKinds;
  // At most 64 chunks (each holds regions² × kinds sums), of at least 256 observations.
  const int64_t num_obs = int64_t(obs.size());
  const int64_t num_chunks = std::clamp<int64_t>((num_obs + 255) / 256, 1, 64);
  const int64_t chunk_size = (num_obs + num_chunks - 1) / num_chunks;
  std::vector<JointSums> chunk_sums(joint ? num_chunks : 0);
  const bool final_round = int(round) >= options.refine_iterations;
  light.incident_direct.resize(obs.size(), 0);
  Progress progress(fmt::format("igi-solve: path tracing, round {}", round), num_chunks, 2.0,
                    options.show_progress && ProgressAllowed());
  ParallelFor(
      0, num_chunks,
      [&](int64_t chunk) {
        JointSums* sums = joint ? &chunk_sums[chunk] : nullptr;
        if (sums != nullptr) sums->Resize(num_regions);
        std::vector<Eigen::Vector3d> dl, d_e(row), d_t(row);
        const int64_t end = std::min(num_obs, (chunk + 1) * chunk_size);
        for (int64_t i = chunk * chunk_size; i < end; ++i) {
          const Observation& o = obs[i];
          const int l = scene.photos[o.photo].lighting;
          const LightingState& st = light.lightings[l];
          const GatherPoint& gp = st.gather.points[light.point[i]];
          const MaterialState& m = materials[o.region];
          const bool glossy = recon::HasSpecularLobe(m.params.model);
          const bool keep = m.KeepsIncident();
          const render::Frame frame = materials.LocalFrame(o.region, o.normal.cast<double>());
          GatherQuery q;
          q.position = o.position.cast<double>();
          q.view = o.view.cast<double>();
          q.n_geo = FaceNormalToward(scene.mesh, o.triangle, q.view);
          q.n_s = o.normal.cast<double>();
          q.lobe = glossy;
          render::Pcg32 rng = render::PixelSampleRng(Mix(options.seed, round), uint64_t(i), 0x2e7);
          // Glossy observations that the fits use get four times the rays: noise in the
          // specular term T would bias ρs low (regression dilution).
          // The last round's: more where a region has few observations (FinalRoundRays), so that
          // its written values are no noisier than a large region's.
          const int base = final_round ? FinalRoundRays(options.refine_final_rays, m.observations)
                                       : options.refine_rays;
          const int n = base * (glossy && obs.in_fit[i] ? 4 : 1);
          std::vector<IncidentLocal> inc;
          if (keep) inc = DirectIncident(st, gp, frame, n);
          light.incident_direct[i] = int32_t(inc.size());
          const double eps = ray_epsilon[l];
          const bool summed = sums != nullptr && obs.in_fit[i];
          const Eigen::Vector3d wo = frame.ToLocal(q.view);
          // The lobe's weight per unit ρs of an incident direction (SpecularTerms' T = Σ scale·v;
          // its part that ρs does not scale, O, is left to SpecularTerms after the round).
          const double ax = WidenedAlpha(m.params.AlphaX(), o.lobe_blur2);
          const double ay = WidenedAlpha(m.params.AlphaY(), o.lobe_blur2);
          auto lobe_weight = [&](const Eigen::Vector3d& wi_local) {
            const double w = LobeWeight(m.params.model, ax, ay, m.params.ior, wo, wi_local).scale;
            return w > 0 ? w : 0.0;
          };
          Eigen::Vector3d t = Eigen::Vector3d::Zero();
          if (summed && glossy) {
            for (const IncidentLocal& in : inc) {
              t += lobe_weight(in.Wi().cast<double>()) * in.Value().cast<double>();
            }
          }
          if (summed) {
            std::fill(d_e.begin(), d_e.end(), Eigen::Vector3d::Zero());
            std::fill(d_t.begin(), d_t.end(), Eigen::Vector3d::Zero());
          }
          Eigen::Vector3d e = Eigen::Vector3d::Zero();
          int k = 0;
          for (const WeightedDirection& dir : HemisphereDirections(q, n, 0.2, rng)) {
            const Eigen::Vector3d origin = q.position + q.n_geo * eps;
            const uint64_t seed = Mix(Mix(options.seed, round), i * 4096 + k++);
            const Eigen::Vector3d li =
                summed ? renderers[l]->ReflectedRadiance(origin, dir.wi, 1, seed, &dl)
                       : renderers[l]->ReflectedRadiance(origin, dir.wi, 1, seed);
            e += dir.weight * li;
            const Eigen::Vector3d wi_local = frame.ToLocal(dir.wi);
            const double w_lobe = glossy ? lobe_weight(wi_local) : 0.0;
            if (summed) {
              for (size_t j = 0; j < row; ++j) d_e[j] += dir.weight * dl[j];
              if (w_lobe > 0) {
                for (size_t j = 0; j < row; ++j) d_t[j] += (w_lobe * dir.weight) * dl[j];
              }
              t += (w_lobe * dir.weight) * li;
            }
            if (keep) inc.push_back({wi_local.cast<float>(), (dir.weight * li).cast<float>()});
          }
          if (summed) sums->Add(o.region, d_e, d_t, t);
          rays += k;
          light.e_direct[i] = gp.e_direct.cast<double>();
          light.e_indirect[i] = e;
          light.incident[i] = std::move(inc);
        }
        progress.Add(1);
      },
      options.num_threads);
  progress.Finish();
  light.joint_sums = JointSums();
  if (joint) {
    light.joint_sums.Resize(num_regions);
    for (const JointSums& c : chunk_sums) light.joint_sums.Add(c);
  }
  return {rays.load(),
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

}  // namespace igi::solver
