// The reflectance models (solver/render/brdf.h) evaluated and sampled at arrays of directions, for
// comparisons with other renderers. A material crosses as the JSON text of a scene.json material
// entry and is read by the scene loader's rules (recon::ReadMaterialEntry), so every model and
// diffuse shape igi has is available and a bad entry raises the loader's InputError. Directions
// are (N, 3) float64 arrays, in the local shading frame (z the normal, x the tangent) unless
// normals are given; the loops run in C++ with the GIL released.
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "python/src/bindings.h"
#include "recon/brdf_model.h"
#include "recon/scene.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::python {
namespace {

using render::BrdfParams;
using Rows3 = py::array_t<double, py::array::c_style | py::array::forcecast>;

// What the messages name as the material's file.
constexpr const char* kMaterialFile = "material";

// A material entry parsed into the renderer's parameters, and the tangent it states (world).
struct ParsedMaterial {
  BrdfParams params;
  std::optional<Eigen::Vector3d> tangent;
};

// Reads `json_text` (one scene.json material entry) by LoadScene's rules with every value the
// renderer needs required. An anisotropic entry without "tangent" is read as if its tangent were
// the local x axis: in the local frame x is the tangent by definition.
ParsedMaterial ParseMaterial(const std::string& json_text) {
  Json entry = ParseJson(json_text, kMaterialFile);
  bool tangent_stated = true;
  if (entry.is_object() && !entry.contains("tangent") && entry.contains("brdf") &&
      entry["brdf"].is_string()) {
    const auto model = recon::BrdfModelFromName(entry["brdf"].get<std::string>());
    if (model && recon::IsAnisotropic(*model)) {
      entry["tangent"] = Json::array({1.0, 0.0, 0.0});
      tangent_stated = false;
    }
  }
  recon::SceneLoadOptions options;
  options.load_geometry = false;
  options.check_images = false;
  options.require_complete_materials = true;
  const recon::Material m = recon::ReadMaterialEntry(
      entry, kMaterialFile, std::filesystem::current_path(), kMaterialFile, options);
  if (!recon::IsReflective(m.brdf)) {
    throw InputError(DescribeProblem(kMaterialFile, "brdf", std::string(BrdfModelName(m.brdf)),
                                     "has no BRDF to evaluate (emitter and black are not "
                                     "reflectance models)"));
  }
  if (m.rho_d_map) {
    throw InputError(DescribeProblem(kMaterialFile, "rho_d_map", m.rho_d_map->string(),
                                     "a texture is not one BRDF: give rho_d instead"));
  }
  ParsedMaterial out;
  BrdfParams& p = out.params;
  p.model = m.brdf;
  p.rho_d = *m.rho_d;
  if (m.rho_s) p.rho_s = *m.rho_s;
  if (m.alpha) p.alpha = *m.alpha;
  if (m.alpha_x) p.alpha_x = *m.alpha_x;
  if (m.alpha_y) p.alpha_y = *m.alpha_y;
  p.ior = m.ior.value_or(recon::Material::kDefaultIor);
  p.diffuse = m.diffuse;
  p.sigma = m.sigma.value_or(0.0);
  if (tangent_stated) out.tangent = m.tangent;
  return out;
}

// An (N, 3) array's rows; N is checked against `n` unless `n` < 0. (The Python layer broadcasts
// (3,) vectors to (N, 3) before the call.)
struct Vectors {
  Rows3 array;
  py::ssize_t rows = 0;
  Eigen::Vector3d operator()(py::ssize_t i) const {
    const double* d = array.data() + 3 * i;
    return {d[0], d[1], d[2]};
  }
};

Vectors ReadVectors(const py::handle& value, const char* name, py::ssize_t n) {
  Vectors v;
  v.array = Rows3::ensure(value);
  if (!v.array || v.array.ndim() != 2 || v.array.shape(1) != 3 ||
      (n >= 0 && v.array.shape(0) != n)) {
    const std::string rows = n >= 0 ? std::to_string(n) : std::string("N");
    throw InputError(DescribeProblem(name, "shape", "", "must be (" + rows + ", 3)"));
  }
  v.rows = v.array.shape(0);
  return v;
}

// The shading frame of each row: the identity (directions given in the local frame already), or
// the frame of the row's normal and tangent (the material's tangent when none is given; any
// tangent when neither is, for the isotropic models).
struct Frames {
  std::optional<Vectors> normal, tangent;
  std::optional<Eigen::Vector3d> material_tangent;
  render::Frame At(py::ssize_t i) const {
    if (!normal) return {};
    const Eigen::Vector3d n = (*normal)(i).normalized();
    if (tangent) return render::Frame::FromNormalTangent(n, (*tangent)(i));
    if (material_tangent) return render::Frame::FromNormalTangent(n, *material_tangent);
    return render::Frame::FromNormal(n);
  }
};

Frames ReadFrames(const py::object& normal, const py::object& tangent, const ParsedMaterial& m,
                  py::ssize_t n) {
  Frames f;
  if (normal.is_none()) {
    if (!tangent.is_none()) {
      throw InputError(DescribeProblem("tangent", "", "",
                                       "needs normal (without it directions are local and x is "
                                       "the tangent)"));
    }
    return f;
  }
  f.normal = ReadVectors(normal, "normal", n);
  if (!tangent.is_none()) f.tangent = ReadVectors(tangent, "tangent", n);
  f.material_tangent = m.tangent;
  if (recon::IsAnisotropic(m.params.model) && !f.tangent && !f.material_tangent) {
    throw InputError(DescribeProblem(kMaterialFile, "tangent", "",
                                     "an anisotropic model with normals needs a tangent (the "
                                     "material's \"tangent\" or the tangent argument)"));
  }
  return f;
}

py::array_t<double> Array(py::ssize_t rows, py::ssize_t columns) {
  if (columns == 1) return py::array_t<double>(rows);
  return py::array_t<double>({rows, columns});
}

py::array_t<double> Evaluate(const std::string& material, const py::object& wi_in,
                             const py::object& wo_in, const py::object& normal,
                             const py::object& tangent) {
  const ParsedMaterial m = ParseMaterial(material);
  const Vectors wi = ReadVectors(wi_in, "wi", -1);
  const Vectors wo = ReadVectors(wo_in, "wo", wi.rows);
  const Frames frames = ReadFrames(normal, tangent, m, wi.rows);
  py::array_t<double> f = Array(wi.rows, 3);
  double* out = f.mutable_data();
  py::gil_scoped_release release;
  for (py::ssize_t i = 0; i < wi.rows; ++i) {
    const render::Frame frame = frames.At(i);
    const Eigen::Vector3d value =
        render::EvalBrdf(m.params, frame.ToLocal(wo(i)), frame.ToLocal(wi(i)));
    for (int c = 0; c < 3; ++c) out[3 * i + c] = value(c);
  }
  return f;
}

py::array_t<double> Pdf(const std::string& material, const py::object& wi_in,
                        const py::object& wo_in, const py::object& normal,
                        const py::object& tangent) {
  const ParsedMaterial m = ParseMaterial(material);
  const Vectors wi = ReadVectors(wi_in, "wi", -1);
  const Vectors wo = ReadVectors(wo_in, "wo", wi.rows);
  const Frames frames = ReadFrames(normal, tangent, m, wi.rows);
  py::array_t<double> pdf = Array(wi.rows, 1);
  double* out = pdf.mutable_data();
  py::gil_scoped_release release;
  for (py::ssize_t i = 0; i < wi.rows; ++i) {
    const render::Frame frame = frames.At(i);
    out[i] = render::BrdfPdf(m.params, frame.ToLocal(wo(i)), frame.ToLocal(wi(i)));
  }
  return pdf;
}

// Draws wi for each wo from three uniform numbers per row; wi comes back in the frame wo was
// given in.
py::dict Sample(const std::string& material, const py::object& wo_in, const py::object& u_in,
                const py::object& normal, const py::object& tangent) {
  const ParsedMaterial m = ParseMaterial(material);
  const Vectors wo = ReadVectors(wo_in, "wo", -1);
  const Vectors u = ReadVectors(u_in, "u", wo.rows);
  const Frames frames = ReadFrames(normal, tangent, m, wo.rows);
  const py::ssize_t n = wo.rows;
  py::array_t<double> wi = Array(n, 3), f = Array(n, 3), weight = Array(n, 3), pdf = Array(n, 1);
  py::array_t<int8_t> lobe(n);
  py::array_t<bool> valid(n);
  {
    double *wi_out = wi.mutable_data(), *f_out = f.mutable_data(),
           *weight_out = weight.mutable_data(), *pdf_out = pdf.mutable_data();
    int8_t* lobe_out = lobe.mutable_data();
    bool* valid_out = valid.mutable_data();
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) {
      const Eigen::Vector3d ui = u(i);
      const render::Frame frame = frames.At(i);
      const render::BrdfSample s =
          render::SampleBrdf(m.params, frame.ToLocal(wo(i)), ui(0), Eigen::Vector2d(ui(1), ui(2)));
      const Eigen::Vector3d wi_given = frame.ToWorld(s.wi);
      for (int c = 0; c < 3; ++c) {
        wi_out[3 * i + c] = wi_given(c);
        f_out[3 * i + c] = s.f(c);
        weight_out[3 * i + c] = s.weight(c);
      }
      pdf_out[i] = s.pdf;
      lobe_out[i] = int8_t(s.lobe);
      valid_out[i] = s.Valid();
    }
  }
  py::dict out;
  out["wi"] = wi;
  out["f"] = f;
  out["weight"] = weight;
  out["pdf"] = pdf;
  out["lobe"] = lobe;
  out["valid"] = valid;
  return out;
}

}  // namespace

