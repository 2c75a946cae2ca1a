#pragma once
// The default synthetic room of igi-synth, in the spirit of Yu et al. 1999's synthetic test:
// a 4 m × 4 m × 3 m room (z up, origin at a floor corner) with
//   floor          ward (or ward_gmd), textured albedo (tiles), weak gloss
//   wall_y4        ward, glossy paint            glossy_box     ward, blue, sharp lobe
//   glossy_sphere  ward, red, smooth normals     matte_box      lambert
//   ceiling, wall_x0, wall_x4, wall_y0           lambert, different colours
// (--satin: the matte box a faint broad lobe; --poster: a striped poster on wall_x4)
// and two small lamps: "lamp" (lighting L0) and "lamp2" (lighting L1). Every material value is
// known (this is the TRUE scene); effects and the declared scene.json derive from it.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "solver/synth/synth_mesh.h"
#include "solver/synth/synth_options.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::synth {

struct SynthLamp {
  std::string name;
  Eigen::Vector3d position;  // centre, metres
  double intensity = 0;      // W·sr⁻¹ per channel (grey), the same in every direction
  double radius = 0;         // 0 = point light; else a sphere of radiance intensity/(π r²)
};

struct SynthRoom {
  Eigen::Vector3d size{4, 4, 3};            // the room spans [0, size] on each axis
  SynthMesh mesh;                           // geometry/room.obj (every region, UVs, normals)
  Json materials;                           // igi-scene "materials", complete (the truth)
  std::vector<std::string> glossy_regions;  // regions with a specular lobe, in placement order
  std::vector<SynthLamp> lamps;             // lamps[0] in L0, lamps[1] in L1
  Image floor_albedo;                       // linear RGB texture of the floor (rho_d_map)
  std::string floor_albedo_file;            // where it is written, relative to the scene folder
  // --textured-walls: the other regions' albedo textures, (file relative to the scene folder,
  // linear RGB image); empty otherwise.
  std::vector<std::pair<std::string, Image>> region_textures;
  // --poster: the poster's centre (it faces −x); the first overview cameras look at it.
  std::optional<Eigen::Vector3d> poster_center;

  // igi-scene "lights" and "lightings" for the lamps as they are.
  Json LightsJson() const;
  Json LightingsJson() const;
};

// Builds the room for `options` (glossy_brdf, lamp type, seed for the floor texture, unknowns
// deciding where the texture goes: textures/ when scene.json declares it, truth/textures/ when
// rho_d is unknown).
SynthRoom BuildRoom(const SynthOptions& options);

// The lamp as an igi-scene light (point, or sphere when radius > 0).
Json LampJson(const SynthLamp& lamp);

// Mean of a texture's RGB over its pixels (the region mean of an affinely mapped plane).
Eigen::Vector3d ImageMean(const Image& image);

}  // namespace igi::synth
