#pragma once
// Internal to igi_solver: the observations one solve fits (solver/inverse/observations.h), as a
// set: the observations themselves, the draw they were collected under
// (solver/inverse/observation_draw.h) and which of them the region fits use (the fit samples).
//
// The set is the solve's first product (read from the photos, then fixed except for their
// radiance's units: solver/inverse/photometric_scale.h); the light model
// (solver/inverse/light_model.h) and the material estimate (solver/inverse/material_estimate.h)
// hold their per-observation values in the set's order.

#include <cstddef>
#include <vector>

#include "solver/inverse/observation_draw.h"
#include "solver/inverse/observations.h"

namespace igi::solver {

struct ObservationSet {
  std::vector<Observation> items;
  // Per observation: whether the region fits use it (SelectFitSamples).
  std::vector<char> in_fit;
  // The draw the observations were collected under; draw.census false: every pixel at the
  // stride, each probability 1.
  ObservationDraw draw;

  size_t size() const { return items.size(); }
  bool empty() const { return items.empty(); }
  Observation& operator[](size_t i) { return items[i]; }
  const Observation& operator[](size_t i) const { return items[i]; }
  std::vector<Observation>::iterator begin() { return items.begin(); }
  std::vector<Observation>::iterator end() { return items.end(); }
  std::vector<Observation>::const_iterator begin() const { return items.begin(); }
  std::vector<Observation>::const_iterator end() const { return items.end(); }

  // The share of region r's pixels at the stride (near a highlight or not) that observations
  // were drawn at (their density), and the hash threshold they were drawn under (the same for
  // single pixels, larger for blocks: solver/inverse/observation_draw.h).
  double DrawnShare(int region, bool near) const {
    return draw.census ? draw.Probability(region, near) : 1.0;
  }
  double DrawnThreshold(int region, bool near) const {
    return draw.census ? draw.Threshold(region, near) : 1.0;
  }
};

// Marks the fit samples (set->in_fit, every other observation unmarked): per region r with
// fitted[r], its observations near a possible highlight (near_highlight[i]: they carry a lobe's
// ρs and α) up to max_highlight_samples, then the rest up to max_fit_samples less those taken (at
// least a third of max_fit_samples). Each is drawn by a hash of the observation's photo and
// pixel, nested in the draw the observations were collected under: the draw does not move when
// another photo's observations change, and a regular stride does not alias with a texture.
void SelectFitSamples(const std::vector<char>& fitted, const std::vector<char>& near_highlight,
                      size_t max_highlight_samples, size_t max_fit_samples, ObservationSet* set);

}  // namespace igi::solver
