// The albedo maps' own pass over the photos (SolverState::StreamAlbedoMaps): when the
// observations were drawn to a budget (solver/inverse/observation_draw.h), a map built from them
// alone would have texels as coarse as the drawn observations' spacing. Instead every photo is read
// again, one at a time, and every pixel at the stride that sees a mapped region cleanly adds its
// albedo estimate π(L − ρs·T)/E to the region's map at the photos' own resolution.
//
// The light at such a pixel: its direct part is gathered there (shadow rays toward the lights,
// as at an observation), so that shadow edges and highlights are the pixel's own; the rest (the
// light from other surfaces, smooth on the scale of the drawn observations' spacing) comes from
// the nearest observation of the same region under the same lighting (normals within ~25°):
//   E = E_map(o) · (E_direct(p) + E_indirect(o)) / (E_direct(o) + E_indirect(o)),
//   T = T_direct(p) + T_indirect(o'),
// E_map(o) being the irradiance the maps divide by at the observation and T_indirect(o') the
// indirect part of the lobe term of the written ρs, averaged over neighbours (MapLightOf), at
// the nearest observation o' of the pixel's own photo: it depends on the view.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "solver/inverse/albedo_map.h"
#include "solver/inverse/gather.h"
#include "solver/inverse/observation_grid.h"
#include "solver/inverse/solve_internal.h"
#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::solver {
namespace {

// One pixel's contribution to its region's map.
struct MapSample {
  int map = -1;  // index into the pass's regions
  int triangle = -1;
  double b1 = 0, b2 = 0;
  Eigen::Vector3d numerator = Eigen::Vector3d::Zero(), denominator = Eigen::Vector3d::Zero();
};

}  // namespace

