// The path tracer: next-event estimation with multiple importance sampling (power heuristic)
// between light sampling and BRDF sampling, unbiased Russian roulette, two-sided surfaces,
// pixel values as means over the pixel square. Ambient lights (uniform radiance from every
// direction, never occluded) are not sampled: each path vertex adds L times the BRDF's
// hemispherical integral, exactly ρd·L for the diffuse term and one direction drawn from the
// specular lobe alone for the lobe (AddAmbient).
#include "solver/render/render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "solver/render/render_internal.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::render {

Eigen::Vector3d SampleTexture(const Image& tex, Eigen::Vector2d uv) {
  for (int k = 0; k < 2; ++k) {
    if (uv[k] < 0.0 || uv[k] > 1.0) uv[k] -= std::floor(uv[k]);
  }
  const double x = uv.x() * tex.width - 0.5;
  const double y = (1.0 - uv.y()) * tex.height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto texel = [&tex](int xi, int yi) {
    xi = std::clamp(xi, 0, tex.width - 1);
    yi = std::clamp(yi, 0, tex.height - 1);
    return Eigen::Vector3d(tex.at(xi, yi, 0), tex.at(xi, yi, 1), tex.at(xi, yi, 2));
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x0 + 1, y0)) +
         fy * ((1 - fx) * texel(x0, y0 + 1) + fx * texel(x0 + 1, y0 + 1));
}

namespace {

struct PathState {
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
  Eigen::Vector3d throughput = Eigen::Vector3d::Ones();
  bool from_camera = true;  // no MIS weight on emitters seen directly
  double bsdf_pdf = 0;      // pdf of the last BRDF-sampled direction
  Eigen::Vector3d last_point = Eigen::Vector3d::Zero();
  uint64_t rays = 0;
};

// The derivatives of one path's radiance with respect to each region's parameters: the logarithm
// of a scale on its diffuse albedo, of a scale on its ρs, and of a scale on its roughness (α, or
// αx and αy together), at scale 1 (Renderer::kDerivativeKinds per region, region-major). Every
// term a path adds is a product of BRDF values at its vertices (through the throughput and, for
// next-event estimation and the ambient light, the vertex's own): the term's derivative with
// respect to a parameter's log-scale is the term times the sum, over its vertices on that
// parameter's region, of ∂ln f/∂ln(scale) there (VertexShares; the sampling densities do not
// depend on the parameters: they are the estimator's, not the integrand's).
struct VertexShares {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();  // (ρd/π)/f: linear in the albedo scale
  Eigen::Vector3d s = Eigen::Vector3d::Zero();  // ρs·scale/f: the part of the lobe ρs scales
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // ∂ln f/∂ln α
};

class PathDerivative {
 public:
  static constexpr int kKinds = Renderer::kDerivativeKinds;
  explicit PathDerivative(std::vector<Eigen::Vector3d>* per_param) : out_(per_param) {}
  // A term added to the path's radiance: its throughput's vertices, plus (region >= 0) the
  // current vertex with its shares.
  void Add(const Eigen::Vector3d& term, int region = -1, const VertexShares& shares = {}) {
    for (const auto& [r, sh] : vertices_) AddShares(term, r, sh);
    if (region >= 0) AddShares(term, region, shares);
  }
  // A vertex whose BRDF value joins the throughput.
  void PushVertex(int region, const VertexShares& shares) { vertices_.push_back({region, shares}); }

