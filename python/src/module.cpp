// The extension module _igi: igi's libraries for the Python package igi (python/igi).
#include "python/src/bindings.h"
#include "tools/common/error.h"

namespace igi::python {

// igi::InputError -> igi.InputError (a ValueError), any other igi::Error -> igi.Error (a
// RuntimeError); both carry `problems`, the error's lines ("FILE: KEY: VALUE: RULE").
void AddErrors(py::module_& m) {
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr thrown) {
    const auto raise = [](py::handle type, const Error& e) {
      py::list problems;
      for (const std::string& line : e.Lines()) problems.append(line);
      py::object instance = py::reinterpret_borrow<py::object>(type)(e.what());
      instance.attr("problems") = problems;
      PyErr_SetObject(type.ptr(), instance.ptr());
    };
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const InputError& e) {
      raise(input_error, e);
    } catch (const Error& e) {
      raise(error, e);
    }
  });
}

}  // namespace igi::python

PYBIND11_MODULE(_igi, m) {
  m.doc() = "igi's libraries (the implementation of the Python package igi)";
  igi::python::AddErrors(m);
  igi::python::AddLogging(m);
  igi::python::AddImages(m);
  igi::python::AddScenes(m);
  igi::python::AddRendering(m);
  igi::python::AddBrdfs(m);
  igi::python::AddLights(m);
  igi::python::AddExports(m);
  igi::python::AddColmap(m);
  igi::python::AddJobs(m);
  igi::python::AddCalibration(m);
}
