#pragma once
// Ray queries on one lighting of a scene, for the inverse solver and igi-diagnose: the first
// surface along a ray, shadow tests, light samples toward the lighting's emitters, and each
// region's shading parameters. It is the scene the path tracer traces (Embree geometry of the
// scene mesh and of the lighting's area and sphere lights); Embree stays private to the renderer.
// World frame, metres; directions are unit vectors.

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>

#include "recon/scene.h"
#include "solver/render/brdf.h"
#include "tools/common/image.h"

namespace igi::render {

struct RenderScene;  // the renderer's prepared scene (solver/render/render_internal.h)

// A surface's reflectance, ready to shade.
struct ShadingMaterial {
  recon::BrdfModel model = recon::BrdfModel::kLambert;
  BrdfParams params;                                   // rho_d replaced per hit when textured
  std::optional<Eigen::Vector3d> tangent;              // anisotropic models (world)
  std::shared_ptr<const Image> rho_d_map;              // linear albedo texture
  Eigen::Vector3d emission = Eigen::Vector3d::Zero();  // "emitter": radiance of the front side
};

// `m` ready to shade (its albedo map read, if any; unknown values as placeholders).
ShadingMaterial MakeShadingMaterial(const recon::Material& m);

// Texture lookup: bilinear, u right and v up (v = 0 is the bottom row); coordinates outside
// [0, 1] repeat, texels at the borders clamp. RGB of a 3-channel linear texture.
Eigen::Vector3d SampleTexture(const Image& texture, Eigen::Vector2d uv);

// The first thing along a ray.
struct RayHit {
  double t = 0;       // distance along the (unit) direction
  int triangle = -1;  // scene mesh triangle; -1 when the ray met a light's own geometry
};

// The first scene surface along a ray, with its shading frame.
struct SurfaceHit {
  int triangle = -1;
  double b1 = 0, b2 = 0;  // barycentrics of vertices 1 and 2
  double t = 0;
  int region = -1;  // index into Scene::materials
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_geo = Eigen::Vector3d::UnitZ();  // face normal, on the ray origin's side
  Eigen::Vector3d n_s = Eigen::Vector3d::UnitZ();    // shading normal, on the same side
  bool front = true;  // the ray arrived on the face's front (counter-clockwise) side
};

// A sampled direction toward a light, from a shading point.
struct LightSample {
  Eigen::Vector3d wi = Eigen::Vector3d::Zero();     // world, unit
  double distance = 0;                              // to the light (infinity: directional)
  Eigen::Vector3d value = Eigen::Vector3d::Zero();  // radiance, or I/d² or E for delta lights
  double pdf = 0;                                   // solid angle; 1 for delta lights
  bool delta = false;
};

class RayScene {
 public:
  // `scene` must have complete materials and outlive this object. Throws InputError as the
  // Renderer does (no light and no emitter material, an unreadable texture).
  RayScene(const recon::Scene& scene, int lighting);
  ~RayScene();
  RayScene(RayScene&&) noexcept;
  RayScene& operator=(RayScene&&) noexcept;

  const recon::Scene& scene() const;
  int lighting() const;
  // Offset along the normal that keeps a ray leaving a surface from hitting it again, metres.
  double ray_epsilon() const;

  // The closest hit along origin + t·dir, t in (0, t_max); nullopt when the ray escapes.
  std::optional<RayHit> Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                  double t_max = std::numeric_limits<double>::infinity()) const;
  // The first surface of the scene mesh along the ray; nullopt when the ray escapes or first
  // meets a light's own geometry (sphere or area emitter).
  std::optional<SurfaceHit> TraceSurface(const Eigen::Vector3d& origin,
                                         const Eigen::Vector3d& dir) const;
  // True when something blocks the segment from origin to origin + dir·distance. The sphere of
  // light `target_light` (the light the segment leads to) is not tested: from an offset origin,
  // a ray toward the sphere's silhouette would otherwise clip the sphere itself.
  bool Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double distance,
                int target_light = -1) const;

  // The lighting's emitters: its lights, then (when the scene has emitter materials) one
  // emitter standing for all of their triangles, of type kArea.
  int num_lights() const;
  recon::LightType light_type(int light) const;
  const recon::Light* light(int light) const;  // nullptr for the emitter-material set
  // A direction toward `light` from `point`, from the uniform numbers `u` in [0, 1)³.
  LightSample SampleLight(int light, const Eigen::Vector3d& point, const Eigen::Vector3d& u) const;

  // A scene triangle's geometric normal (unit, front = counter-clockwise).
  const Eigen::Vector3d& face_normal(int triangle) const;
  // A region's (scene material's) shading parameters.
  const ShadingMaterial& material(int region) const;

  // The renderer's own view of the scene (used inside solver/render only).
  const RenderScene& internal() const { return *scene_; }

 private:
  std::unique_ptr<RenderScene> scene_;
};

}  // namespace igi::render