 private:
  void AddShares(const Eigen::Vector3d& term, int region, const VertexShares& sh) {
    Eigen::Vector3d* out = &(*out_)[size_t(region) * kKinds];
    out[0] += term.cwiseProduct(sh.d);
    out[1] += term.cwiseProduct(sh.s);
    out[2] += term.cwiseProduct(sh.a);
  }
  std::vector<Eigen::Vector3d>* out_;
  std::vector<std::pair<int, VertexShares>> vertices_;
};

// The shares of a BRDF value f = EvalBrdf(params, wo, wi) (local frame). The lobe's part
// ρs·scale + offset (SpecularWeights) is proportional to S at any α. For Ward's lobes
// S = g·exp(−Q)/(αx·αy), Q = qx/αx² + qy/αy² (SpecularFactorParts), so scaling both roughnesses
// by e^t gives ∂ln S/∂t = 2Q − 2 at t = 0; for the microfacet lobes it is a central difference
// in t. ρs scales only the `scale` part (Schlick's F0 = ρs leaves F's grazing part).
VertexShares BrdfShares(const BrdfParams& params, const Eigen::Vector3d& wo,
                        const Eigen::Vector3d& wi, const Eigen::Vector3d& f) {
  VertexShares out;
  double lobe_log_slope = 0;
  double qx = 0, qy = 0, g = 0;
  const double ax = params.AlphaX(), ay = params.AlphaY();
  if (SpecularFactorParts(params.model, wo, wi, &qx, &qy, &g)) {
    lobe_log_slope = 2 * (qx / (ax * ax) + qy / (ay * ay)) - 2;
  } else if (recon::IsMicrofacet(params.model)) {
    constexpr double kStep = 1e-4;
    const double up = std::exp(kStep), down = std::exp(-kStep);
    const double s_up = SpecularFactor<double>(params.model, ax * up, ay * up, wo, wi);
    const double s_down = SpecularFactor<double>(params.model, ax * down, ay * down, wo, wi);
    if (s_up > 0 && s_down > 0) lobe_log_slope = std::log(s_up / s_down) / (2 * kStep);
  }
  const LobeWeights w = recon::HasSpecularLobe(params.model)
                            ? SpecularWeights<double>(params.model, ax, ay, params.ior, wo, wi)
                            : LobeWeights{};
  for (int c = 0; c < 3; ++c) {
    if (!(f[c] > 0)) continue;
    const double diffuse = params.rho_d[c] * kInvPi * DiffuseFactor(params, wo, wi);
    const double lobe = std::clamp((f[c] - diffuse) / f[c], 0.0, 1.0);
    out.d[c] = std::min(1.0, diffuse / f[c]);
    out.s[c] = w.offset > 0 ? std::clamp(params.rho_s[c] * w.scale / f[c], 0.0, 1.0) : lobe;
    out.a[c] = lobe * lobe_log_slope;
  }
  return out;
}

// The shares of a hemispherical reflectance `albedo` (the ambient light's): its diffuse part is
// ρd, the rest the lobe's; the lobe's reflectance barely depends on α (no share).
VertexShares AlbedoShares(const Eigen::Vector3d& rho_d, const Eigen::Vector3d& albedo) {
  VertexShares out;
  for (int c = 0; c < 3; ++c) {
    if (!(albedo[c] > 0)) continue;
    out.d[c] = std::min(1.0, rho_d[c] / albedo[c]);
    out.s[c] = 1.0 - out.d[c];
  }
  return out;
}

// The uniform numbers SampleLight reads for a light of `type`: none for the delta lights, two for
// a sphere (the cone's θ and φ), three otherwise (triangle, then a point on it).
Eigen::Vector3d LightNumbers(recon::LightType type, Pcg32& rng) {
  switch (type) {
    case recon::LightType::kPoint:
    case recon::LightType::kSpot:
    case recon::LightType::kDirectional:
      return Eigen::Vector3d::Zero();
    case recon::LightType::kSphere: {
      const double u0 = rng.UniformDouble();
      return {u0, rng.UniformDouble(), 0.0};
    }
    default: {
      const double u0 = rng.UniformDouble();
      const double u1 = rng.UniformDouble();
      return {u0, u1, rng.UniformDouble()};
    }
  }
}

class PathTracer {
 public:
  PathTracer(const RenderScene& impl, const RenderOptions& options)
      : impl_(impl), options_(options) {
    for (int l = 0; l < static_cast<int>(impl.lights.size()); ++l) {
      if (impl.lights[l].type == recon::LightType::kAmbient) {
        ambient_ += impl.lights[l].light->radiance;
      } else {
        sampled_lights_.push_back(l);
      }
    }
    light_select_pdf_ = sampled_lights_.empty() ? 0.0 : 1.0 / double(sampled_lights_.size());
  }

