#include "solver/diagnose/pixel_records.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "solver/inverse/gather.h"
#include "solver/inverse/observations.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"

namespace igi::diagnose {
namespace {

std::vector<std::unique_ptr<render::RayScene>> LightingScenes(const recon::Scene& scene) {
  std::vector<std::unique_ptr<render::RayScene>> out(scene.lightings.size());
  for (const recon::Photo& p : scene.photos) {
    if (!out[p.lighting]) out[p.lighting] = std::make_unique<render::RayScene>(scene, p.lighting);
  }
  return out;
}

// The region the ray through continuous pixel (x, y) hits first, or -1 (nothing, a light, or a
// surface that does not reflect).
int RegionAt(const render::RayScene& impl, const recon::Camera& cam, double x, double y) {
  const std::optional<render::SurfaceHit> hit =
      impl.TraceSurface(cam.CenterInWorld(), cam.WorldRayFromImg(Eigen::Vector2d(x, y)));
  if (!hit) return -1;
  const recon::BrdfModel m = impl.material(hit->region).model;
  return recon::IsReflective(m) ? hit->region : -1;
}

}  // namespace

PhotoSet LoadPhotoSet(const recon::Scene& scene) {
  PhotoSet set;
  const auto scenes = LightingScenes(scene);
  set.recorded.resize(scene.photos.size());
  set.valid.resize(scene.photos.size());
  for (size_t i = 0; i < scene.photos.size(); ++i) {
    const recon::Photo& p = scene.photos[i];
    const recon::Camera& cam = scene.cameras[p.camera];
    const Image& img = set.recorded[i] = ReadImage(p.file, 3);
    std::optional<Image> mask;
    if (p.mask) mask = ReadImage(*p.mask, 1);
    const double clip = solver::AutoSaturation(img);
    Image& valid = set.valid[i] = Image(img.width, img.height, 1);
    const render::RayScene& impl = *scenes[p.lighting];
    ParallelFor(0, img.height, [&](int64_t yy) {
      const int y = int(yy);
      for (int x = 0; x < img.width; ++x) {
        bool ok = UsablePixel(img, mask ? &*mask : nullptr, clip, x, y);
        if (ok) {
          const int r = RegionAt(impl, cam, x + 0.5, y + 0.5);
          ok = r >= 0;
          for (int k = 0; k < 4 && ok; ++k) {
            ok = RegionAt(impl, cam, x + 0.05 + 0.9 * (k & 1), y + 0.05 + 0.9 * (k >> 1)) == r;
          }
        }
        valid.at(x, y, 0) = ok ? 1.0f : 0.0f;
      }
    });
  }
  return set;
}

namespace {

// The mean over the (2r+1)² window about each pixel (clipped at the image's edges), per channel.
Image BoxMean(const Image& in, int r) {
  Image out(in.width, in.height, in.channels);
  for (int y = 0; y < in.height; ++y) {
    for (int x = 0; x < in.width; ++x) {
      for (int c = 0; c < in.channels; ++c) {
        double sum = 0;
        int n = 0;
        for (int v = std::max(0, y - r); v <= std::min(in.height - 1, y + r); ++v) {
          for (int u = std::max(0, x - r); u <= std::min(in.width - 1, x + r); ++u) {
            sum += in.at(u, v, c);
            ++n;
          }
        }
        out.at(x, y, c) = float(sum / n);
      }
    }
  }
  return out;
}

}  // namespace

void SimulatePhotos(const recon::Scene& model, const DiagnoseOptions& options, uint64_t seed,
                    Simulation* sim, const PixelMasks* only) {
  const size_t n = model.photos.size();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const bool first = sim->sims.size() != n;
  if (first) {
    sim->sims.assign(n, Image());
    sim->variance.assign(n, Image());
    sim->raw_variance.assign(n, Image());
    sim->rendered.assign(n, {});
  }
  std::vector<std::unique_ptr<render::Renderer>> renderers(model.lightings.size());
  const bool split = options.spp >= 2;
  const int spp1 = split ? options.spp / 2 : options.spp, spp2 = options.spp - spp1;
  for (size_t i = 0; i < n; ++i) {
    const recon::Photo& p = model.photos[i];
    const recon::Camera& cam = model.cameras[p.camera];
    const size_t pixels = size_t(cam.width) * cam.height;
    if (sim->sims[i].empty()) {
      sim->sims[i] = Image(cam.width, cam.height, 3, nan);
      sim->raw_variance[i] = Image(cam.width, cam.height, 3);
      sim->rendered[i].assign(pixels, 0);
    }
    // What this call renders: wanted and not yet rendered.
    std::vector<uint8_t> todo(pixels, 0);
    size_t count = 0;
    for (size_t k = 0; k < pixels; ++k) {
      const bool want = only == nullptr || (i < only->size() && (*only)[i][k] != 0);
      todo[k] = want && sim->rendered[i][k] == 0;
      count += todo[k];
    }
    if (count == 0) continue;
    if (!renderers[p.lighting]) {
      renderers[p.lighting] = std::make_unique<render::Renderer>(model, p.lighting);
    }
    render::RenderOptions ro;
    ro.spp = spp1;
    ro.seed = seed + 7919 * i;
    ro.num_threads = options.num_threads;
    ro.show_progress = false;
    ro.pixel_mask = count == pixels ? nullptr : &todo;
    Image h1 = renderers[p.lighting]->Render(cam, ro);
    Image h2;
    if (split) {
      ro.spp = spp2;
      ro.seed = seed + 7919 * i + 0x5bd1e995ULL;
      h2 = renderers[p.lighting]->Render(cam, ro);
    }
    Image mean = h1;
    if (split) {
      for (size_t k = 0; k < mean.pixels.size(); ++k) {
        mean.pixels[k] =
            float((spp1 * double(h1.pixels[k]) + spp2 * double(h2.pixels[k])) / options.spp);
      }
      solver::ApplyExposureAndResponse(p, &h1);
      solver::ApplyExposureAndResponse(p, &h2);
    }
    solver::ApplyExposureAndResponse(p, &mean);
    const double k_var = split ? 1.0 / (options.spp * (1.0 / spp1 + 1.0 / spp2)) : 0.0;
    Image& out = sim->sims[i];
    Image& raw = sim->raw_variance[i];
    for (size_t k = 0; k < pixels; ++k) {
      if (!todo[k]) continue;
      sim->rendered[i][k] = 1;
      for (int c = 0; c < 3; ++c) {
        const size_t j = k * 3 + c;
        out.pixels[j] = mean.pixels[j];
        const double d = split ? double(h1.pixels[j]) - double(h2.pixels[j]) : 0.0;
        raw.pixels[j] = std::isfinite(d) ? float(k_var * d * d) : 0.0f;
      }
    }
    // One pixel's estimate has one degree of freedom (its noise is as large as itself): averaged
    // over a 5 × 5 window, where the variance changes slowly, it adds little noise to the gains.
    sim->variance[i] = BoxMean(raw, 2);
  }
  bool complete = true;
  for (const std::vector<uint8_t>& r : sim->rendered) {
    complete = complete && std::all_of(r.begin(), r.end(), [](uint8_t v) { return v != 0; });
  }
  if (complete) sim->rendered.clear();
}

PixelMasks HeldOutTestMasks(const recon::Scene& model, const solver::PixelHoldout& holdout,
                            int grid) {
  constexpr int kWindow = 2;  // SimulatePhotos' variance window
  PixelMasks masks(model.photos.size());
  for (size_t i = 0; i < masks.size(); ++i) {
    const recon::Camera& cam = model.cameras[model.photos[i].camera];
    const int w = cam.width, h = cam.height;
    std::vector<uint8_t> held(size_t(w) * h, 0), rows(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) held[size_t(y) * w + x] = holdout.HeldOut(int(i), x, y);
    }
    // Widened by the window: a separable maximum, along x then y.
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        uint8_t v = 0;
        for (int u = std::max(0, x - kWindow); u <= std::min(w - 1, x + kWindow) && !v; ++u) {
          v = held[size_t(y) * w + u];
        }
        rows[size_t(y) * w + x] = v;
      }
    }
    std::vector<uint8_t>& m = masks[i];
    m.assign(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        uint8_t v = grid > 0 && x % grid == 0 && y % grid == 0;
        for (int t = std::max(0, y - kWindow); t <= std::min(h - 1, y + kWindow) && !v; ++t) {
          v = rows[size_t(t) * w + x];
        }
        m[size_t(y) * w + x] = v;
      }
    }
  }
  return masks;
}

