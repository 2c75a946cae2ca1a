#pragma once
// Internal to the renderer (solver/render/): the prepared scene of one lighting. Not public API
// (ray_scene.h is); Embree types stay out of it (the Embree scene is held behind an opaque handle).

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "recon/scene.h"
#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"
#include "tools/common/image.h"

namespace igi::render {

// A set of emitting triangles sampled by area (an area light, or the scene's emitter
// materials). Triangles emit `radiance` from their front (counter-clockwise) side.
struct TriangleEmitter {
  std::vector<Eigen::Vector3d> v0, v1, v2;  // world positions
  std::vector<Eigen::Vector3d> radiance;    // per triangle
  std::vector<double> cdf;                  // area CDF, last = total area
  double total_area = 0;
};

// One emitter of the lighting.
struct RenderLight {
  recon::LightType type =
      recon::LightType::kPoint;         // kArea also stands for emitter-material triangles
  const recon::Light* light = nullptr;  // nullptr for the emitter-material set
  Eigen::Matrix3d spot_frame = Eigen::Matrix3d::Identity();
  TriangleEmitter triangles;  // kArea
};

struct Hit {
  double t = 0;
  int geometry = -1;  // 0 = scene mesh, 1 + k = area light k's mesh
  int primitive = -1;
  double u = 0, v = 0;    // barycentrics of vertices 1 and 2
  int sphere_light = -1;  // >= 0: hit the sphere emitter lights[sphere_light]
};

// Per scene triangle, precomputed once so that shading a hit reads one record.
struct TriangleShading {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // geometric, unit, front = CCW
  int material = 0;                                   // index into materials
  int emitter = -1;  // index in the emitter-material light's triangles, or -1
  bool flat = true;  // vertex normals all equal the face normal: no interpolation
  // Frame::FromNormal(normal)'s t and b: the shading frame of a flat triangle seen from its
  // front; (t, -b, -normal) from its back.
  Eigen::Vector3d tangent = Eigen::Vector3d::UnitX();
  Eigen::Vector3d bitangent = Eigen::Vector3d::UnitY();
};

// The prepared scene of one lighting (RayScene's and the Renderer's).
struct RenderScene {
  const recon::Scene* scene = nullptr;
  int lighting = -1;
  std::vector<ShadingMaterial> materials;   // per scene material
  std::vector<RenderLight> lights;          // emitters of the lighting
  std::vector<int> area_light_of_geometry;  // geometry id -> index into lights (-1 for mesh)
  int emitter_material_light = -1;          // index into lights of the emitter-material set
  std::vector<int> emitter_triangle_index;  // scene triangle -> index in that set (or -1)
  std::vector<TriangleShading> triangles;   // per scene triangle
  std::vector<int> sphere_lights;           // indices into lights of the sphere emitters
  std::vector<std::vector<Eigen::Vector3d>> area_normals;  // geometry id -> triangle normals
  double ray_epsilon = 1e-4;                               // self-intersection offset, metres
  struct Embree;
  std::unique_ptr<Embree> embree;

  // Closest hit along the ray within (0, t_max); nullopt when it escapes.
  std::optional<Hit> Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                               double t_max = std::numeric_limits<double>::infinity()) const;
  // True when something blocks the segment from origin to origin + dir * distance. The sphere
  // of light `target` (the light the segment leads to) is not tested: from an offset origin, a
  // ray toward the sphere's silhouette would otherwise clip the sphere itself.
  bool Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double distance,
                int target = -1) const;

  // Light sampling (render_lights.cpp).
  LightSample SampleLight(int light, const Eigen::Vector3d& point, const Eigen::Vector3d& u) const;
  // Solid-angle pdf of sampling `dir` from `point` toward light `light` hitting it at
  // `hit_point` (for MIS of BRDF-sampled hits on area and sphere emitters).
  double LightPdf(int light, const Eigen::Vector3d& point, const Eigen::Vector3d& dir,
                  const Eigen::Vector3d& hit_point, const Eigen::Vector3d& hit_normal) const;

  ~RenderScene();
};

// Builds the Embree scene, materials and lights (render_scene.cpp).
std::unique_ptr<RenderScene> BuildRenderScene(const recon::Scene& scene, int lighting);

}  // namespace igi::render
