#include "solver/inverse/photo_model.h"

#include <algorithm>

namespace igi::solver {

bool PixelHoldout::HeldOut(int photo, int x, int y) const {
  return fraction > 0 && Draw(photo, x, y) < fraction;
}

int PixelHoldout::Fold(int photo, int x, int y, int folds) const {
  const double u = Draw(photo, x, y);
  if (fraction > 0 && u < fraction) return 0;
  const double f = std::max(fraction, 0.0);
  return 1 + std::clamp(int((u - f) / (1 - f) * (folds - 1)), 0, std::max(folds - 2, 0));
}

double PixelHoldout::Draw(int photo, int x, int y) const {
  // SplitMix64 of the block's coordinates: an even, reproducible choice of blocks.
  uint64_t z = seed * 0x9E3779B97F4A7C15ull + uint64_t(photo) * 0xBF58476D1CE4E5B9ull +
               uint64_t(x / block_px) * 0x94D049BB133111EBull +
               uint64_t(y / block_px) * 0x2545F4914F6CDD1Dull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

bool HasPhotoModel(const recon::Photo& photo, const recon::Camera& camera) {
  return photo.HasResponse() || photo.exposure_scale != 1.0 || camera.HasVignetting();
}

Image LinearRadianceOfPhoto(const recon::Photo& photo, const recon::Camera& camera,
                            const Image& recorded) {
  Image out = recorded;
  if (!HasPhotoModel(photo, camera)) return out;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const double f =
          photo.exposure_scale * camera.VignettingFactor(Eigen::Vector2d(x + 0.5, y + 0.5));
      for (int c = 0; c < out.channels; ++c) {
        float& v = out.at(x, y, c);
        v = float(photo.LinearFromRecorded(v) / f);
      }
    }
  }
  return out;
}

void ApplyExposureAndResponse(const recon::Photo& photo, Image* render) {
  if (!photo.HasResponse() && photo.exposure_scale == 1.0) return;
  for (float& v : render->pixels) v = float(photo.RecordedFromLinear(v * photo.exposure_scale));
}

}  // namespace igi::solver
