// The path tracer (solver/render/render.h): one lighting of a scene, rendered from any camera, the
// GIL released while it runs. The renderer keeps its scene alive.
#include <pybind11/stl.h>

#include <memory>

#include "python/src/bindings.h"
#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/error.h"

namespace igi::python {
namespace {

struct PyRenderer {
  std::shared_ptr<recon::Scene> scene;  // outlives the renderer, which refers to it
  std::unique_ptr<render::Renderer> renderer;
};

}  // namespace

void AddRendering(py::module_& m) {
  py::class_<PyRenderer>(m, "_Renderer")
      .def(py::init([](std::shared_ptr<recon::Scene> scene, const std::string& lighting) {
             const int index = scene->FindLighting(lighting);
             if (index < 0) {
               throw InputError(DescribeProblem(scene->file.string(), "lighting", lighting,
                                                "no lighting of that name in the scene"));
             }
             for (const recon::Material& material : scene->materials) {
               const std::vector<std::string> missing = material.MissingForRendering();
               if (!missing.empty()) {
                 throw InputError(DescribeProblem(scene->file.string(),
                                                  "materials." + material.name + "." + missing[0],
                                                  "", "rendering needs every material value"));
               }
             }
             PyRenderer r{scene, nullptr};
             py::gil_scoped_release release;
             r.renderer = std::make_unique<render::Renderer>(*r.scene, index);
             return r;
           }),
           py::arg("scene"), py::arg("lighting"))
      .def(
          "render",
          [](const PyRenderer& r, const std::string& camera, int spp, uint64_t seed, int width,
             int height, int max_bounces, int threads) {
            const int index = r.scene->FindCamera(camera);
            if (index < 0) {
              throw InputError(DescribeProblem(r.scene->file.string(), "camera", camera,
                                               "no camera of that name in the scene"));
            }
            render::RenderOptions options;
            options.spp = spp;
            options.seed = seed;
            options.width = width;
            options.height = height;
            options.max_bounces = max_bounces;
            options.num_threads = threads;
            options.show_progress = false;
            options.Validate();
            render::RenderSummary summary;
            Image image;
            {
              py::gil_scoped_release release;
              image = r.renderer->Render(r.scene->cameras[size_t(index)], options, &summary);
            }
            py::dict info;
            info["seconds"] = summary.seconds;
            info["rays"] = summary.rays;
            info["camera_rays"] = summary.camera_rays;
            return py::make_tuple(PixelsToArray(std::move(image)), info);
          },
          py::arg("camera"), py::arg("spp") = 64, py::arg("seed") = 0, py::arg("width") = 0,
          py::arg("height") = 0, py::arg("max_bounces") = 64, py::arg("threads") = 0);
}

}  // namespace igi::python
