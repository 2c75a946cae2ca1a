// The prepared scene of one lighting: Embree geometry (scene mesh and the lighting's area
// lights), shading materials with their textures, and the lighting's emitters.
#include <embree3/rtcore.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>

#include "solver/render/render_internal.h"

namespace igi::render {

struct RenderScene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }
};

RenderScene::~RenderScene() = default;

namespace {

unsigned AttachTriangles(RTCDevice device, RTCScene rtc_scene,
                         const std::vector<Eigen::Vector3f>& positions,
                         const std::vector<Eigen::Vector3i>& triangles) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
  for (size_t i = 0; i < positions.size(); ++i) {
    vb[3 * i] = positions[i].x();
    vb[3 * i + 1] = positions[i].y();
    vb[3 * i + 2] = positions[i].z();
  }
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) ib[3 * t + k] = static_cast<unsigned>(triangles[t][k]);
  }
  rtcCommitGeometry(geom);
  const unsigned id = rtcAttachGeometry(rtc_scene, geom);
  rtcReleaseGeometry(geom);
  return id;
}

}  // namespace

ShadingMaterial MakeShadingMaterial(const recon::Material& m) {
  ShadingMaterial s;
  s.model = m.brdf;
  s.params.model = recon::IsReflective(m.brdf) ? m.brdf : recon::BrdfModel::kLambert;
  s.params.rho_d = m.rho_d.value_or(Eigen::Vector3d::Zero());
  s.params.rho_s = m.rho_s.value_or(Eigen::Vector3d::Zero());
  s.params.alpha = m.alpha.value_or(0.1);
  s.params.alpha_x = m.alpha_x.value_or(0.1);
  s.params.alpha_y = m.alpha_y.value_or(0.1);
  s.params.ior = m.ior.value_or(recon::Material::kDefaultIor);
  s.params.diffuse = m.diffuse;
  s.params.sigma = m.sigma.value_or(0.0);
  s.tangent = m.tangent;
  if (m.brdf == recon::BrdfModel::kEmitter)
    s.emission = m.radiance.value_or(Eigen::Vector3d::Zero());
  if (m.rho_d_map) {
    s.rho_d_map = std::make_shared<const Image>(ReadImage(*m.rho_d_map, 3));
    if (!m.rho_d) {  // the mean albedo, for anything that needs a region value
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      const Image& t = *s.rho_d_map;
      for (size_t i = 0; i < t.pixels.size(); i += 3) {
        sum += Eigen::Vector3d(t.pixels[i], t.pixels[i + 1], t.pixels[i + 2]);
      }
      s.params.rho_d = sum / double(t.width * t.height);
    }
  }
  return s;
}

namespace {

void AddTriangle(TriangleEmitter* e, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 const Eigen::Vector3d& c, const Eigen::Vector3d& radiance) {
  const double area = 0.5 * (b - a).cross(c - a).norm();
  if (!(area > 0)) return;
  e->v0.push_back(a);
  e->v1.push_back(b);
  e->v2.push_back(c);
  e->radiance.push_back(radiance);
  e->total_area += area;
  e->cdf.push_back(e->total_area);
}

// Unit geometric normals in double precision (front = counter-clockwise).
std::vector<Eigen::Vector3d> FaceNormals(const recon::TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.num_triangles());
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>();
    normals[t] = (mesh.positions[tri[1]].cast<double>() - a)
                     .cross(mesh.positions[tri[2]].cast<double>() - a)
                     .normalized();
  }
  return normals;
}

// The per-triangle shading records of the scene mesh (after emitter_triangle_index is set).
std::vector<TriangleShading> TriangleRecords(const RenderScene& impl) {
  const recon::TriangleMesh& mesh = impl.scene->mesh;
  const std::vector<Eigen::Vector3d> normals = FaceNormals(mesh);
  std::vector<TriangleShading> records(mesh.num_triangles());
  // Vertex normals this close to the face normal shade as the face itself (flat shading).
  constexpr double kFlatTolerance = 1e-6;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    TriangleShading& r = records[t];
    r.normal = normals[t];
    r.material = mesh.triangle_region[t];
    r.emitter = impl.emitter_triangle_index[t];
    const Frame frame = Frame::FromNormal(r.normal);
    r.tangent = frame.t;
    r.bitangent = frame.b;
    for (int k = 0; k < 3 && mesh.has_normals(); ++k) {
      const Eigen::Vector3d n = mesh.normals[mesh.triangles[t][k]].cast<double>();
      if (!((n - r.normal).cwiseAbs().maxCoeff() <= kFlatTolerance)) r.flat = false;
    }
  }
  return records;
}

}  // namespace