  // Radiance arriving along the ray. reflected_only: leave out the emission of what the ray
  // meets first (lights, emitters), i.e. only light reflected by the first surface.
  // With `derivative`, also the radiance's derivatives with respect to the regions' albedo
  // scales (PathDerivative); the same random numbers and radiance either way.
  Eigen::Vector3d Trace(Eigen::Vector3d origin, Eigen::Vector3d dir, Pcg32& rng, uint64_t* rays,
                        bool reflected_only = false, PathDerivative* derivative = nullptr) const;

 private:
  // Adds an emitter's radiance seen along the path, MIS-weighted against light sampling.
  // Returns the term added.
  Eigen::Vector3d AddEmission(PathState* s, int light, const Eigen::Vector3d& le,
                              const Eigen::Vector3d& dir, const Eigen::Vector3d& hit_point,
                              const Eigen::Vector3d& hit_normal) const {
    double w = 1.0;
    if (!s->from_camera) {
      const double light_pdf =
          light_select_pdf_ * impl_.LightPdf(light, s->last_point, dir, hit_point, hit_normal);
      w = PowerHeuristic(1, s->bsdf_pdf, 1, light_pdf);
    }
    const Eigen::Vector3d term = s->throughput.cwiseProduct(le) * w;
    s->radiance += term;
    return term;
  }

  // Next-event estimation from a shading point. Returns the term added, and the BRDF value
  // toward the light in `f` (zero when nothing was added) and the light's direction in the
  // local frame in `wi_local`.
  Eigen::Vector3d SampleDirectLight(PathState* s, const Eigen::Vector3d& p,
                                    const Eigen::Vector3d& n_geo, const Frame& frame,
                                    const BrdfParams& params, const Eigen::Vector3d& wo_local,
                                    Pcg32& rng, Eigen::Vector3d* f,
                                    Eigen::Vector3d* wi_local) const;

  // The ambient lights' radiance reflected toward wo: L·∫ f(wo, wi) cosθi dωi over the
  // hemisphere, i.e. L·ρd exactly plus the specular lobe's directional albedo estimated with one
  // direction drawn from the lobe alone (weight f_s·cos/pdf_s, nearly constant for Ward's lobe).
  // No ray: nothing occludes an ambient light, and no other estimator counts it (light sampling
  // skips it and a BRDF-sampled ray never reaches it).
  // Returns the term added, and in `albedo` the hemispherical reflectance it used.
  Eigen::Vector3d AddAmbient(PathState* s, const BrdfParams& params,
                             const Eigen::Vector3d& wo_local, Pcg32& rng,
                             Eigen::Vector3d* albedo) const;

