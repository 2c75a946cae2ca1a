#pragma once
// The parts of the extension module _igi (python/src/*.cpp), each adding its functions and
// classes to the module. The pure-Python layer (python/igi/__init__.py) is the public surface;
// _igi's names are its implementation.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "tools/common/image.h"

namespace igi::python {

namespace py = pybind11;

void AddErrors(py::module_& m);
void AddLogging(py::module_& m);
void AddImages(py::module_& m);
void AddScenes(py::module_& m);
void AddRendering(py::module_& m);
void AddBrdfs(py::module_& m);
void AddLights(py::module_& m);
void AddExports(py::module_& m);
void AddColmap(py::module_& m);
void AddJobs(py::module_& m);
void AddCalibration(py::module_& m);

// An image's pixels as a float32 (H, W, C) array that owns them (moved, not copied), row 0 at the
// top, and its metadata as a dict.
py::array_t<float> PixelsToArray(Image&& image);
py::dict MetadataToDict(const ImageMetadata& metadata);

}  // namespace igi::python
