// IES LM-63 photometric profiles (recon/ies_profile.h): the file's tables as numpy arrays, its
// interpolated intensity, and the relative intensity a spot light with this profile emits in a
// direction, computed by the renderer's own code (recon::SpotProfile::Relative).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <memory>
#include <optional>

#include "python/src/bindings.h"
#include "recon/ies_profile.h"
#include "recon/scene.h"
#include "tools/common/error.h"
#include "tools/common/geometry.h"

namespace igi::python {
namespace {

using recon::IesProfile;
using IesPtr = std::shared_ptr<IesProfile>;

py::array_t<double> ToArray(const std::vector<double>& values) {
  py::array_t<double> out(py::ssize_t(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

// Relative intensity (0..1) toward each direction (N, 3): in the luminaire's frame (z its axis,
// the vertical angle's 0; x the horizontal angle's 0), or in the world frame of a spot light
// pointing along `axis`, with the azimuth reference the renderer gives it (FrameFromAxis).
py::array_t<double> Relative(const IesPtr& ies, const py::array& directions,
                             const std::optional<Eigen::Vector3d>& axis) {
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(directions);
  if (!d || d.ndim() != 2 || d.shape(1) != 3) {
    throw InputError(DescribeProblem("directions", "shape", "", "must be (N, 3)"));
  }
  if (axis && !(axis->norm() > 0)) {
    throw InputError(DescribeProblem("axis", "", "", "must be a non-zero vector"));
  }
  recon::SpotProfile profile;
  profile.kind = recon::SpotProfile::Kind::kIes;
  profile.ies = ies;
  const Eigen::Matrix3d world_from_spot = axis ? FrameFromAxis(*axis) : Eigen::Matrix3d::Identity();
  const py::ssize_t n = d.shape(0);
  py::array_t<double> out(n);
  const double* in = d.data();
  double* o = out.mutable_data();
  py::gil_scoped_release release;
  for (py::ssize_t i = 0; i < n; ++i) {
    const Eigen::Vector3d v(in[3 * i], in[3 * i + 1], in[3 * i + 2]);
    const double norm = v.norm();
    if (!(norm > 0)) {
      o[i] = 0.0;
      continue;
    }
    const Eigen::Vector3d local = world_from_spot.transpose() * (v / norm);
    const double theta = std::acos(std::clamp(local.z(), -1.0, 1.0));
    o[i] = profile.Relative(theta, std::atan2(local.y(), local.x()));
  }
  return out;
}

}  // namespace

void AddLights(py::module_& m) {
  py::class_<IesProfile, IesPtr>(
      m, "IesProfile",
      "An IESNA LM-63 photometric file: a luminaire's candela table over vertical angles (from "
      "nadir, the luminaire's axis) and horizontal angles (about the axis), in degrees. Read "
      "with IesProfile.read(path); every multiplier of the file is applied to the table.")
      .def_static(
          "read",
          [](const std::filesystem::path& path) {
            py::gil_scoped_release release;
            return IesPtr(std::make_shared<IesProfile>(recon::ReadIesProfile(path)));
          },
          py::arg("path"),
          "Reads and validates an LM-63 file (1986 to 2019); raises InputError naming the line, "
          "field and value on bad input.")
      .def_readonly("file", &IesProfile::file, "The path it was read from.")
      .def_readonly("standard", &IesProfile::standard,
                    "The header: \"IESNA:LM-63-2002\", \"IESNA91\", \"LM-63-1986\", ...")
      .def_readonly("keywords", &IesProfile::keywords,
                    "[TEST], [MANUFAC], ... values by keyword (without brackets).")
      .def_readonly("photometric_type", &IesProfile::photometric_type,
                    "1 = type C (the usual one), 2 = type B, 3 = type A.")
      .def_readonly("lamp_count", &IesProfile::lamp_count, "Number of lamps.")
      .def_readonly("lumens_per_lamp", &IesProfile::lumens_per_lamp,
                    "Lumens per lamp, or -1 for absolute photometry.")
      .def_readonly("candela_multiplier", &IesProfile::candela_multiplier,
                    "The file's candela multiplier (already applied to candela).")
      .def_readonly("input_watts", &IesProfile::input_watts, "Input power (W).")
      .def_property_readonly(
          "vertical_deg", [](const IesProfile& p) { return ToArray(p.vertical_deg); },
          "The vertical angles (V,) in degrees, increasing (0 = nadir, along the axis).")
      .def_property_readonly(
          "horizontal_deg", [](const IesProfile& p) { return ToArray(p.horizontal_deg); },
          "The horizontal angles (H,) in degrees, increasing (about the axis).")
      .def_property_readonly(
          "candela",
          [](const IesProfile& p) {
            const auto v = py::ssize_t(p.vertical_deg.size());
            const auto h = py::ssize_t(p.horizontal_deg.size());
            py::array_t<double> out({h, v});
            std::copy(p.candela.begin(), p.candela.end(), out.mutable_data());
            return out;
          },
          "The candela table (H, V): candela[j, i] is the intensity (cd) toward "
          "(vertical_deg[i], horizontal_deg[j]), multipliers applied.")
      .def_property_readonly("max_candela", &IesProfile::MaxCandela,
                             "The table's largest intensity (cd).")
      .def(
          "intensity",
          [](const IesProfile& p, const py::array_t<double>& vertical_deg,
             const py::array_t<double>& horizontal_deg) -> py::object {
            return py::vectorize([&p](double v, double h) { return p.Candela(v, h); })(
                vertical_deg, horizontal_deg);
          },
          py::arg("vertical_deg"), py::arg("horizontal_deg"),
          "Intensity (cd) toward (vertical, horizontal) in degrees, bilinear in the angles with "
          "the symmetry the horizontal range implies; numpy broadcasting. Type C: any angles "
          "(folded onto the sphere), 0 outside the vertical range.")
      .def("relative", &Relative, py::arg("directions"), py::arg("axis") = py::none(),
           "Relative intensity (N,) in [0, 1] toward directions (N, 3) as igi's renderer weighs "
           "a spot light with this profile: intensity / max_candela at the direction's vertical "
           "angle (from the axis) and horizontal angle (atan2(y, x), about it). Without `axis` "
           "the directions are in the luminaire's frame (z the axis, x horizontal angle 0); with "
           "it they are world directions from a spot pointing along `axis`, x the renderer's "
           "reference (world x projected off the axis, or world y for an axis near world x).")
      .def("total_lumens", &IesProfile::TotalLumens,
           "Luminous flux (lm) by the zonal-lumen method of photometric reports (type C only).")
      .def("interpolated_lumens", &IesProfile::InterpolatedLumens,
           "The exact integral (lm) of the interpolated distribution over the sphere (type C "
           "only).")
      .def("__repr__", [](const IesProfile& p) {
        return "<igi.lights.IesProfile " + p.file + ": " + std::to_string(p.vertical_deg.size()) +
               " x " + std::to_string(p.horizontal_deg.size()) + " angles>";
      });
}

}  // namespace igi::python