namespace {

Eigen::Vector3f AlbedoAt(const recon::Scene& model, const render::RayScene& impl,
                         const render::SurfaceHit& hit) {
  const render::ShadingMaterial& m = impl.material(hit.region);
  Eigen::Vector3d rho = m.params.rho_d;
  if (m.rho_d_map && model.mesh.has_uvs()) {
    const Eigen::Vector3i& t = model.mesh.triangles[hit.triangle];
    const double b0 = 1 - hit.b1 - hit.b2;
    const Eigen::Vector2d uv =
        (b0 * model.mesh.uvs[t[0]] + hit.b1 * model.mesh.uvs[t[1]] + hit.b2 * model.mesh.uvs[t[2]])
            .cast<double>();
    rho = render::SampleTexture(*m.rho_d_map, uv);
  }
  return rho.cast<float>();
}

// An ambient light (radiance L from every direction, never occluded) as k cosine-weighted
// directions about the shading normal, stratified on a grid, each bringing irradiance π·L/k: the
// diffuse term Σ ρd/π·irradiance is ρd·L exactly, as the renderer computes it, and a lobe is
// estimated without bias. No shadow rays.
void GatherAmbient(const recon::Light& light, const render::SurfaceHit& hit, int k,
                   render::Pcg32& rng, int id, PixelRecord* r) {
  const render::Frame frame = render::Frame::FromNormal(hit.n_s);
  const int side = std::max(1, static_cast<int>(std::sqrt(double(k))));
  const Eigen::Vector3f irradiance = (light.radiance * (render::kPi / k)).cast<float>();
  for (int s = 0; s < k; ++s) {
    Eigen::Vector2d u = rng.Uniform2D();
    if (s < side * side) u = Eigen::Vector2d((s % side + u.x()) / side, (s / side + u.y()) / side);
    RecordLightSample rs;
    rs.light = id;
    rs.wi = frame.ToWorld(render::SampleCosineHemisphere(u)).cast<float>();
    rs.irradiance = irradiance;
    rs.distance = 1e30f;
    r->lights.push_back(rs);
  }
}

void GatherLights(const recon::Scene& model, const render::RayScene& impl,
                  const render::SurfaceHit& hit, int samples, render::Pcg32& rng, PixelRecord* r) {
  const double eps = impl.ray_epsilon();
  const std::vector<int>& ids = model.lightings[model.photos[r->photo].lighting].lights;
  for (int l = 0; l < impl.num_lights(); ++l) {
    const recon::LightType type = impl.light_type(l);
    const bool delta = type == recon::LightType::kPoint || type == recon::LightType::kSpot ||
                       type == recon::LightType::kDirectional;
    if (type == recon::LightType::kAmbient) {
      GatherAmbient(*impl.light(l), hit, 4 * samples, rng, l < int(ids.size()) ? ids[l] : -1, r);
      continue;
    }
    const int k = delta ? 1 : samples;
    for (int s = 0; s < k; ++s) {
      const Eigen::Vector3d u(rng.UniformDouble(), rng.UniformDouble(), rng.UniformDouble());
      const render::LightSample ls = impl.SampleLight(l, hit.position, u);
      if (!(ls.pdf > 0) || !(ls.value.maxCoeff() > 0)) continue;
      const double cos_geo = ls.wi.dot(hit.n_geo), cos_s = ls.wi.dot(hit.n_s);
      if (!(cos_geo > 0) || !(cos_s > 0)) continue;
      const double d = std::isfinite(ls.distance)
                           ? ls.distance - std::max(4 * eps, 1e-6 * ls.distance)
                           : ls.distance;
      if (impl.Occluded(hit.position + hit.n_geo * eps, ls.wi, d, l)) continue;
      RecordLightSample rs;
      rs.light = l < int(ids.size()) ? ids[l] : -1;  // the emitter-material light has no id
      rs.wi = ls.wi.cast<float>();
      rs.irradiance = (ls.value * (cos_s / (ls.pdf * k))).cast<float>();
      rs.distance = float(std::isfinite(ls.distance) ? ls.distance : 1e30);
      r->lights.push_back(rs);
    }
  }
}

// The room's light reflected onto a glossy record (PixelRecord::room).
void GatherRoom(const render::Renderer& renderer, const render::ShadingMaterial& m,
                const render::SurfaceHit& hit, uint64_t seed, render::Pcg32& rng, PixelRecord* r) {
  solver::GatherQuery q;
  q.position = hit.position;
  q.n_geo = hit.n_geo;
  q.n_s = hit.n_s;
  q.view = r->view.cast<double>();
  q.lobe = true;
  const double alpha = std::clamp(std::max(m.params.AlphaX(), m.params.AlphaY()), 0.02, 0.5);
  const double eps = renderer.rays().ray_epsilon();
  int k = 0;
  for (const solver::WeightedDirection& d :
       solver::HemisphereDirections(q, PixelRecord::kRoomSamples, 2 * alpha, rng)) {
    const Eigen::Vector3d li =
        renderer.ReflectedRadiance(hit.position + hit.n_geo * eps, d.wi, 1, seed * 64 + k++);
    if (!li.allFinite() || !(li.maxCoeff() > 0)) continue;
    RecordLightSample rs;
    rs.wi = d.wi.cast<float>();
    rs.irradiance = (li * d.weight).cast<float>();
    rs.distance = 1e30f;
    r->room.push_back(rs);
  }
}

}  // namespace

