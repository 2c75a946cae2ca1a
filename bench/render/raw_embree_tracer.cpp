#include "bench/render/raw_embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "solver/render/sampling.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace igi::bench {
namespace {

using Vec3 = Eigen::Vector3f;
constexpr unsigned kMaskSurfaces = 1;  // triangles: hit by every ray
constexpr unsigned kMaskSpheres = 2;   // sphere lights: hit by camera/bounce rays only
constexpr float kInf = std::numeric_limits<float>::infinity();

struct RawLight {
  recon::LightType type = recon::LightType::kPoint;
  Vec3 position = Vec3::Zero();  // point/spot position, sphere centre
  Vec3 direction = Vec3::UnitZ();
  float radius = 0;
  std::vector<Vec3> tri_vertices;  // area: 3 per triangle
};

unsigned AttachMesh(RTCDevice device, RTCScene scene, const recon::TriangleMesh& mesh) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                         mesh.positions.size()));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = mesh.positions[i][k];
  }
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                            RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                            mesh.triangles.size()));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) ib[3 * t + k] = static_cast<unsigned>(mesh.triangles[t][k]);
  }
  rtcSetGeometryMask(geom, kMaskSurfaces);
  rtcCommitGeometry(geom);
  const unsigned id = rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  return id;
}

void AttachSphere(RTCDevice device, RTCScene scene, const Eigen::Vector3d& c, double r) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
  vb[0] = float(c.x());
  vb[1] = float(c.y());
  vb[2] = float(c.z());
  vb[3] = float(r);
  rtcSetGeometryMask(geom, kMaskSpheres);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
}

// Distance along unit d from o to the sphere, or infinity.
float HitSphere(const Vec3& o, const Vec3& d, const Vec3& c, float r) {
  const Vec3 oc = o - c;
  const float b = oc.dot(d), disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0) return kInf;
  const float s = std::sqrt(disc);
  return -b - s > 1e-6f ? -b - s : (-b + s > 1e-6f ? -b + s : kInf);
}

float Uniform(render::Pcg32& rng) { return float(rng.NextUInt32() >> 8) * 0x1p-24f; }

// Cosine-distributed direction around unit n (Duff et al.'s frame, Malley's method).
Vec3 CosineAround(const Vec3& n, float u0, float u1) {
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float b = n.x() * n.y() * a;
  const Vec3 t(1.0f + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  const Vec3 bt(b, sign + n.y() * n.y() * a, -n.y());
  const float r = std::sqrt(u0), phi = 2.0f * float(render::kPi) * u1;
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  return t * x + bt * y + n * std::sqrt(std::max(0.0f, 1.0f - u0));
}

void InitRay(RTCRay* ray, const Vec3& o, const Vec3& d, float tfar, unsigned mask) {
  ray->org_x = o.x();
  ray->org_y = o.y();
  ray->org_z = o.z();
  ray->dir_x = d.x();
  ray->dir_y = d.y();
  ray->dir_z = d.z();
  ray->tnear = 0.0f;
  ray->tfar = tfar;
  ray->time = 0.0f;
  ray->mask = mask;
  ray->id = 0;
  ray->flags = 0;
}

}  // namespace

struct RawEmbreeTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<Vec3> normals;  // per scene triangle, unit
  std::vector<Vec3> albedo;   // per scene triangle
  std::vector<RawLight> lights;
  float epsilon = 1e-5f;
  bool embree_spheres = false;

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }

  // Direction and distance toward a point sampled on light `index`.
  float SampleLight(int index, const Vec3& p, render::Pcg32& rng, Vec3* wi) const;
  // One path; returns its rays (and counts shadow rays into *shadow).
  uint64_t TracePath(Vec3 origin, Vec3 dir, const RawTraceOptions& options, render::Pcg32& rng,
                     uint64_t* shadow) const;
};

float RawEmbreeTracer::Impl::SampleLight(int index, const Vec3& p, render::Pcg32& rng,
                                         Vec3* wi) const {
  const RawLight& l = lights[index];
  Vec3 target;
  switch (l.type) {
    case recon::LightType::kDirectional:
      *wi = -l.direction;
      return kInf;
    case recon::LightType::kSphere: {
      const float z = 1.0f - 2.0f * Uniform(rng), phi = 2.0f * float(render::kPi) * Uniform(rng);
      const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
      target = l.position + l.radius * Vec3(s * std::cos(phi), s * std::sin(phi), z);
      break;
    }
    case recon::LightType::kArea: {
      const size_t t = std::min<size_t>(size_t(Uniform(rng) * float(l.tri_vertices.size() / 3)),
                                        l.tri_vertices.size() / 3 - 1);
      float b1 = Uniform(rng), b2 = Uniform(rng);
      if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
      target = l.tri_vertices[3 * t] * (1 - b1 - b2) + l.tri_vertices[3 * t + 1] * b1 +
               l.tri_vertices[3 * t + 2] * b2;
      break;
    }
    default:
      target = l.position;
  }
  const Vec3 to = target - p;
  const float d = to.norm();
  *wi = to / d;
  return d * 0.999f;
}

