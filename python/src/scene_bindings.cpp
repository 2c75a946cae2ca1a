// Scenes and cameras: recon::Scene (scene.json, docs/scene-format.md) loaded from a file or from a
// document in memory, its cameras with COLMAP's conventions (recon/camera.h), its photos, lightings
// and mesh as numpy arrays. The document itself crosses as JSON text (the Python layer turns it
// into dicts): scene documents are small.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <limits>
#include <memory>

#include "python/src/bindings.h"
#include "recon/scene.h"
#include "recon/scene_document.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::python {
namespace {

recon::SceneLoadOptions LoadOptions(bool load_geometry, bool check_images,
                                    bool require_complete_materials) {
  recon::SceneLoadOptions options;
  options.load_geometry = load_geometry;
  options.check_images = check_images;
  options.require_complete_materials = require_complete_materials;
  return options;
}

// Rows of an (N, K) float64 array, K = `columns`; one copy.
Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Rows(const py::array& array,
                                                                             int columns,
                                                                             const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 2 || a.shape(1) != columns) {
    throw InputError(DescribeProblem(what, "shape", "", "must be (N, " + std::to_string(columns) + ")"));
  }
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      a.data(), a.shape(0), columns);
}

void AddCamera(py::module_& m) {
  py::class_<recon::Camera>(m, "Camera",
                            "A camera of a scene: COLMAP's model, frame (x right, y down, z "
                            "forward) and pose cam_from_world; pixel centres at +0.5.")
      .def_readonly("name", &recon::Camera::name)
      .def_property_readonly("model",
                             [](const recon::Camera& c) { return std::string(CameraModelName(c.model)); })
      .def_readonly("width", &recon::Camera::width)
      .def_readonly("height", &recon::Camera::height)
      .def_readonly("params", &recon::Camera::params)
      .def_property_readonly(
          "K",
          [](const recon::Camera& c) {
            Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
            k(0, 0) = c.focal_x_px();
            k(1, 1) = c.focal_y_px();
            k(0, 2) = c.principal_x_px();
            k(1, 2) = c.principal_y_px();
            return k;
          },
          "The 3x3 intrinsic matrix (fx, fy, cx, cy in pixels, top-left pixel centre at 0.5).")
      .def_property_readonly(
          "qvec",
          [](const recon::Camera& c) {
            const Eigen::Quaterniond& q = c.cam_from_world.rotation;
            return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
          },
          "cam_from_world's rotation as a unit quaternion in the order (w, x, y, z), COLMAP's "
          "qvec (pycolmap's Rotation3d.quat is (x, y, z, w)).")
      .def_property_readonly(
          "tvec", [](const recon::Camera& c) { return Eigen::Vector3d(c.cam_from_world.translation); },
          "cam_from_world's translation (metres).")
      .def_property_readonly(
          "R", [](const recon::Camera& c) { return Eigen::Matrix3d(c.cam_from_world.rotation.toRotationMatrix()); },
          "cam_from_world's rotation matrix: x_cam = R x_world + tvec.")
      .def_property_readonly("center", [](const recon::Camera& c) { return Eigen::Vector3d(c.CenterInWorld()); },
                             "The camera centre in the world frame.")
      .def_property_readonly("vignetting",
                             [](const recon::Camera& c) {
                               return py::make_tuple(c.vignetting_k1, c.vignetting_k2);
                             },
                             "(k1, k2) of the fall-off 1 + k1 r^2 + k2 r^4 (zeros: none).")
      .def(
          "project",
          [](const recon::Camera& c, const py::array& points) {
            const auto rows = Rows(points, 3, "points");
            py::array_t<double> out({py::ssize_t(rows.rows()), py::ssize_t(2)});
            auto o = out.mutable_unchecked<2>();
            for (Eigen::Index i = 0; i < rows.rows(); ++i) {
              const std::optional<Eigen::Vector2d> p = c.ImgFromWorld(rows.row(i).transpose());
              o(i, 0) = p ? (*p)(0) : std::numeric_limits<double>::quiet_NaN();
              o(i, 1) = p ? (*p)(1) : std::numeric_limits<double>::quiet_NaN();
            }
            return out;
          },
          py::arg("points"),
          "Pixels (N, 2) of world points (N, 3), distortion applied; NaN for points behind the "
          "camera.")
      .def(
          "rays",
          [](const recon::Camera& c, const py::array& pixels) {
            const auto rows = Rows(pixels, 2, "pixels");
            py::array_t<double> directions({py::ssize_t(rows.rows()), py::ssize_t(3)});
            auto d = directions.mutable_unchecked<2>();
            for (Eigen::Index i = 0; i < rows.rows(); ++i) {
              const Eigen::Vector3d ray = c.WorldRayFromImg(rows.row(i).transpose());
              for (int k = 0; k < 3; ++k) d(i, k) = ray(k);
            }
            return py::make_tuple(Eigen::Vector3d(c.CenterInWorld()), directions);
          },
          py::arg("pixels"),
          "(origin (3,), unit directions (N, 3)) of the world rays through pixels (N, 2).")
      .def("__repr__", [](const recon::Camera& c) {
        return "<igi.Camera " + c.name + " " + std::string(CameraModelName(c.model)) + " " +
               std::to_string(c.width) + "x" + std::to_string(c.height) + ">";
      });
}