std::vector<PixelRecord> BuildRecords(const recon::Scene& model, const PhotoSet& photos,
                                      const std::vector<Image>& sims,
                                      const DiagnoseOptions& options,
                                      const std::vector<Image>* variance) {
  const auto scenes = LightingScenes(model);
  // The room's reflection needs the model's radiance: one renderer per photographed lighting,
  // built only when some reflective region has a specular lobe.
  bool glossy = false;
  for (const recon::Material& m : model.materials) glossy |= recon::HasSpecularLobe(m.brdf);
  std::vector<std::unique_ptr<render::Renderer>> renderers(model.lightings.size());
  if (glossy) {
    for (const recon::Photo& p : model.photos) {
      if (!renderers[p.lighting])
        renderers[p.lighting] = std::make_unique<render::Renderer>(model, p.lighting);
    }
  }
  const solver::PixelHoldout holdout{options.holdout_fraction, options.holdout_block_px,
                                     options.solve.holdout_seed};
  std::vector<std::vector<PixelRecord>> rows;
  std::vector<std::pair<int, int>> row_of;  // (photo, y)
  for (size_t i = 0; i < model.photos.size(); ++i) {
    for (int y = 0; y < photos.recorded[i].height; y += options.pixel_stride) {
      row_of.emplace_back(int(i), y);
    }
  }
  rows.resize(row_of.size());
  ParallelFor(
      0, int64_t(row_of.size()),
      [&](int64_t k) {
        const auto [i, y] = row_of[k];
        const recon::Photo& p = model.photos[i];
        const recon::Camera& cam = model.cameras[p.camera];
        const render::RayScene& impl = *scenes[p.lighting];
        const Image& rec = photos.recorded[i];
        const double half_diag2 =
            0.25 * (double(cam.width) * cam.width + double(cam.height) * cam.height);
        render::Pcg32 rng = render::PixelSampleRng(options.seed + 17, uint64_t(k), 0);
        for (int x = 0; x < rec.width; x += options.pixel_stride) {
          if (photos.valid[i].at(x, y, 0) < 0.5f) continue;
          const Eigen::Vector3d center = cam.CenterInWorld();
          const Eigen::Vector3d dir = cam.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
          const std::optional<render::SurfaceHit> hit = impl.TraceSurface(center, dir);
          if (!hit) continue;
          PixelRecord r;
          r.photo = i;
          r.x = x;
          r.y = y;
          r.held_out = holdout.HeldOut(i, x, y);
          for (int c = 0; c < 3; ++c) {
            r.recorded[c] = rec.at(x, y, c);
            r.sim[c] = sims[i].at(x, y, c);
            if (variance && i < int(variance->size()) && !(*variance)[i].pixels.empty()) {
              r.sim_var[c] = (*variance)[i].at(x, y, c);
            }
          }
          if (!r.sim.allFinite()) continue;
          r.region = hit->region;
          r.position = hit->position.cast<float>();
          r.normal = hit->n_s.cast<float>();
          r.view = (-dir).cast<float>();
          if (recon::HasSpecularLobe(model.materials[hit->region].brdf)) {
            const auto quarter = solver::QuarterPixelNormals(impl, cam, x, y, *hit, 0.98);
            if (quarter) r.lobe_blur2 = float(solver::PixelNormalSpread(*quarter, hit->n_s));
          }
          const double dx = x + 0.5 - cam.principal_x_px(), dy = y + 0.5 - cam.principal_y_px();
          r.r2 = float((dx * dx + dy * dy) / half_diag2);
          r.albedo = AlbedoAt(model, impl, *hit);
          r.point_cam = (cam.cam_from_world * hit->position).cast<float>();
          const Image& sim = sims[i];
          auto at = [&](int xx, int yy, int c) {
            return sim.at(std::clamp(xx, 0, sim.width - 1), std::clamp(yy, 0, sim.height - 1), c);
          };
          for (int c = 0; c < 3; ++c) {
            float gx = 0, gy = 0;
            for (int d = -1; d <= 1; ++d) {
              gx += at(x + 1, y + d, c) - at(x - 1, y + d, c);
              gy += at(x + d, y + 1, c) - at(x + d, y - 1, c);
            }
            r.sim_gradient(c, 0) = gx / 6;
            r.sim_gradient(c, 1) = gy / 6;
          }
          GatherLights(model, impl, *hit, options.light_samples, rng, &r);
          const render::ShadingMaterial& sm = impl.material(hit->region);
          if (renderers[p.lighting] && recon::HasSpecularLobe(sm.model)) {
            // Its own random stream: the lights' samples stay those of a scene without lobes.
            const uint64_t stream = uint64_t(k) * 65537 + uint64_t(x);
            render::Pcg32 room_rng = render::PixelSampleRng(options.seed + 29, stream, 1);
            GatherRoom(*renderers[p.lighting], sm, *hit, options.seed * 1000003 + stream, room_rng,
                       &r);
          }
          rows[k].push_back(std::move(r));
        }
      },
      options.num_threads);
  std::vector<PixelRecord> out;
  for (auto& row : rows) {
    for (PixelRecord& r : row) out.push_back(std::move(r));
  }
  FlagOutliers(&out);
  return out;
}