uint64_t RawEmbreeTracer::Impl::TracePath(Vec3 origin, Vec3 dir, const RawTraceOptions& options,
                                          render::Pcg32& rng, uint64_t* shadow) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  uint64_t rays = 0;
  Vec3 throughput = Vec3::Ones();
  const int n_lights = static_cast<int>(lights.size());
  for (int bounce = 0;; ++bounce) {
    RTCRayHit rh;
    InitRay(&rh.ray, origin, dir, kInf, kMaskSurfaces | kMaskSpheres);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    ++rays;
    if (!embree_spheres) {
      for (const RawLight& l : lights) {
        if (l.type == recon::LightType::kSphere &&
            HitSphere(origin, dir, l.position, l.radius) < rh.ray.tfar) {
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        }
      }
    }
    if (rh.hit.geomID != 0) break;  // escaped, or hit an emitter
    const Vec3 p = origin + rh.ray.tfar * dir;
    Vec3 n = normals[rh.hit.primID];
    if (n.dot(dir) > 0) n = -n;
    const Vec3 p_off = p + n * epsilon;
    Vec3 wi;
    const int light = std::min(int(Uniform(rng) * float(n_lights)), n_lights - 1);
    const float distance = SampleLight(light, p_off, rng, &wi);
    if (wi.dot(n) > 0) {
      RTCRay shadow_ray;
      InitRay(&shadow_ray, p_off, wi, distance, kMaskSurfaces);
      rtcOccluded1(scene, &context, &shadow_ray);
      ++rays;
      ++*shadow;
    }
    throughput = throughput.cwiseProduct(albedo[rh.hit.primID]);
    if (bounce + 1 >= options.max_bounces) break;
    if (bounce + 1 >= options.rr_start_bounce) {
      const float q = std::min(0.95f, throughput.maxCoeff());
      if (!(Uniform(rng) < q)) break;
      throughput /= q;
    }
    const float u0 = Uniform(rng), u1 = Uniform(rng);
    dir = CosineAround(n, u0, u1);
    origin = p_off;
  }
  return rays;
}

RawEmbreeTracer::RawEmbreeTracer(const recon::Scene& scene, int lighting, bool embree_spheres)
    : impl_(std::make_unique<Impl>()) {
  impl_->embree_spheres = embree_spheres;
  impl_->device = rtcNewDevice(nullptr);
  if (impl_->device == nullptr) throw Error("cannot create the Embree device");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  const recon::TriangleMesh& mesh = scene.mesh;
  AttachMesh(impl_->device, impl_->scene, mesh);  // geometry 0
  float extent = 1.0f;
  for (const Vec3& p : mesh.positions) extent = std::max(extent, p.cwiseAbs().maxCoeff());
  impl_->epsilon = 1e-5f * extent;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    impl_->normals.push_back(mesh.FaceNormal(t));
    const recon::Material& m = scene.materials[mesh.triangle_region[t]];
    const Eigen::Vector3d a = m.rho_d.value_or(Eigen::Vector3d::Constant(0.5)) +
                              m.rho_s.value_or(Eigen::Vector3d::Zero());
    impl_->albedo.push_back(a.cast<float>());
  }
  for (int index : scene.lightings[lighting].lights) {
    const recon::Light& light = scene.lights[index];
    RawLight rl;
    rl.type = light.type;
    rl.position =
        (light.type == recon::LightType::kSphere ? light.center : light.position).cast<float>();
    rl.direction = light.direction.cast<float>();
    rl.radius = float(light.radius);
    if (light.type == recon::LightType::kSphere && embree_spheres)
      AttachSphere(impl_->device, impl_->scene, light.center, light.radius);
    if (light.type == recon::LightType::kArea) {
      for (const Eigen::Vector3i& t : light.mesh.triangles) {
        for (int k = 0; k < 3; ++k) rl.tri_vertices.push_back(light.mesh.positions[t[k]]);
      }
      AttachMesh(impl_->device, impl_->scene, light.mesh);
    }
    impl_->lights.push_back(std::move(rl));
  }
  if (impl_->lights.empty()) throw Error("raw tracer: the lighting has no light");
  rtcCommitScene(impl_->scene);
}

RawEmbreeTracer::~RawEmbreeTracer() = default;

RawTraceSummary RawEmbreeTracer::Trace(const recon::Camera& camera,
                                       const RawTraceOptions& options) const {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Matrix3f world_from_cam =
      camera.cam_from_world.rotation.conjugate().toRotationMatrix().cast<float>();
  const Vec3 center = camera.CenterInWorld().cast<float>();
  const float fx = float(camera.params[0]), fy = float(camera.params[1]);
  const float cx = float(camera.params[2]), cy = float(camera.params[3]);
  std::atomic<uint64_t> total{0}, total_shadow{0};
  ParallelFor(
      0, camera.height,
      [&](int64_t y) {
        uint64_t rays = 0, shadow = 0;
        for (int x = 0; x < camera.width; ++x) {
          const uint64_t pixel = uint64_t(y) * camera.width + x;
          for (int k = 0; k < options.spp; ++k) {
            render::Pcg32 rng(options.seed, pixel * uint64_t(options.spp) + uint64_t(k));
            const float px = float(x) + Uniform(rng), py = float(y) + Uniform(rng);
            const Vec3 d_cam((px - cx) / fx, (py - cy) / fy, 1.0f);
            rays += impl_->TracePath(center, (world_from_cam * d_cam).normalized(), options, rng,
                                     &shadow);
          }
        }
        total += rays;
        total_shadow += shadow;
      },
      options.num_threads);
  RawTraceSummary summary;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.rays = total.load();
  summary.shadow_rays = total_shadow.load();
  return summary;
}

}  // namespace igi::bench
