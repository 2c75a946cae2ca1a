#include "solver/light_model.h"

#include <algorithm>

#include "solver/neighbour_mean.h"
#include "tools/common/parallel.h"

namespace igi {

std::vector<Eigen::Vector3d> NeighbourMean(const ObservationSet& obs,
                                           const std::vector<LightingState>& lightings,
                                           const std::vector<Eigen::Vector3d>& values,
                                           double radius, bool same_photo, int num_threads,
                                           const std::vector<float>* point_radius) {
  std::vector<Eigen::Vector3d> out(obs.size(), Eigen::Vector3d::Zero());
  std::vector<NeighbourPoint> points(obs.size());
  for (size_t i = 0; i < obs.size(); ++i) {
    points[i] = {obs[i].position, obs[i].normal, obs[i].region, obs[i].photo};
  }
  for (const LightingState& st : lightings) {
    if (st.active) {
      NeighbourMean(points, values, st.obs, radius, same_photo, num_threads, &out, point_radius);
    }
  }
  return out;
}

void SmoothIrradiance(const ObservationSet& obs, int num_threads, LightModel* light) {
  double widest = 0;  // the grid's cell
  for (float r : light->smoothing_radius) widest = std::max(widest, double(r));
  const std::vector<Eigen::Vector3d> smooth =
      NeighbourMean(obs, light->lightings, light->e_indirect, widest, false, num_threads,
                    &light->smoothing_radius);
  light->e.resize(obs.size());
  for (size_t i = 0; i < obs.size(); ++i) light->e[i] = light->e_direct[i] + smooth[i];
}

std::vector<Eigen::Vector3d> SpecularTerms(const ObservationSet& obs,
                                           const MaterialEstimate& materials,
                                           const std::vector<std::vector<IncidentLocal>>& incident,
                                           int num_threads) {
  std::vector<Eigen::Vector3d> out(obs.size(), Eigen::Vector3d::Zero());
  ParallelFor(
      0, int64_t(obs.size()),
      [&](int64_t i) {
        const Observation& o = obs[i];
        const MaterialState& m = materials[o.region];
        if (!HasSpecularLobe(m.params.model)) return;
        const Eigen::Vector3d wo =
            materials.LocalFrame(o.region, o.normal.cast<double>()).ToLocal(o.view.cast<double>());
        const double ax = WidenedAlpha(m.params.AlphaX(), o.lobe_blur2);
        const double ay = WidenedAlpha(m.params.AlphaY(), o.lobe_blur2);
        Eigen::Vector3d t = Eigen::Vector3d::Zero();
        for (const IncidentLocal& inc : incident[i]) {
          const double w =
              SpecularWeight(m.params.model, ax, ay, m.params.ior, wo, inc.Wi().cast<double>());
          if (w > 0) t += w * inc.Value().cast<double>();
        }
        out[i] = t;
      },
      num_threads);
  return out;
}

}  // namespace igi
