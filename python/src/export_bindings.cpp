// The Mitsuba 3 bridge (solver/export/export_mitsuba.h): one lighting of a loaded scene as a
// mitsuba.load_dict dictionary, built from the same description as igi-export's XML. The dict
// and the export report cross as JSON text (the Python layer turns them into dicts).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <memory>

#include "python/src/bindings.h"
#include "recon/scene.h"
#include "solver/export/export.h"
#include "solver/export/export_mitsuba.h"
#include "tools/common/error.h"

namespace igi::python {

void AddExports(py::module_& m) {
  m.def(
      "_mitsuba_scene_dict",
      [](const std::shared_ptr<recon::Scene>& scene, const std::string& lighting,
         const std::filesystem::path& out_dir, int spp) {
        const int index = scene->FindLighting(lighting);
        if (index < 0) {
          throw InputError(DescribeProblem(scene->file.string(), "lighting", lighting,
                                           "no lighting of that name in the scene"));
        }
        exporter::ExportOptions options;
        options.format = exporter::ExportFormat::kMitsuba;
        options.mitsuba_spp = spp;
        exporter::ExportReport report;
        Json dict;
        {
          py::gil_scoped_release release;
          dict = exporter::MitsubaSceneDict(*scene, index, options, out_dir, &report);
        }
        return py::make_tuple(dict.dump(), report.ToJson().dump());
      },
      py::arg("scene"), py::arg("lighting"), py::arg("out_dir"), py::arg("spp") = 256,
      "(dict as JSON text, export report as JSON text) of lighting `lighting` of a scene for "
      "mitsuba.load_dict; meshes and textures are written into out_dir.");
}

}  // namespace igi::python
