#include "solver/inverse/observation_set.h"

#include <algorithm>

#include "solver/render/sampling.h"

namespace igi::solver {
namespace {

// Marks about `count` of `indices` (into `obs`) in `chosen` (all when there are no more), each
// drawn with the same probability by a hash of its photo and pixel; returns how many it marked.
// The indices were themselves collected with probability `collected` by the same hash
// (solver/inverse/observation_draw.h), so this draw is nested in that one: a pixel is marked when
// its hash falls under `collected` × count / indices.size(). Not by the observation's index: a
// change to one photo's observations (its pose, its mask, a pixel that passes an edge test or not)
// shifts every later photo's indices and redraws them all, and a faint lobe's ρs moved by up to 11
// points with the draw alone (bench/RESULTS.md).
size_t DrawSubset(const std::vector<Observation>& obs, const std::vector<int>& indices,
                  size_t count, double collected, std::vector<char>* chosen) {
  size_t marked = 0;
  const double p = indices.empty() ? 0.0 : collected * (double(count) / double(indices.size()));
  for (int i : indices) {
    const Observation& o = obs[i];
    if (render::InHashedSubset(PixelKey(o.photo, o.x, o.y), p)) {
      (*chosen)[i] = 1;
      ++marked;
    }
  }
  return marked;
}

}  // namespace

void SelectFitSamples(const std::vector<char>& fitted, const std::vector<char>& near_highlight,
                      size_t max_highlight_samples, size_t max_fit_samples, ObservationSet* set) {
  const std::vector<Observation>& obs = set->items;
  set->in_fit.assign(obs.size(), 0);
  std::vector<std::vector<int>> near(fitted.size()), rest(fitted.size());
  for (size_t i = 0; i < obs.size(); ++i) {
    const int r = obs[i].region;
    if (r >= 0 && size_t(r) < fitted.size() && fitted[r]) {
      (near_highlight[i] ? near : rest)[r].push_back(int(i));
    }
  }
  // The highlight observations carry ρs and α, the rest mostly the albedo: up to
  // max_highlight_samples of the first, then the rest (max_fit_samples in all, at least a third
  // of it). Both drawn by a hash of the observation's photo and pixel: a regular stride through
  // the photos' pixel rows aliased with a texture's period (the SolveSynth room's textured floor,
  // ρs 0.04: −10.3 % with the stride, +2.1 % drawn by hash).
  const size_t min_rest = max_fit_samples / 3;
  for (size_t r = 0; r < fitted.size(); ++r) {
    const size_t taken = DrawSubset(obs, near[r], max_highlight_samples,
                                    set->DrawnThreshold(int(r), true), &set->in_fit);
    const size_t budget = std::max(min_rest, max_fit_samples - std::min(taken, max_fit_samples));
    DrawSubset(obs, rest[r], budget, set->DrawnThreshold(int(r), false), &set->in_fit);
  }
}

}  // namespace igi::solver