std::vector<Image> SolverState::StreamAlbedoMaps(const std::vector<int>& regions,
                                                 const std::vector<RegionAtlas>& atlases,
                                                 const MapLight& map_light,
                                                 std::vector<Image>* seen,
                                                 std::vector<double>* coverage) const {
  const std::vector<Eigen::Vector3d>& map_e = map_light.e;
  std::vector<char> mapped(materials.size(), 0);
  std::vector<int> map_of(materials.size(), -1);
  for (size_t k = 0; k < regions.size(); ++k) mapped[regions[k]] = 1, map_of[regions[k]] = int(k);
  // Cells of the smoothing radius: the indirect light is averaged over about that already.
  const double radius =
      options.smoothing_radius_m > 0 ? options.smoothing_radius_m : summary.scene_scale_m / 96;
  const ObservationGrid grid(scene, obs, mapped, radius);
  // T's indirect part depends on the view (the room reflected toward the camera): it comes from
  // the nearest observation in the same photo, in cells of three radii (a photo holds a
  // fraction of the observations).
  const ObservationGrid grid_in_photo(scene, obs, mapped, 3 * radius, true);
  std::vector<AlbedoMapBuilder> builders;
  for (const RegionAtlas& atlas : atlases) builders.emplace_back(atlas);
  const double cos_edge = std::cos(10.0 * render::kPi / 180.0);
  const int stride = options.pixel_stride;
  Progress progress("igi-solve: albedo maps", int64_t(scene.photos.size()), 2.0,
                    options.show_progress && ProgressAllowed());
  for (size_t i = 0; i < scene.photos.size(); ++i) {
    const recon::Photo& photo = scene.photos[i];
    const recon::Camera& cam = scene.cameras[photo.camera];
    const int l = photo.lighting;
    const render::RayScene& geometry = *lighting_scenes[l];
    const LoadedPhoto loaded = LoadPhoto(int(i));
    const std::vector<uint8_t>* mask = loaded.mask.empty() ? nullptr : &loaded.mask;
    const double saturation =
        options.saturation > 0 ? options.saturation : AutoSaturation(loaded.radiance);
    const Eigen::Vector3d eye = cam.CenterInWorld();
    const int rows = (cam.height + stride - 1) / stride;
    std::vector<std::vector<MapSample>> per_row(rows);
    ParallelFor(
        0, rows,
        [&](int64_t row) {
          const int y = std::min(int(row) * stride + stride / 2, cam.height - 1);
          for (int x = stride / 2; x < cam.width; x += stride) {
            Eigen::Vector3f value;
            if (CheckPixel(loaded.radiance, mask, x, y, saturation, &value) != PixelUse::kUsable) {
              continue;
            }
            const Eigen::Vector3d dir = cam.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
            const std::optional<render::SurfaceHit> hit = geometry.TraceSurface(eye, dir);
            if (!hit || !mapped[hit->region]) continue;
            const auto quarter = QuarterPixelNormals(geometry, cam, x, y, *hit, cos_edge, 0.01);
            if (!quarter) continue;
            const int j = grid.Nearest(l, hit->region, hit->position, hit->n_s);
            if (j < 0 || !(map_e[j].minCoeff() > 0)) continue;
            const MaterialState& m = materials[hit->region];
            Observation o;  // the pixel as an observation, for its footprint and frame
            o.photo = int(i), o.x = x, o.y = y;
            GatherQuery q;
            q.position = hit->position;
            q.n_geo = hit->n_geo;
            q.n_s = hit->n_s;
            q.view = -dir;
            if (options.pixel_footprint) q.footprint = PixelFootprint(o);
            render::Pcg32 rng =
                render::PixelSampleRng(options.seed ^ 0xa1bed0, PixelKey(int(i), x, y), 0);
            std::vector<DirectSample> direct;
            const Eigen::Vector3d e_direct = GatherDirectAt(geometry, q, options.light_samples,
                                                            options.footprint_samples, rng, &direct)
                                                 .cast<double>();
            const Eigen::Vector3d e_indirect = light.e[j] - light.e_direct[j];
            const Eigen::Vector3d ratio =
                (e_direct + e_indirect).cwiseQuotient((light.e[j]).cwiseMax(1e-300));
            const Eigen::Vector3d e = map_e[j].cwiseProduct(ratio);
            Eigen::Vector3d t = Eigen::Vector3d::Zero(), t0 = t;
            const bool offset = recon::Info(m.params.model).fresnel == recon::LobeFresnel::kRhoS;
            if (recon::HasSpecularLobe(m.params.model) &&
                (offset || m.params.rho_s.maxCoeff() > 0)) {
              // The pixel's own direct lobe, and the indirect part of T at the nearest
              // observation of the same photo (of any photo when it has none near).
              const double spread =
                  options.pixel_footprint ? PixelNormalSpread(*quarter, hit->n_s) : 0.0;
              const int jv = grid_in_photo.Nearest(int(i), hit->region, hit->position, hit->n_s);
              t = DirectSpecularTerm(m.params, spread, materials.LocalFrame(hit->region, hit->n_s),
                                     -dir, direct.data(), int64_t(direct.size()), &t0) +
                  map_light.t_indirect[jv >= 0 ? jv : j].cwiseMax(0.0);
              t0 += map_light.t0_indirect[jv >= 0 ? jv : j].cwiseMax(0.0);
            }
            const Eigen::Vector3d spec = m.params.rho_s.cwiseProduct(t) + t0;
            const Eigen::Vector3d diffuse = value.cast<double>() - spec;
            // As the maps from the observations (AlbedoMapOf): each weighted by its diffuse share.
            const int patch = patches.PatchOf(hit->triangle, hit->b1, hit->b2);
            const double diffuse_pred =
                (materials.PatchAlbedo(patches, patch).cwiseProduct(e) / render::kPi).sum();
            const double share = diffuse_pred / std::max(1e-12, diffuse_pred + spec.sum());
            const double w = std::clamp(2.0 * share - 1.0, 0.0, 1.0);
            if (!(w > 0) || !(e.minCoeff() > 0)) continue;
            per_row[row].push_back({map_of[hit->region], hit->triangle, hit->b1, hit->b2,
                                    w * render::kPi * diffuse.cwiseProduct(m.map_scale), w * e});
          }
        },
        options.num_threads);
    for (const std::vector<MapSample>& samples : per_row) {
      for (const MapSample& s : samples) {
        builders[s.map].Add(s.triangle, s.b1, s.b2, s.numerator, s.denominator);
      }
    }
    progress.Add(1);
  }
  progress.Finish();
  std::vector<Image> maps;
  seen->clear();
  coverage->clear();
  for (size_t k = 0; k < regions.size(); ++k) {
    maps.push_back(builders[k].Finish(materials[regions[k]].params.rho_d));
    seen->push_back(builders[k].DirectMask());
    coverage->push_back(builders[k].Coverage());
    spdlog::debug("region {}: albedo map of {}x{} texels from {} pixels (every photo re-read)",
                  scene.materials[regions[k]].name, maps.back().width, maps.back().height,
                  builders[k].num_samples());
  }
  return maps;
}

}  // namespace igi::solver
