#include "solver/diagnose/effects/effects.h"

namespace igi::diagnose {

// The order is the driver's: the effects tried alone first come first (an object the geometry
// lacks before any albedo map), and a round's fits come out in this order.
std::vector<std::unique_ptr<Effect>> MakeEffects() {
  std::vector<std::unique_ptr<Effect>> effects;
  effects.push_back(MakeMissingGeometry());
  effects.push_back(MakeAlbedoTexture());
  effects.push_back(MakeExposureScale());
  effects.push_back(MakeVignetting());
  effects.push_back(MakeCameraResponse());
  effects.push_back(MakeAmbientLight());
  effects.push_back(MakeLightEmissionProfile());
  effects.push_back(MakeLightIntensity());
  effects.push_back(MakeLightSourceExtent());
  effects.push_back(MakeSpecularLobeShape());
  effects.push_back(MakeFresnel());
  effects.push_back(MakeAnisotropicReflection());
  effects.push_back(MakePoseError());
  effects.push_back(MakeSpecularReflection());
  effects.push_back(MakeDiffuseShape());
  return effects;
}

}  // namespace igi::diagnose
