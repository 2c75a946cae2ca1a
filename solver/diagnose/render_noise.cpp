#include "solver/diagnose/render_noise.h"

#include <algorithm>
#include <cmath>

namespace igi::diagnose {

RenderNoise ChooseSpp(const PhotoSet& photos, const Simulation& sim, int spp, int spp_max,
                      double share) {
  double white = 0, render = 0, scale = 0;
  for (size_t i = 0; i < sim.sims.size() && i < photos.recorded.size(); ++i) {
    const Image& rec = photos.recorded[i];
    const Image& s = sim.sims[i];
    const Image* var = i < sim.variance.size() ? &sim.variance[i] : nullptr;
    for (int y = 0; y < rec.height; ++y) {
      for (int x = 0; x + 1 < rec.width; ++x) {
        if (photos.valid[i].at(x, y, 0) < 0.5f || photos.valid[i].at(x + 1, y, 0) < 0.5f) continue;
        for (int c = 0; c < 3; ++c) {
          const double e1 = s.at(x, y, c) - rec.at(x, y, c);
          const double e2 = s.at(x + 1, y, c) - rec.at(x + 1, y, c);
          if (!std::isfinite(e1) || !std::isfinite(e2)) continue;
          white += 0.5 * (e1 - e2) * (e1 - e2);
          // Both pixels' render variance enters the difference: their mean is one pixel's.
          if (var) render += 0.5 * (double(var->at(x, y, c)) + double(var->at(x + 1, y, c)));
          scale +=
              0.5 * (rec.at(x, y, c) * rec.at(x, y, c) + rec.at(x + 1, y, c) * rec.at(x + 1, y, c));
        }
      }
    }
  }
  RenderNoise n;
  n.spp_measured = n.spp = spp;
  if (!(scale > 0)) return n;
  n.white = white / scale;
  n.render = render / scale;
  n.photo = std::max(n.white - n.render, 0.01 * n.white);
  if (n.render > 0 && n.photo > 0 && spp_max > spp) {
    const double wanted = std::ceil(spp * n.render / (share * n.photo));
    n.spp = int(std::clamp(wanted, double(spp), double(spp_max)));
  }
  return n;
}

int MaxSpp(const DiagnoseOptions& o, const PhotoSet& photos) {
  if (o.spp_max >= 0) return o.spp_max;
  double pixels = 0;
  for (const Image& p : photos.recorded) pixels += double(p.width) * p.height;
  if (!(o.analysis_megapixels > 0) || !(pixels > 0)) return o.spp;
  return int(
      std::clamp(std::floor(o.spp * o.analysis_megapixels * 1e6 / pixels), double(o.spp), 65536.0));
}

Json RenderNoiseJson(const RenderNoise& n, double share) {
  return {{"white_residual", std::sqrt(n.white)},
          {"photo_noise", std::sqrt(n.photo)},
          {"render_noise", std::sqrt(n.render)},
          {"render_noise_at_spp", std::sqrt(n.render * n.spp_measured / n.spp)},
          {"spp_measured", n.spp_measured},
          {"spp", n.spp},
          {"render_variance_share_wanted", share}};
}

}  // namespace igi::diagnose
