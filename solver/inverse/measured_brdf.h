#pragma once
// Measured BRDFs and the fit of igi's reflectance models to them.
//
// The reader takes the Cornell gonioreflectometer's text format (../shared/data/real/
// measured_brdf): '#' comment lines, the number of wavelengths, the wavelengths (nm), then one
// row per measurement: θi φi θs φs (radians, from the normal; azimuths about it, so the mirror
// direction of (θi, φi) is (θi, φi + π)) followed by the BRDF (sr⁻¹) at every wavelength.
//
// The spectra become RGB by the mean over three bands: B = [400, 500) nm, G = [500, 600) nm,
// R = [600, 700] nm (a colorimetric conversion would mix the bands; for fitting a model, whose
// specular term is grey, bands keep every channel a measurement of its own).
//
// A model is fitted to a measurement by the solver's own region fit (region_fit.h), each row an
// observation under a directional light of unit irradiance: L = f·cosθi with E = cosθi. So the
// parameters and the residual are what igi-solve would find for a region made of that material
// seen from those directions, and the model with the smallest residual is the one the solver's
// and igi-diagnose's comparisons of models would pick on it.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "recon/brdf_model.h"
#include "solver/inverse/region_fit.h"

namespace igi::solver {

struct MeasuredBrdfSample {
  Eigen::Vector3d wi = Eigen::Vector3d::UnitZ();  // toward the light, local frame (z = normal)
  Eigen::Vector3d wo = Eigen::Vector3d::UnitZ();  // toward the sensor
  Eigen::Vector3d f = Eigen::Vector3d::Zero();    // the BRDF, RGB band means, sr⁻¹
};

struct MeasuredBrdf {
  std::filesystem::path file;
  std::vector<double> wavelengths_nm;
  std::vector<MeasuredBrdfSample> samples;
};

// Reads a Cornell .brdf file; a malformed file is an InputError naming the file, the line and the
// rule it breaks. Rows with a direction below the surface are an error, as are negative values.
MeasuredBrdf ReadCornellBrdf(const std::filesystem::path& file);

// Rows at or above this elevation (θi or θo) are "grazing" in MeasuredFit.
inline constexpr double kGrazingDeg = 60.0;

struct MeasuredFit {
  recon::BrdfModel model = recon::BrdfModel::kLambert;
  RegionFitResult fit;  // ρd, ρs, α and the fit's own residual (relative_rms)
  // Relative RMS error of the fitted model's f·cosθi·cosθo against the measurement's, over all
  // channels: all rows, the rows with θi and θo below kGrazingDeg, and the grazing rest.
  double error_all = 0, error_near = 0, error_grazing = 0;
  int rows_near = 0, rows_grazing = 0;
};

// Fits `model` (an isotropic reflective model: lambert or one with a lobe; a *_fresnel model
// with `ior`) to `measured`, with one grey ρs as the solver fits it.
MeasuredFit FitMeasuredBrdf(const MeasuredBrdf& measured, recon::BrdfModel model, double ior = 1.5);

}  // namespace igi::solver