void AddBrdfs(py::module_& m) {
  m.def("_brdf_eval", &Evaluate, py::arg("material"), py::arg("wi"), py::arg("wo"),
        py::arg("normal") = py::none(), py::arg("tangent") = py::none(),
        "f(wi, wo) (N, 3) of a material entry (JSON text) at directions (N, 3) or (3,).");
  m.def("_brdf_pdf", &Pdf, py::arg("material"), py::arg("wi"), py::arg("wo"),
        py::arg("normal") = py::none(), py::arg("tangent") = py::none(),
        "The density (N,) per steradian with which _brdf_sample draws wi given wo.");
  m.def("_brdf_sample", &Sample, py::arg("material"), py::arg("wo"), py::arg("u"),
        py::arg("normal") = py::none(), py::arg("tangent") = py::none(),
        "Draws wi for each wo from uniform numbers u (N, 3): dict of wi, f, weight, pdf, lobe "
        "(0 none, 1 diffuse, 2 specular) and valid.");
  m.def(
      "_brdf_models",
      [] {
        py::list names;
        for (const recon::BrdfModelInfo& info : recon::kBrdfModels) {
          if (info.reflective) names.append(std::string(info.name));
        }
        return names;
      },
      "The names of the reflectance models (scene.json \"brdf\" values with a BRDF).");
}

}  // namespace igi::python
