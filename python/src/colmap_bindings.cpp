// COLMAP sparse models (recon/colmap_model.h) for igi.colmap: a model read from a folder (TXT or
// BIN) or built from Python values, written as TXT, BIN or a PLY of its points. Records cross as
// plain tuples of ints, strings and numpy arrays, which the Python layer (python/igi/colmap.py)
// wraps in classes; a model built in Python is checked by the same rules as one read from files.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <limits>
#include <string>

#include "python/src/bindings.h"
#include "recon/colmap_model.h"
#include "tools/common/error.h"

namespace igi::python {
namespace {

using recon::ColmapModel;

[[noreturn]] void Fail(const std::string& where, const std::string& value,
                       const std::string& rule) {
  throw InputError(DescribeProblem(where, "", value, rule));
}

// An integer (Python int or numpy integer) in [min, max].
long long Integer(py::handle value, long long min, long long max, const std::string& where) {
  PyObject* index = PyNumber_Index(value.ptr());
  if (index == nullptr) {
    PyErr_Clear();
    Fail(where, py::str(py::repr(value)), "must be an integer");
  }
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index, &overflow);
  Py_DECREF(index);
  if (overflow != 0 || v < min || v > max) {
    Fail(where, py::str(py::repr(value)),
         "must be an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  }
  return v;
}

constexpr long long kMaxId32 = std::numeric_limits<uint32_t>::max();
constexpr long long kMaxId64 = std::numeric_limits<int64_t>::max();

// A C-contiguous float64 copy of `value` with `ndim` dimensions; `columns` > 0 fixes the last.
py::array_t<double> Doubles(py::handle value, int ndim, py::ssize_t columns,
                            const std::string& where) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != ndim || (columns > 0 && a.shape(ndim - 1) != columns)) {
    Fail(where, "",
         ndim == 1 ? "must be a 1-D array of numbers"
                   : "must be an (N, " + std::to_string(columns) + ") array of numbers");
  }
  return a;
}

// A C-contiguous int64 copy of an integer array (float arrays are refused, not truncated).
py::array_t<int64_t> Integers(py::handle value, int ndim, py::ssize_t columns,
                              const std::string& where) {
  const py::array raw = py::array::ensure(value);
  const char kind = raw ? raw.dtype().kind() : 'O';
  auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(raw);
  if (!raw || (kind != 'i' && kind != 'u' && !(kind == 'f' && raw.size() == 0)) || !a ||
      a.ndim() != ndim || (columns > 0 && a.shape(ndim - 1) != columns)) {
    Fail(where, "",
         ndim == 1 ? "must be a 1-D array of integers"
                   : "must be an (N, " + std::to_string(columns) + ") array of integers");
  }
  return a;
}

// Checks every value of `a` is in [min, max].
void RequireRange(const py::array_t<int64_t>& a, long long min, long long max,
                  const std::string& where) {
  const int64_t* data = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    if (data[i] < min || data[i] > max) {
      Fail(where, std::to_string(data[i]),
           "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
  }
}

// A tuple's items, checking its length.
py::tuple Fields(py::handle record, size_t count, const std::string& where) {
  if (!py::isinstance<py::tuple>(record) || py::len(record) != count) {
    Fail(where, "", "must be a tuple of " + std::to_string(count) + " values");
  }
  return py::reinterpret_borrow<py::tuple>(record);
}

// (key, camera_id, model, width, height, params)
void AddCameras(const py::list& cameras, ColmapModel* model) {
  for (size_t i = 0; i < cameras.size(); ++i) {
    const py::tuple f = Fields(cameras[i], 6, "cameras record " + std::to_string(i));
    const auto key = static_cast<uint32_t>(Integer(f[0], 0, kMaxId32, "cameras key"));
    const std::string where = "cameras[" + std::to_string(key) + "]";  // as Python indexes it
    recon::ColmapCamera camera;
    camera.camera_id = static_cast<uint32_t>(Integer(f[1], 0, kMaxId32, where + ".camera_id"));
    camera.model = py::cast<std::string>(py::str(f[2]));
    camera.width =
        static_cast<int>(Integer(f[3], 1, std::numeric_limits<int>::max(), where + ".width"));
    camera.height =
        static_cast<int>(Integer(f[4], 1, std::numeric_limits<int>::max(), where + ".height"));
    const auto params = Doubles(f[5], 1, 0, where + ".params");
    camera.params.assign(params.data(), params.data() + params.size());
    if (!model->cameras.emplace(key, std::move(camera)).second) {
      Fail(where, std::to_string(key), "duplicate camera key");
    }
  }
}

// (key, image_id, qvec, tvec, camera_id, name, xys, point3D_ids)
void AddImages(const py::list& images, ColmapModel* model) {
  for (size_t i = 0; i < images.size(); ++i) {
    const py::tuple f = Fields(images[i], 8, "images record " + std::to_string(i));
    const auto key = static_cast<uint32_t>(Integer(f[0], 0, kMaxId32, "images key"));
    const std::string where = "images[" + std::to_string(key) + "]";  // as Python indexes it
    recon::ColmapImage image;
    image.image_id = static_cast<uint32_t>(Integer(f[1], 0, kMaxId32, where + ".image_id"));
    const auto qvec = Doubles(f[2], 1, 4, where + ".qvec");
    const auto tvec = Doubles(f[3], 1, 3, where + ".tvec");
    image.qvec = Eigen::Vector4d(qvec.at(0), qvec.at(1), qvec.at(2), qvec.at(3));
    image.tvec = Eigen::Vector3d(tvec.at(0), tvec.at(1), tvec.at(2));
    image.camera_id = static_cast<uint32_t>(Integer(f[4], 0, kMaxId32, where + ".camera_id"));
    image.name = py::cast<std::string>(py::str(f[5]));
    const auto xys = Doubles(f[6], 2, 2, where + ".xys");
    const auto ids = Integers(f[7], 1, 0, where + ".point3D_ids");
    if (ids.shape(0) != xys.shape(0)) {
      Fail(where, std::to_string(xys.shape(0)) + " xys, " + std::to_string(ids.shape(0)) + " ids",
           "xys and point3D_ids must have one row per 2D point");
    }
    RequireRange(ids, -1, kMaxId64, where + ".point3D_ids");
    image.points2d.resize(static_cast<size_t>(xys.shape(0)));
    for (size_t k = 0; k < image.points2d.size(); ++k) {
      image.points2d[k].xy = Eigen::Vector2d(xys.data()[2 * k], xys.data()[2 * k + 1]);
      image.points2d[k].point3d_id = ids.data()[k];
    }
    if (!model->images.emplace(key, std::move(image)).second) {
      Fail(where, std::to_string(key), "duplicate image key");
    }
  }
}

// (ids (P,), xyz (P, 3), rgb (P, 3), error (P,), track_offsets (P + 1,), track (T, 2))
void AddPoints3D(py::handle points, ColmapModel* model) {
  const py::tuple f = Fields(points, 6, "points3D");
  const auto ids = Integers(f[0], 1, 0, "points3D.ids");
  const auto xyz = Doubles(f[1], 2, 3, "points3D.xyz");
  const auto rgb = Integers(f[2], 2, 3, "points3D.rgb");
  const auto error = Doubles(f[3], 1, 0, "points3D.error");
  const auto offsets = Integers(f[4], 1, 0, "points3D.track_offsets");
  const auto track = Integers(f[5], 2, 2, "points3D.track");
  const py::ssize_t n = ids.shape(0);
  if (xyz.shape(0) != n || rgb.shape(0) != n || error.shape(0) != n || offsets.shape(0) != n + 1) {
    Fail("points3D", "", "ids, xyz, rgb and error need one row per point, track_offsets one more");
  }
  RequireRange(ids, 0, kMaxId64, "points3D.ids");
  RequireRange(rgb, 0, 255, "points3D.rgb");
  RequireRange(track, 0, kMaxId32, "points3D.track");
  const int64_t* o = offsets.data();
  if (o[0] != 0 || o[n] != track.shape(0)) {
    Fail("points3D.track_offsets", std::to_string(o[0]) + " ... " + std::to_string(o[n]),
         "must start at 0 and end at the number of track rows (" + std::to_string(track.shape(0)) +
             ")");
  }
  for (py::ssize_t i = 0; i < n; ++i) {
    if (o[i + 1] < o[i]) {
      Fail("points3D.track_offsets[" + std::to_string(i + 1) + "]", std::to_string(o[i + 1]),
           "must not decrease");
    }
    recon::ColmapPoint3D point;
    point.point3d_id = static_cast<uint64_t>(ids.data()[i]);
    point.xyz = Eigen::Vector3d(xyz.data()[3 * i], xyz.data()[3 * i + 1], xyz.data()[3 * i + 2]);
    for (int c = 0; c < 3; ++c) point.rgb[c] = static_cast<uint8_t>(rgb.data()[3 * i + c]);
    point.error = error.data()[i];
    for (int64_t t = o[i]; t < o[i + 1]; ++t) {
      point.track.push_back({static_cast<uint32_t>(track.data()[2 * t]),
                             static_cast<uint32_t>(track.data()[2 * t + 1])});
    }
    if (!model->points3d.emplace(point.point3d_id, std::move(point)).second) {
      Fail("points3D.ids[" + std::to_string(i) + "]", std::to_string(ids.data()[i]),
           "duplicate point id");
    }
  }
}

py::list CamerasOf(const ColmapModel& model) {
  py::list out;
  for (const auto& [id, c] : model.cameras) {
    py::array_t<double> params(py::ssize_t(c.params.size()));
    std::memcpy(params.mutable_data(), c.params.data(), c.params.size() * sizeof(double));
    out.append(py::make_tuple(id, c.camera_id, c.model, c.width, c.height, params));
  }
  return out;
}

py::list ImagesOf(const ColmapModel& model) {
  py::list out;
  for (const auto& [id, image] : model.images) {
    const auto n = py::ssize_t(image.points2d.size());
    py::array_t<double> qvec(4), tvec(3), xys({n, py::ssize_t(2)});
    py::array_t<int64_t> ids(n);
    for (int k = 0; k < 4; ++k) qvec.mutable_data()[k] = image.qvec[k];
    for (int k = 0; k < 3; ++k) tvec.mutable_data()[k] = image.tvec[k];
    for (py::ssize_t k = 0; k < n; ++k) {
      xys.mutable_data()[2 * k] = image.points2d[k].xy.x();
      xys.mutable_data()[2 * k + 1] = image.points2d[k].xy.y();
      ids.mutable_data()[k] = image.points2d[k].point3d_id;
    }
    out.append(
        py::make_tuple(id, image.image_id, qvec, tvec, image.camera_id, image.name, xys, ids));
  }
  return out;
}

py::tuple Points3DOf(const ColmapModel& model) {
  const auto n = py::ssize_t(model.points3d.size());
  size_t track_rows = 0;
  for (const auto& [id, point] : model.points3d) track_rows += point.track.size();
  py::array_t<int64_t> ids(n), offsets(n + 1);
  py::array_t<double> xyz({n, py::ssize_t(3)}), error(n);
  py::array_t<uint8_t> rgb({n, py::ssize_t(3)});
  py::array_t<uint32_t> track({py::ssize_t(track_rows), py::ssize_t(2)});
  py::ssize_t i = 0;
  size_t t = 0;
  offsets.mutable_data()[0] = 0;
  for (const auto& [id, point] : model.points3d) {
    ids.mutable_data()[i] = static_cast<int64_t>(id);
    for (int k = 0; k < 3; ++k) {
      xyz.mutable_data()[3 * i + k] = point.xyz[k];
      rgb.mutable_data()[3 * i + k] = point.rgb[k];
    }
    error.mutable_data()[i] = point.error;
    for (const recon::ColmapTrackElement& element : point.track) {
      track.mutable_data()[2 * t] = element.image_id;
      track.mutable_data()[2 * t + 1] = element.point2d_idx;
      ++t;
    }
    offsets.mutable_data()[++i] = static_cast<int64_t>(t);
  }
  return py::make_tuple(ids, xyz, rgb, error, offsets, track);
}

}  // namespace

void AddColmap(py::module_& m) {
  py::class_<ColmapModel>(m, "_ColmapModel")
      .def(py::init([](const py::list& cameras, const py::list& images, py::handle points3d) {
             ColmapModel model;
             AddCameras(cameras, &model);
             AddImages(images, &model);
             AddPoints3D(points3d, &model);
             return model;
           }),
           py::arg("cameras"), py::arg("images"), py::arg("points3D"))
      .def_static(
          "read",
          [](const std::filesystem::path& dir) {
            py::gil_scoped_release release;
            return recon::ReadColmapModel(dir);
          },
          py::arg("path"))
      .def("cameras", &CamerasOf)
      .def("images", &ImagesOf)
      .def("points3D", &Points3DOf)
      .def("num_observations", &ColmapModel::NumObservations)
      .def(
          "write_text",
          [](const ColmapModel& model, const std::filesystem::path& dir) {
            py::gil_scoped_release release;
            recon::WriteColmapModelText(model, dir);
          },
          py::arg("path"))
      .def(
          "write_binary",
          [](const ColmapModel& model, const std::filesystem::path& dir) {
            py::gil_scoped_release release;
            recon::WriteColmapModelBinary(model, dir);
          },
          py::arg("path"))
      .def(
          "export_ply",
          [](const ColmapModel& model, const std::filesystem::path& path) {
            py::gil_scoped_release release;
            recon::WriteColmapPointsPly(model, path);
          },
          py::arg("path"))
      .def("validate",
           [](const ColmapModel& model) { recon::ValidateColmapModel(model, "", ".txt"); })
      .def("__eq__", [](const ColmapModel& a, const ColmapModel& b) { return a == b; });
  m.def("_colmap_camera_models", [] {
    py::dict out;
    for (const std::string& name : recon::ColmapModelNames()) {
      out[py::str(name)] = recon::ColmapModelNumParams(name);
    }
    return out;
  });
}

}  // namespace igi::python