  const RenderScene& impl_;
  const RenderOptions& options_;
  std::vector<int> sampled_lights_;  // lights drawn by next-event estimation: all but ambient
  double light_select_pdf_ = 0;      // 1 / sampled_lights_.size()
  Eigen::Vector3d ambient_ = Eigen::Vector3d::Zero();  // total radiance of the ambient lights
};

Eigen::Vector3d PathTracer::AddAmbient(PathState* s, const BrdfParams& params,
                                       const Eigen::Vector3d& wo_local, Pcg32& rng,
                                       Eigen::Vector3d* albedo) const {
  *albedo = params.rho_d;
  if (!(ambient_.maxCoeff() > 0) || !(wo_local.z() > 0)) return Eigen::Vector3d::Zero();
  if (recon::HasSpecularLobe(params.model) && params.rho_s.maxCoeff() > 0) {
    BrdfParams lobe = params;  // ρd = 0: the draw comes from the specular lobe, pdf its own
    lobe.rho_d.setZero();
    const BrdfSample bs = SampleBrdf(lobe, wo_local, 0.0, rng.Uniform2D());
    if (bs.Valid()) *albedo += bs.weight;
  }
  const Eigen::Vector3d term = s->throughput.cwiseProduct(ambient_).cwiseProduct(*albedo);
  s->radiance += term;
  return term;
}

Eigen::Vector3d PathTracer::SampleDirectLight(PathState* s, const Eigen::Vector3d& p,
                                              const Eigen::Vector3d& n_geo, const Frame& frame,
                                              const BrdfParams& params,
                                              const Eigen::Vector3d& wo_local, Pcg32& rng,
                                              Eigen::Vector3d* f, Eigen::Vector3d* wi_out) const {
  f->setZero();
  wi_out->setUnit(2);
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  const int n = static_cast<int>(sampled_lights_.size());
  if (n == 0) return none;
  const int light =
      sampled_lights_[n == 1 ? 0 : std::min(static_cast<int>(rng.UniformDouble() * n), n - 1)];
  // A light that rays can hit (sphere, area) is sampled from the point the shadow ray and the
  // BSDF-sampled ray leave, so that its solid angle is the same for both techniques: a sphere
  // seen from p and from p + ε·n differs in a thin band at its rim that only the BSDF could
  // reach, with MIS weight 1 there (fireflies of the light's full radiance). Delta lights keep
  // the shading point itself (exact falloff).
  const Eigen::Vector3d origin = p + n_geo * impl_.ray_epsilon;
  const recon::LightType type = impl_.lights[light].type;
  const bool hittable = type == recon::LightType::kSphere || type == recon::LightType::kArea;
  const LightSample ls = impl_.SampleLight(light, hittable ? origin : p, LightNumbers(type, rng));
  if (!(ls.pdf > 0) || !(ls.value.maxCoeff() > 0) || !(ls.wi.dot(n_geo) > 0)) return none;
  const Eigen::Vector3d wi_local = frame.ToLocal(ls.wi);
  if (!(wi_local.z() > 0)) return none;
  *wi_out = wi_local;
  const BrdfEval fe = EvalBrdfAndPdf(params, wo_local, wi_local);
  if (!(fe.f.maxCoeff() > 0)) return none;
  const double eps = impl_.ray_epsilon;
  // The segment stops short of the light's surface (area lights are Embree geometry too).
  const double distance = std::isfinite(ls.distance)
                              ? ls.distance - std::max(4 * eps, 1e-6 * ls.distance)
                              : ls.distance;
  ++s->rays;
  if (impl_.Occluded(origin, ls.wi, distance, light)) return none;
  const double light_pdf = light_select_pdf_ * ls.pdf;
  const double w = ls.delta ? 1.0 : PowerHeuristic(1, light_pdf, 1, fe.pdf);
  const Eigen::Vector3d term =
      s->throughput.cwiseProduct(fe.f).cwiseProduct(ls.value) * (wi_local.z() * w / light_pdf);
  s->radiance += term;
  *f = fe.f;
  return term;
}

Eigen::Vector3d PathTracer::Trace(Eigen::Vector3d origin, Eigen::Vector3d dir, Pcg32& rng,
                                  uint64_t* rays, bool reflected_only,
                                  PathDerivative* derivative) const {
  const recon::Scene& scene = *impl_.scene;
  const recon::TriangleMesh& mesh = scene.mesh;
  PathState s;
  for (int bounce = 0;; ++bounce) {
    ++s.rays;
    const std::optional<Hit> hit = impl_.Intersect(origin, dir);
    if (!hit) break;
    const Eigen::Vector3d p = origin + hit->t * dir;
    if (hit->sphere_light >= 0) {
      const recon::Light& l = *impl_.lights[hit->sphere_light].light;
      if (!(reflected_only && bounce == 0)) {
        const Eigen::Vector3d term =
            AddEmission(&s, hit->sphere_light, l.radiance, dir, p, (p - l.center).normalized());
        if (derivative != nullptr) derivative->Add(term);
      }
      break;
    }
    if (hit->geometry > 0) {  // an area light's own mesh: emits on its front, absorbs
      const int light = impl_.area_light_of_geometry[hit->geometry];
      const Eigen::Vector3d& n = impl_.area_normals[hit->geometry][hit->primitive];
      if (n.dot(dir) < 0 && !(reflected_only && bounce == 0)) {
        const Eigen::Vector3d term =
            AddEmission(&s, light, impl_.lights[light].light->radiance, dir, p, n);
        if (derivative != nullptr) derivative->Add(term);
      }
      break;
    }
    const int tri_index = hit->primitive;
    const TriangleShading& ts = impl_.triangles[tri_index];
    const ShadingMaterial& m = impl_.materials[ts.material];
    Eigen::Vector3d n_geo = ts.normal;
    if (ts.emitter >= 0 && n_geo.dot(dir) < 0 && !(reflected_only && bounce == 0)) {
      const Eigen::Vector3d term =
          AddEmission(&s, impl_.emitter_material_light, m.emission, dir, p, n_geo);
      if (derivative != nullptr) derivative->Add(term);
    }
    if (!recon::IsReflective(m.model)) break;  // emitters and black surfaces absorb
    const double b0 = 1.0 - hit->u - hit->v;
    const Eigen::Vector3i& tri = mesh.triangles[tri_index];
    Eigen::Vector3d n_s = n_geo;
    if (!ts.flat) {
      n_s = (b0 * mesh.normals[tri[0]] + hit->u * mesh.normals[tri[1]] +
             hit->v * mesh.normals[tri[2]])
                .cast<double>()
                .normalized();
    }
    const Eigen::Vector3d wo = -dir;
    if (n_geo.dot(wo) < 0) {  // two-sided: shade the side the ray came from
      n_geo = -n_geo;
      n_s = -n_s;
    }
    if (!(n_s.dot(wo) > 0)) n_s = n_geo;
    Frame frame;
    if (m.tangent) {
      frame = Frame::FromNormalTangent(n_s, *m.tangent);
    } else if (ts.flat) {  // n_s = ±ts.normal: the precomputed frame, mirrored for the back
      const bool back = n_geo.dot(ts.normal) < 0;
      frame.t = ts.tangent;
      frame.b = back ? Eigen::Vector3d(-ts.bitangent) : ts.bitangent;
      frame.n = n_geo;
    } else {
      frame = Frame::FromNormal(n_s);
    }
    BrdfParams params = m.params;
    if (m.rho_d_map && mesh.has_uvs()) {
      const Eigen::Vector2d uv =
          (b0 * mesh.uvs[tri[0]] + hit->u * mesh.uvs[tri[1]] + hit->v * mesh.uvs[tri[2]])
              .cast<double>();
      params.rho_d = SampleTexture(*m.rho_d_map, uv);
    }
    const Eigen::Vector3d wo_local = frame.ToLocal(wo);
    Eigen::Vector3d f_light, light_wi, albedo;
    const Eigen::Vector3d direct =
        SampleDirectLight(&s, p, n_geo, frame, params, wo_local, rng, &f_light, &light_wi);
    const Eigen::Vector3d ambient = AddAmbient(&s, params, wo_local, rng, &albedo);
    if (derivative != nullptr) {
      derivative->Add(direct, ts.material, BrdfShares(params, wo_local, light_wi, f_light));
      derivative->Add(ambient, ts.material, AlbedoShares(params.rho_d, albedo));
    }

    // Lambert has one lobe: no number to pick it.
    const double u_lobe = recon::HasSpecularLobe(params.model) ? rng.UniformDouble() : 0.0;
    const Eigen::Vector2d u_dir = rng.Uniform2D();
    const BrdfSample bs = SampleBrdf(params, wo_local, u_lobe, u_dir);
    if (!bs.Valid()) break;
    const Eigen::Vector3d wi = frame.ToWorld(bs.wi);
    if (!(wi.dot(n_geo) > 0)) break;  // under the true surface (shading-normal artefact)
    s.throughput = s.throughput.cwiseProduct(bs.weight);
    if (derivative != nullptr)
      derivative->PushVertex(ts.material, BrdfShares(params, wo_local, bs.wi, bs.f));
    s.from_camera = false;
    s.bsdf_pdf = bs.pdf;
    s.last_point = p + n_geo * impl_.ray_epsilon;  // where the next ray leaves (MIS pdfs)
    if (bounce + 1 >= options_.max_bounces) break;
    if (bounce + 1 >= options_.rr_start_bounce) {
      const double q = std::min(0.95, s.throughput.maxCoeff());
      if (!(rng.UniformDouble() < q)) break;
      s.throughput /= q;
    }
    origin = s.last_point;
    dir = wi;
  }
  *rays += s.rays;
  return s.radiance;
}

recon::Camera ScaledCamera(const recon::Camera& camera, int width, int height) {
  recon::Camera out = camera;
  if (width <= 0 || height <= 0 || (width == camera.width && height == camera.height)) return out;
  const double sx = double(width) / camera.width, sy = double(height) / camera.height;
  out.params[0] *= sx;
  out.params[2] *= sx;
  out.params[1] *= sy;
  out.params[3] *= sy;
  out.width = width;
  out.height = height;
  return out;
}

}  // namespace

