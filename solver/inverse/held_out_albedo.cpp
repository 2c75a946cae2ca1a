#include "solver/inverse/held_out_albedo.h"

#include <algorithm>
#include <cmath>

#include "solver/inverse/texel_splat.h"

namespace igi::solver {

HeldOutAlbedo::Splat HeldOutAlbedo::SplatOf(int triangle, double b1, double b2) const {
  const TexelSplat t = BilinearTexelSplat(*atlas_, triangle, b1, b2);
  Splat s;
  for (int k = 0; k < 4; ++k) {
    s.texel[k] = int64_t(t.y[k]) * atlas_->width + t.x[k];
    s.weight[k] = t.weight[k];
  }
  return s;
}

void HeldOutAlbedo::Add(int photo, int triangle, double b1, double b2,
                        const Eigen::Vector3d& numerator, const Eigen::Vector3d& denominator) {
  if (!numerator.allFinite() || !denominator.allFinite() || !std::isfinite(b1) ||
      !std::isfinite(b2)) {
    return;
  }
  const Splat s = SplatOf(triangle, b1, b2);
  const int64_t texels = int64_t(atlas_->width) * atlas_->height;
  for (int k = 0; k < 4; ++k) {
    const double w = s.weight[k];
    if (!(w > 0)) continue;
    Sums& t = total_[s.texel[k]];
    Sums& p = per_photo_[int64_t(photo) * texels + s.texel[k]];
    for (int c = 0; c < 3; ++c) {
      t[c] += w * numerator[c], p[c] += w * numerator[c];
      t[3 + c] += w * denominator[c], p[3 + c] += w * denominator[c];
    }
    t[6] += w, p[6] += w;
  }
}

Eigen::Vector3d HeldOutAlbedo::At(int photo, int triangle, double b1, double b2) const {
  const Eigen::Vector3d none = Eigen::Vector3d::Constant(NAN);
  if (!std::isfinite(b1) || !std::isfinite(b2)) return none;
  const Splat s = SplatOf(triangle, b1, b2);
  const int64_t texels = int64_t(atlas_->width) * atlas_->height;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double used = 0;
  for (int k = 0; k < 4; ++k) {
    if (!(s.weight[k] > 0)) continue;
    const auto t = total_.find(s.texel[k]);
    if (t == total_.end()) continue;
    Sums held = t->second;
    const auto p = per_photo_.find(int64_t(photo) * texels + s.texel[k]);
    if (p != per_photo_.end()) {
      for (int j = 0; j < 7; ++j) held[j] -= p->second[j];
    }
    if (held[6] < kMinTexelWeight || !(std::min({held[3], held[4], held[5]}) > 0)) continue;
    for (int c = 0; c < 3; ++c) sum[c] += s.weight[k] * held[c] / held[3 + c];
    used += s.weight[k];
  }
  return used >= 0.5 ? Eigen::Vector3d(sum / used) : none;
}

}  // namespace igi::solver
