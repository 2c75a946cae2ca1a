#include "solver/render/ray_scene.h"

#include "solver/render/render_internal.h"

namespace igi::render {

RayScene::RayScene(const recon::Scene& scene, int lighting)
    : scene_(BuildRenderScene(scene, lighting)) {}
RayScene::~RayScene() = default;
RayScene::RayScene(RayScene&&) noexcept = default;
RayScene& RayScene::operator=(RayScene&&) noexcept = default;

const recon::Scene& RayScene::scene() const { return *scene_->scene; }
int RayScene::lighting() const { return scene_->lighting; }
double RayScene::ray_epsilon() const { return scene_->ray_epsilon; }

std::optional<RayHit> RayScene::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                          double t_max) const {
  const std::optional<Hit> hit = scene_->Intersect(origin, dir, t_max);
  if (!hit) return std::nullopt;
  RayHit out;
  out.t = hit->t;
  if (hit->geometry == 0 && hit->sphere_light < 0) out.triangle = hit->primitive;
  return out;
}

std::optional<SurfaceHit> RayScene::TraceSurface(const Eigen::Vector3d& origin,
                                                 const Eigen::Vector3d& dir) const {
  const std::optional<Hit> hit = scene_->Intersect(origin, dir);
  if (!hit || hit->geometry != 0 || hit->sphere_light >= 0) return std::nullopt;
  const recon::TriangleMesh& mesh = scene_->scene->mesh;
  SurfaceHit s;
  s.triangle = hit->primitive;
  s.b1 = hit->u;
  s.b2 = hit->v;
  s.t = hit->t;
  s.position = origin + hit->t * dir;
  const TriangleShading& ts = scene_->triangles[s.triangle];
  s.region = ts.material;
  s.n_geo = ts.normal;
  s.n_s = s.n_geo;
  if (!ts.flat) {
    const Eigen::Vector3i& tri = mesh.triangles[s.triangle];
    const double b0 = 1.0 - s.b1 - s.b2;
    s.n_s = (b0 * mesh.normals[tri[0]] + s.b1 * mesh.normals[tri[1]] + s.b2 * mesh.normals[tri[2]])
                .cast<double>()
                .normalized();
  }
  s.front = s.n_geo.dot(dir) < 0;
  if (!s.front) {
    s.n_geo = -s.n_geo;
    s.n_s = -s.n_s;
  }
  if (!(s.n_s.dot(-dir) > 0)) s.n_s = s.n_geo;
  return s;
}

bool RayScene::Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double distance,
                        int target_light) const {
  return scene_->Occluded(origin, dir, distance, target_light);
}

int RayScene::num_lights() const { return static_cast<int>(scene_->lights.size()); }
recon::LightType RayScene::light_type(int light) const { return scene_->lights[light].type; }
const recon::Light* RayScene::light(int light) const { return scene_->lights[light].light; }

LightSample RayScene::SampleLight(int light, const Eigen::Vector3d& point,
                                  const Eigen::Vector3d& u) const {
  return scene_->SampleLight(light, point, u);
}

const Eigen::Vector3d& RayScene::face_normal(int triangle) const {
  return scene_->triangles[triangle].normal;
}
const ShadingMaterial& RayScene::material(int region) const { return scene_->materials[region]; }

}  // namespace igi::render