using ScenePtr = std::shared_ptr<recon::Scene>;

void AddScene(py::module_& m) {
  py::class_<recon::Scene, ScenePtr>(m, "_Scene")
      .def_static(
          "load",
          [](const std::filesystem::path& path, bool load_geometry, bool check_images,
             bool require_complete_materials) {
            py::gil_scoped_release release;
            return ScenePtr(std::make_shared<recon::Scene>(recon::LoadScene(
                path, LoadOptions(load_geometry, check_images, require_complete_materials))));
          },
          py::arg("path"), py::arg("load_geometry") = true, py::arg("check_images") = true,
          py::arg("require_complete_materials") = false)
      .def_static(
          "from_json",
          [](const std::string& text, const std::filesystem::path& path, bool load_geometry,
             bool check_images, bool require_complete_materials) {
            Json document = ParseJson(text, path.string());
            py::gil_scoped_release release;
            return ScenePtr(std::make_shared<recon::Scene>(recon::LoadSceneFromDocument(
                std::move(document), path,
                LoadOptions(load_geometry, check_images, require_complete_materials))));
          },
          py::arg("text"), py::arg("path"), py::arg("load_geometry") = true,
          py::arg("check_images") = true, py::arg("require_complete_materials") = false)
      .def_property_readonly("file", [](const recon::Scene& s) { return s.file; })
      .def_property_readonly("dir", [](const recon::Scene& s) { return s.dir; })
      .def("document_json", [](const recon::Scene& s) { return s.document.dump(); })
      .def_property_readonly("cameras",
                             [](const recon::Scene& s) {
                               py::dict out;
                               for (const recon::Camera& c : s.cameras) out[py::str(c.name)] = c;
                               return out;
                             })
      .def_property_readonly("lightings",
                             [](const recon::Scene& s) {
                               py::dict out;
                               for (const recon::Lighting& l : s.lightings) {
                                 py::list names;
                                 for (int i : l.lights) names.append(s.lights[size_t(i)].name);
                                 out[py::str(l.name)] = names;
                               }
                               return out;
                             })
      .def_property_readonly("photos",
                             [](const recon::Scene& s) {
                               py::list out;
                               for (const recon::Photo& p : s.photos) {
                                 py::dict d;
                                 d["file"] = p.file;
                                 d["mask"] = p.mask ? py::cast(*p.mask) : py::none();
                                 d["camera"] = s.cameras[size_t(p.camera)].name;
                                 d["lighting"] = s.lightings[size_t(p.lighting)].name;
                                 d["exposure_scale"] = p.exposure_scale;
                                 out.append(d);
                               }
                               return out;
                             })
      .def_property_readonly("mesh", [](const recon::Scene& s) {
        const recon::TriangleMesh& mesh = s.mesh;
        py::array_t<float> positions({py::ssize_t(mesh.positions.size()), py::ssize_t(3)});
        py::array_t<float> normals({py::ssize_t(mesh.normals.size()), py::ssize_t(3)});
        py::array_t<float> uvs({py::ssize_t(mesh.uvs.size()), py::ssize_t(2)});
        py::array_t<int32_t> triangles({py::ssize_t(mesh.triangles.size()), py::ssize_t(3)});
        py::array_t<int32_t> regions(py::ssize_t(mesh.triangle_region.size()));
        std::memcpy(positions.mutable_data(), mesh.positions.data(), mesh.positions.size() * 12);
        std::memcpy(normals.mutable_data(), mesh.normals.data(), mesh.normals.size() * 12);
        std::memcpy(uvs.mutable_data(), mesh.uvs.data(), mesh.uvs.size() * 8);
        std::memcpy(triangles.mutable_data(), mesh.triangles.data(), mesh.triangles.size() * 12);
        std::memcpy(regions.mutable_data(), mesh.triangle_region.data(), mesh.triangle_region.size() * 4);
        py::dict out;
        out["positions"] = positions;
        out["normals"] = normals;
        out["uvs"] = uvs;
        out["triangles"] = triangles;
        out["triangle_region"] = regions;
        out["region_names"] = mesh.region_names;
        return out;
      });
  m.def(
      "_save_scene",
      [](const std::string& text, const std::filesystem::path& from_dir,
         const std::filesystem::path& path) {
        recon::SceneDocument document(ParseJson(text, path.string()));
        const std::filesystem::path to_dir = std::filesystem::absolute(path).parent_path();
        document.RebasePaths(from_dir, to_dir);
        py::gil_scoped_release release;
        document.Validate(to_dir);  // nothing is written when the document breaks a rule
        WriteJsonFile(path, document.json());
      },
      py::arg("text"), py::arg("from_dir"), py::arg("path"));
}

}  // namespace

void AddScenes(py::module_& m) {
  AddCamera(m);
  AddScene(m);
}

}  // namespace igi::python