void RenderOptions::Validate() const {
  auto check = [](bool ok, const std::string& key, double value, const std::string& rule) {
    if (!ok) throw InputError(DescribeProblem("", key, std::to_string(value), rule));
  };
  check(spp >= 1, "--spp", spp, "must be >= 1");
  check(max_bounces >= 1, "--max-bounces", max_bounces, "must be >= 1");
  check(rr_start_bounce >= 1, "--rr-start-bounce", rr_start_bounce, "must be >= 1");
  check(width >= 0 && width <= 65536, "--width", width, "must be in [0, 65536] (0 = camera's)");
  check(height >= 0 && height <= 65536, "--height", height, "must be in [0, 65536] (0 = camera's)");
  check((width == 0) == (height == 0), "--width/--height", width, "give both or neither");
}

Renderer::Renderer(const recon::Scene& scene, int lighting) : rays_(scene, lighting) {}
Renderer::~Renderer() = default;

Image Renderer::Render(const recon::Camera& camera_in, const RenderOptions& options,
                       RenderSummary* summary) const {
  options.Validate();
  const auto start = std::chrono::steady_clock::now();
  const recon::Camera camera = ScaledCamera(camera_in, options.width, options.height);
  const std::vector<uint8_t>* mask = options.pixel_mask;
  if (mask && mask->size() != size_t(camera.width) * camera.height) {
    throw InputError(DescribeProblem("", "pixel_mask", std::to_string(mask->size()),
                                     "must hold one value per output pixel (" +
                                         std::to_string(camera.width) + " x " +
                                         std::to_string(camera.height) + ")"));
  }
  Image image(camera.width, camera.height, 3,
              mask ? std::numeric_limits<float>::quiet_NaN() : 0.0f);
  const PathTracer tracer(rays_.internal(), options);
  const Eigen::Vector3d center = camera.CenterInWorld();
  // PINHOLE rays straight from the intrinsics and a rotation matrix (what WorldRayFromImg
  // computes, without its per-call quaternion rotation); OPENCV goes through WorldRayFromImg.
  const bool pinhole = camera.model == recon::CameraModel::kPinhole;
  const Eigen::Matrix3d world_from_cam =
      camera.cam_from_world.rotation.conjugate().toRotationMatrix();
  auto camera_ray = [&](double px, double py) -> Eigen::Vector3d {
    if (!pinhole) return camera.WorldRayFromImg(Eigen::Vector2d(px, py));
    const Eigen::Vector3d d((px - camera.params[2]) / camera.params[0],
                            (py - camera.params[3]) / camera.params[1], 1.0);
    return (world_from_cam * d).normalized();
  };
  std::atomic<uint64_t> total_rays{0};
  Progress progress("igi-render", camera.height, 2.0, options.show_progress && ProgressAllowed());
  ParallelFor(
      0, camera.height,
      [&](int64_t y) {
        uint64_t rays = 0;
        for (int x = 0; x < camera.width; ++x) {
          const uint64_t pixel = uint64_t(y) * camera.width + x;
          if (mask && (*mask)[pixel] == 0) continue;
          Eigen::Vector3d sum = Eigen::Vector3d::Zero();
          for (int k = 0; k < options.spp; ++k) {
            Pcg32 rng = PixelSampleRng(options.seed, pixel, k);
            const Eigen::Vector2d jitter = rng.Uniform2D();
            const Eigen::Vector3d dir = camera_ray(x + jitter.x(), y + jitter.y());
            const Eigen::Vector3d l = tracer.Trace(center, dir, rng, &rays);
            if (l.allFinite()) sum += l;
          }
          const Eigen::Vector3d mean =
              sum * (camera.VignettingFactor(Eigen::Vector2d(x + 0.5, y + 0.5)) / options.spp);
          for (int c = 0; c < 3; ++c) image.at(x, int(y), c) = static_cast<float>(mean[c]);
        }
        total_rays += rays;
        progress.Add(1);
      },
      options.num_threads);
  progress.Finish();
  if (summary != nullptr) {
    summary->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    uint64_t pixels = uint64_t(camera.width) * camera.height;
    if (mask)
      pixels =
          uint64_t(std::count_if(mask->begin(), mask->end(), [](uint8_t v) { return v != 0; }));
    summary->camera_rays = pixels * options.spp;
    summary->rays = total_rays.load();
  }
  return image;
}

