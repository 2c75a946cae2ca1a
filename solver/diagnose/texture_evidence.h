#pragma once
// Which solved regions are textured: their photos' ratio to a constant-albedo model varies from
// one surface cell to the next in the same way in two disjoint sets of photos.
//
// Why igi-diagnose needs it: it judges its candidates on a model whose solved regions have one
// albedo each (an albedo map could absorb any effect of the lights), but on a textured region
// the texture is then most of the residual, and a smooth candidate that happens to correlate
// with it earns a false gain. igi-run's demo showed it: its textured ceiling is darker than its
// mean under the lamp's hot spot, and an ambient light (which flattens the lit/unlit contrast)
// was kept with 23 standard errors. A texture differs from every effect of the lights or the
// camera in scale: those are smooth on a surface (or sharp along a few edges), a texture changes
// from cell to cell everywhere. So the test looks at the high-pass part of the ratio over surface
// cells (each cell's mean ratio minus its neighbours' mean) and asks that it be (a) reproducible
// between even and odd photos — photo noise is not: the rank correlation of the two sets' values
// over the cells, as a z (Spearman's ρ·√(n−1), a standard normal without a texture; ranks, so
// that a few extreme cells cannot carry it); (b) of the same sign in most cells — a few shadow or
// highlight edges are not most cells; (c) at least `min_amplitude` of the ratio.
// (a) is not the sign agreement's z: that ignores how large each cell's values are,
// and the suite's control, a textured floor at 4 % amplitude, stayed at z 3.9–4.1 (64 % of 218
// cells agreeing) — unmodelled, its texture raised a false missing_geometry.

#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/pixel_records.h"

namespace igi::diagnose {

struct TextureEvidenceOptions {
  double cell_m = 0.05;  // surface cell, metres
  // The test runs with cells of cell_m times each of these, finest first; a region is textured
  // when it passes at one of them. A coarser scale is tried only while the region's cells are
  // starved: their median count of records (the smaller of the two photo sets') is below
  // `dense_records`. One fine scale is blind to a texture of large flat tiles seen sparsely:
  // their high-pass lives only along the tiles' edges, and in small photos few fine cells hold
  // two records of each photo set. Coarse cells are where a few long edges (a shadow the model
  // lacks) become a larger share of the cells: on records dense enough for the fine scale they
  // are not tried.
  std::vector<double> scales = {1, 2, 3};
  int dense_records = 8;
  int min_cells = 30;            // cells seen by both photo sets with enough neighbours
  double min_agreement = 0.6;    // share of those cells whose high-pass signs agree
  double min_z = 5;              // the rank correlation's z (test (a))
  double min_amplitude = 0.015;  // reproducible high-pass RMS, relative to the mean ratio
  int min_records_per_cell = 2;  // per photo set
};

struct TextureEvidence {
  std::string region;
  double cell_m = 0;     // the cells of the scale reported: the first that passes, else the one of
                         // the highest z
  int cells = 0;         // cells compared
  double agreement = 0;  // share of cells whose high-pass signs agree between the photo sets
  double sign_z = 0;     // (agreement − ½)·2·√cells (reported)
  double rank_correlation = 0;  // Spearman's ρ of the two sets' high-pass values
  double z = 0;                 // ρ·√(cells − 1): the test (a)
  double amplitude = 0;         // √(trimmed mean of hA·hB) / mean ratio
  bool textured = false;
};

// One entry per region whose ρd the model solved (`solved[r]` true) and that has records; the
// training records (not held out, not outliers) are used.
std::vector<TextureEvidence> FindTexturedRegions(const recon::Scene& model,
                                                 const std::vector<PixelRecord>& records,
                                                 const std::vector<bool>& solved,
                                                 const TextureEvidenceOptions& options);

}  // namespace igi::diagnose
