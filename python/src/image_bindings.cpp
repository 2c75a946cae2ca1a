// Images between igi and numpy: igi::Image's pixels (row-major, interleaved channels, row 0 at
// the top) are exactly a C-contiguous (H, W, C) float32 array, so a read hands its pixel vector to
// numpy without a copy and a write copies the array once into an Image.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <variant>

#include "python/src/bindings.h"
#include "tools/common/error.h"

namespace igi::python {

py::array_t<float> PixelsToArray(Image&& image) {
  auto* pixels = new std::vector<float>(std::move(image.pixels));
  py::capsule owner(pixels, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  const auto h = py::ssize_t(image.height), w = py::ssize_t(image.width),
             c = py::ssize_t(image.channels);
  return py::array_t<float>({h, w, c},
                            {w * c * py::ssize_t(sizeof(float)), c * py::ssize_t(sizeof(float)),
                             py::ssize_t(sizeof(float))},
                            pixels->data(), owner);
}

py::dict MetadataToDict(const ImageMetadata& metadata) {
  py::dict out;
  for (const auto& [key, value] : metadata) {
    std::visit([&](const auto& v) { out[py::str(key)] = v; }, value);
  }
  return out;
}

namespace {

ImageMetadata DictToMetadata(const py::dict& metadata) {
  ImageMetadata out;
  for (const auto& [key, value] : metadata) {
    const std::string name = py::str(key);
    if (py::isinstance<py::bool_>(value) || py::isinstance<py::int_>(value)) {
      out[name] = value.cast<int64_t>();
    } else if (py::isinstance<py::float_>(value)) {
      out[name] = value.cast<double>();
    } else if (py::isinstance<py::str>(value)) {
      out[name] = value.cast<std::string>();
    } else {
      throw InputError(DescribeProblem("metadata", name, py::str(py::type::of(value)),
                                       "must be an int, a float or a str"));
    }
  }
  return out;
}

Image ArrayToImage(const py::array& array, const std::string& where) {
  if (array.ndim() != 2 && array.ndim() != 3) {
    throw InputError(DescribeProblem(where, "shape", py::str(py::tuple(py::cast(array.request().shape))),
                                     "must be (H, W) or (H, W, C)"));
  }
  const auto pixels = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!pixels) throw InputError(DescribeProblem(where, "dtype", "", "must convert to float32"));
  const int height = int(pixels.shape(0)), width = int(pixels.shape(1));
  const int channels = pixels.ndim() == 3 ? int(pixels.shape(2)) : 1;
  if (height < 1 || width < 1 || channels < 1 || channels > 4) {
    throw InputError(DescribeProblem(where, "shape",
                                     std::to_string(height) + "x" + std::to_string(width) + "x" +
                                         std::to_string(channels),
                                     "needs at least one pixel and 1 to 4 channels"));
  }
  Image image(width, height, channels);
  std::copy(pixels.data(), pixels.data() + image.pixels.size(), image.pixels.begin());
  return image;
}

}  // namespace

void AddImages(py::module_& m) {
  m.def(
      "read_image",
      [](const std::filesystem::path& path, int channels) {
        Image image;
        {
          py::gil_scoped_release release;
          image = ReadImage(path, channels);
        }
        py::dict metadata = MetadataToDict(image.metadata);
        return py::make_tuple(PixelsToArray(std::move(image)), metadata);
      },
      py::arg("path"), py::arg("channels") = 0,
      "Reads an image (any format OpenImageIO reads) as (float32 (H, W, C) array, metadata).");
  m.def(
      "write_image",
      [](const std::filesystem::path& path, const py::array& array, const py::dict& metadata,
         const std::string& pixel_type, const std::string& compression) {
        Image image = ArrayToImage(array, path.string());
        image.metadata = DictToMetadata(metadata);
        WriteImageOptions options;
        if (pixel_type == "half") {
          options.type = PixelType::kHalf;
        } else if (pixel_type == "float") {
          options.type = PixelType::kFloat;
        } else if (pixel_type == "uint8") {
          options.type = PixelType::kUInt8;
        } else if (pixel_type == "uint16") {
          options.type = PixelType::kUInt16;
        } else if (pixel_type != "auto") {
          throw InputError(DescribeProblem(path.string(), "pixel_type", pixel_type,
                                           "must be auto, half, float, uint8 or uint16"));
        }
        options.compression = compression;
        py::gil_scoped_release release;
        WriteImage(path, image, options);
      },
      py::arg("path"), py::arg("array"), py::arg("metadata") = py::dict(),
      py::arg("pixel_type") = "auto", py::arg("compression") = "",
      "Writes an (H, W) or (H, W, C) array atomically; the format follows the extension.");
}

}  // namespace igi::python