void FlagOutliers(std::vector<PixelRecord>* records) {
  // Residual relative to the pixel's level; flagged beyond 5× its median (≈ 7 σ for Gaussian
  // errors).
  std::vector<float> t(records->size());
  for (size_t i = 0; i < t.size(); ++i) {
    const PixelRecord& r = (*records)[i];
    const float level = std::sqrt(0.5f * (r.sim.squaredNorm() + r.recorded.squaredNorm())) + 1e-20f;
    t[i] = (r.sim - r.recorded).norm() / level;
  }
  if (t.empty()) return;
  std::vector<float> sorted = t;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const float limit = 5 * sorted[sorted.size() / 2];
  for (size_t i = 0; i < t.size(); ++i) (*records)[i].outlier = t[i] > limit;
}

ResidualSums Residual(const std::vector<PixelRecord>& records, bool held_out) {
  ResidualSums s;
  for (const PixelRecord& r : records) {
    if (r.held_out != held_out) continue;
    s.sq_err += double((r.sim - r.recorded).squaredNorm());
    s.sq_photo += double(r.recorded.squaredNorm());
  }
  return s;
}

ResidualSums ResidualOverPhotos(const PhotoSet& photos, const std::vector<Image>& sims,
                                const solver::PixelHoldout& holdout, bool held_out) {
  ResidualSums s;
  for (size_t i = 0; i < sims.size(); ++i) {
    const Image& rec = photos.recorded[i];
    for (int y = 0; y < rec.height; ++y) {
      for (int x = 0; x < rec.width; ++x) {
        if (photos.valid[i].at(x, y, 0) < 0.5f || holdout.HeldOut(int(i), x, y) != held_out) {
          continue;
        }
        s.AddPixel(rec, sims[i], x, y);
      }
    }
  }
  return s;
}

}  // namespace igi::diagnose
