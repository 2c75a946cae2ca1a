#pragma once
// Cameras of a synthetic room. The first cameras each target one glossy region: a point p of
// the region that sees the lamp is chosen, the lamp direction is mirrored about the surface
// normal, and the camera is placed along the mirrored direction (inside the room, with nothing
// in between), looking at p, so the lamp's specular highlight is in the middle of its photo.
// The remaining cameras look at the room's centre from near the walls.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "recon/camera.h"
#include "solver/synth/room_builder.h"
#include "solver/synth/synth_options.h"

namespace igi::synth {

struct PlacedCamera {
  recon::Camera camera;       // PINHOLE, options' size and field of view
  std::string target_region;  // glossy region whose highlight it sees; "" = overview
  Eigen::Vector3d highlight_point = Eigen::Vector3d::Zero();  // world, metres
  Eigen::Vector2d highlight_pixel = Eigen::Vector2d::Zero();  // continuous pixel coordinates
};

// A PINHOLE camera at `eye` looking at `target` with world +z up (+y when looking nearly
// straight up or down); horizontal field of view `fov_deg`, principal point at the centre.
recon::Camera LookAtCamera(const std::string& name, const Eigen::Vector3d& eye,
                           const Eigen::Vector3d& target, int width, int height, double fov_deg);

// options.cameras cameras named cam0, cam1, … (deterministic for options.seed). Throws Error
// when a glossy region offers no viewpoint (a room-builder bug, not user input).
std::vector<PlacedCamera> PlaceCameras(const SynthRoom& room, const SynthOptions& options);

}  // namespace igi::synth