std::unique_ptr<RenderScene> BuildRenderScene(const recon::Scene& scene, int lighting) {
  auto impl = std::make_unique<RenderScene>();
  impl->scene = &scene;
  impl->lighting = lighting;
  for (const recon::Material& m : scene.materials)
    impl->materials.push_back(MakeShadingMaterial(m));

  impl->embree = std::make_unique<RenderScene::Embree>();
  impl->embree->device = rtcNewDevice(nullptr);
  if (impl->embree->device == nullptr) throw Error("cannot create the Embree device");
  impl->embree->scene = rtcNewScene(impl->embree->device);
  rtcSetSceneBuildQuality(impl->embree->scene, RTC_BUILD_QUALITY_HIGH);
  const recon::TriangleMesh& mesh = scene.mesh;
  AttachTriangles(impl->embree->device, impl->embree->scene, mesh.positions, mesh.triangles);
  impl->area_light_of_geometry.push_back(-1);
  impl->area_normals.emplace_back();

  // Scene extent sets the self-intersection offset.
  double extent = 1.0;
  for (const Eigen::Vector3f& p : mesh.positions)
    extent = std::max(extent, double(p.cwiseAbs().maxCoeff()));
  impl->ray_epsilon = 1e-5 * extent;

  for (int index : scene.lightings[lighting].lights) {
    const recon::Light& light = scene.lights[index];
    RenderLight rl;
    rl.type = light.type;
    rl.light = &light;
    if (light.type == recon::LightType::kSpot) rl.spot_frame = FrameFromAxis(light.direction);
    if (light.type == recon::LightType::kArea) {
      const recon::TriangleMesh& lm = light.mesh;
      for (const Eigen::Vector3i& t : lm.triangles) {
        AddTriangle(&rl.triangles, lm.positions[t[0]].cast<double>(),
                    lm.positions[t[1]].cast<double>(), lm.positions[t[2]].cast<double>(),
                    light.radiance);
      }
      AttachTriangles(impl->embree->device, impl->embree->scene, lm.positions, lm.triangles);
      impl->area_light_of_geometry.push_back(static_cast<int>(impl->lights.size()));
      impl->area_normals.push_back(FaceNormals(lm));
    }
    if (light.type == recon::LightType::kSphere)
      impl->sphere_lights.push_back(int(impl->lights.size()));
    impl->lights.push_back(std::move(rl));
  }
  // Triangles of "emitter" materials form one more light, sampled by area.
  RenderLight emitters;
  emitters.type = recon::LightType::kArea;
  impl->emitter_triangle_index.assign(mesh.num_triangles(), -1);
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    const ShadingMaterial& m = impl->materials[mesh.triangle_region[t]];
    if (!(m.emission.maxCoeff() > 0)) continue;
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const size_t before = emitters.triangles.v0.size();
    AddTriangle(&emitters.triangles, mesh.positions[tri[0]].cast<double>(),
                mesh.positions[tri[1]].cast<double>(), mesh.positions[tri[2]].cast<double>(),
                m.emission);
    if (emitters.triangles.v0.size() > before) impl->emitter_triangle_index[t] = int(before);
  }
  if (!emitters.triangles.v0.empty()) {
    impl->emitter_material_light = static_cast<int>(impl->lights.size());
    impl->lights.push_back(std::move(emitters));
  }
  impl->triangles = TriangleRecords(*impl);
  if (impl->lights.empty()) {
    throw InputError(DescribeProblem(scene.file.string(),
                                     "lightings." + scene.lightings[lighting].name, "",
                                     "the lighting has no light and no material emits: "
                                     "nothing to render"));
  }
  rtcCommitScene(impl->embree->scene);
  return impl;
}

namespace {

// Nearest positive intersection of a ray with a sphere, or infinity.
double IntersectSphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                       const Eigen::Vector3d& center, double radius) {
  const Eigen::Vector3d oc = o - center;
  const double b = oc.dot(d);
  const double c = oc.squaredNorm() - radius * radius;
  const double disc = b * b - c;
  if (disc < 0) return std::numeric_limits<double>::infinity();
  const double s = std::sqrt(disc);
  const double t0 = -b - s, t1 = -b + s;
  if (t0 > 1e-9) return t0;
  if (t1 > 1e-9) return t1;
  return std::numeric_limits<double>::infinity();
}

RTCRay MakeRay(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max) {
  RTCRay ray;
  ray.org_x = float(o.x());
  ray.org_y = float(o.y());
  ray.org_z = float(o.z());
  ray.dir_x = float(d.x());
  ray.dir_y = float(d.y());
  ray.dir_z = float(d.z());
  ray.tnear = 0.0f;
  // +infinity and NaN: the whole ray (a finite t_max beyond float's range rounds to +infinity).
  ray.tfar = t_max < std::numeric_limits<double>::infinity()
                 ? float(t_max)
                 : std::numeric_limits<float>::infinity();
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

}  // namespace

std::optional<Hit> RenderScene::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                          double t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rayhit;
  rayhit.ray = MakeRay(origin, dir, t_max);
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree->scene, &context, &rayhit);
  Hit hit;
  bool found = false;
  if (rayhit.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    hit.t = rayhit.ray.tfar;
    hit.geometry = static_cast<int>(rayhit.hit.geomID);
    hit.primitive = static_cast<int>(rayhit.hit.primID);
    hit.u = rayhit.hit.u;
    hit.v = rayhit.hit.v;
    found = true;
  }
  for (int i : sphere_lights) {
    const double t = IntersectSphere(origin, dir, lights[i].light->center, lights[i].light->radius);
    if (t < t_max && (!found || t < hit.t)) {
      hit = Hit();
      hit.t = t;
      hit.sphere_light = i;
      found = true;
    }
  }
  if (!found) return std::nullopt;
  return hit;
}

bool RenderScene::Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                           double distance, int target) const {
  if (!(distance > 0)) return false;  // ambient light: nothing occludes it
  for (int i : sphere_lights) {
    const recon::Light& l = *lights[i].light;
    if (i != target && IntersectSphere(origin, dir, l.center, l.radius) < distance) return true;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = MakeRay(origin, dir, distance);
  rtcOccluded1(embree->scene, &context, &ray);
  return ray.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace igi::render