namespace {

// The mean of `spp` paths along one ray (non-finite paths dropped).
// With `d_ln_params`: also the mean's derivatives with respect to each region's parameter
// scales (Renderer::kDerivativeKinds entries per scene material, overwritten).
Eigen::Vector3d MeanRadiance(const RenderScene& impl, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& direction, int spp, uint64_t seed,
                             bool reflected_only,
                             std::vector<Eigen::Vector3d>* d_ln_params = nullptr) {
  RenderOptions options;
  const PathTracer tracer(impl, options);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  uint64_t rays = 0;
  std::vector<Eigen::Vector3d> path_d;
  if (d_ln_params != nullptr) {
    const size_t n = impl.materials.size() * Renderer::kDerivativeKinds;
    d_ln_params->assign(n, Eigen::Vector3d::Zero());
    path_d.resize(n);
  }
  for (int k = 0; k < spp; ++k) {
    Pcg32 rng = PixelSampleRng(seed, reflected_only ? 1 : 0, k);
    std::optional<PathDerivative> derivative;
    if (d_ln_params != nullptr) {
      std::fill(path_d.begin(), path_d.end(), Eigen::Vector3d::Zero());
      derivative.emplace(&path_d);
    }
    const Eigen::Vector3d l = tracer.Trace(origin, direction.normalized(), rng, &rays,
                                           reflected_only, derivative ? &*derivative : nullptr);
    if (!l.allFinite()) continue;
    sum += l;
    for (size_t r = 0; r < path_d.size(); ++r) (*d_ln_params)[r] += path_d[r];
  }
  const double n = std::max(1, spp);
  if (d_ln_params != nullptr) {
    for (Eigen::Vector3d& d : *d_ln_params) d /= n;
  }
  return sum / n;
}

}  // namespace

Eigen::Vector3d Renderer::Radiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                   int spp, uint64_t seed) const {
  return MeanRadiance(rays_.internal(), origin, direction, spp, seed, false);
}

Eigen::Vector3d Renderer::ReflectedRadiance(const Eigen::Vector3d& origin,
                                            const Eigen::Vector3d& direction, int spp,
                                            uint64_t seed) const {
  return MeanRadiance(rays_.internal(), origin, direction, spp, seed, true);
}

Eigen::Vector3d Renderer::ReflectedRadiance(const Eigen::Vector3d& origin,
                                            const Eigen::Vector3d& direction, int spp,
                                            uint64_t seed,
                                            std::vector<Eigen::Vector3d>* d_ln_params) const {
  return MeanRadiance(rays_.internal(), origin, direction, spp, seed, true, d_ln_params);
}

}  // namespace igi::render
