#include "tools/common/image.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi {
namespace {

PixelType FromOiio(OIIO::TypeDesc t) {
  switch (t.basetype) {
    case OIIO::TypeDesc::UINT8: return PixelType::kUInt8;
    case OIIO::TypeDesc::UINT16: return PixelType::kUInt16;
    case OIIO::TypeDesc::HALF: return PixelType::kHalf;
    default: return PixelType::kFloat;
  }
}

OIIO::TypeDesc ToOiio(PixelType t) {
  switch (t) {
    case PixelType::kUInt8: return OIIO::TypeDesc::UINT8;
    case PixelType::kUInt16: return OIIO::TypeDesc::UINT16;
    case PixelType::kHalf: return OIIO::TypeDesc::HALF;
    default: return OIIO::TypeDesc::FLOAT;
  }
}

ImageMetadata MetadataFromSpec(const OIIO::ImageSpec& spec) {
  ImageMetadata out;
  for (const OIIO::ParamValue& p : spec.extra_attribs) {
    const OIIO::TypeDesc t = p.type();
    const std::string name = p.name().string();
    if (t == OIIO::TypeDesc::STRING) {
      out[name] = std::string(p.get_ustring().string());
    } else if (t == OIIO::TypeRational) {  // e.g. EXIF ExposureTime in TIFF: numerator/denominator
      const int* r = static_cast<const int*>(p.data());
      if (r[1] != 0) out[name] = double(r[0]) / double(r[1]);
    } else if (t.basetype == OIIO::TypeDesc::FLOAT || t.basetype == OIIO::TypeDesc::DOUBLE ||
               t.basetype == OIIO::TypeDesc::HALF) {
      if (t.aggregate == OIIO::TypeDesc::SCALAR && t.arraylen == 0) out[name] = p.get_float();
    } else if (t.aggregate == OIIO::TypeDesc::SCALAR && t.arraylen == 0 &&
               t.basetype != OIIO::TypeDesc::PTR) {
      out[name] = int64_t(p.get_int());
    }
  }
  return out;
}

void MetadataToSpec(const ImageMetadata& metadata, OIIO::ImageSpec* spec) {
  for (const auto& [name, value] : metadata) {
    if (const auto* i = std::get_if<int64_t>(&value)) {
      spec->attribute(name, int(*i));
    } else if (const auto* d = std::get_if<double>(&value)) {
      spec->attribute(name, float(*d));
    } else {
      spec->attribute(name, std::get<std::string>(value));
    }
  }
}

std::string Lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

ImageInfo ReadImageInfo(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) {
    throw InputError(DescribeProblem(path.string(), "", "",
                                     "cannot read image: " + OIIO::geterror()));
  }
  const OIIO::ImageSpec& spec = in->spec();
  ImageInfo info;
  info.width = spec.width;
  info.height = spec.height;
  info.channels = spec.nchannels;
  info.type = FromOiio(spec.format);
  info.bits_per_sample = spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size() * 8));
  info.format = in->format_name();
  info.metadata = MetadataFromSpec(spec);
  in->close();
  return info;
}

Image ReadImage(const std::filesystem::path& path, int channels) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) {
    throw InputError(DescribeProblem(path.string(), "", "",
                                     "cannot read image: " + OIIO::geterror()));
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    throw InputError(DescribeProblem(path.string(), "", "", "image has no pixels"));
  }
  Image image(spec.width, spec.height, spec.nchannels);
  image.metadata = MetadataFromSpec(spec);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
    throw InputError(DescribeProblem(path.string(), "", "",
                                     "cannot read image data: " + in->geterror()));
  }
  in->close();
  if (channels <= 0 || channels == image.channels) return image;
  Image out(image.width, image.height, channels);
  out.metadata = image.metadata;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < channels; ++c) {
        const int src = image.channels == 1 ? 0 : std::min(c, image.channels - 1);
        out.at(x, y, c) = c < image.channels || image.channels == 1 ? image.at(x, y, src) : 0.0f;
      }
    }
  }
  return out;
}

namespace {

// Creates the writer for `path`'s extension and opens `temp_path` with the spec of an image of
// the given shape, `metadata` and `options`.
std::unique_ptr<OIIO::ImageOutput> OpenOutput(const std::filesystem::path& path,
                                              const std::filesystem::path& temp_path, int width,
                                              int height, int channels,
                                              const ImageMetadata& metadata,
                                              const WriteImageOptions& options) {
  const std::string ext = Lower(path.extension().string());
  PixelType type = options.type;
  if (type == PixelType::kAuto) {
    if (ext == ".exr" || ext == ".hdr")
      type = PixelType::kFloat;
    else if (ext == ".tif" || ext == ".tiff")
      type = PixelType::kUInt16;
    else
      type = PixelType::kUInt8;
  }
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) {
    throw Error(DescribeProblem(path.string(), "", "",
                                "no image writer for this extension: " + OIIO::geterror()));
  }
  OIIO::ImageSpec spec(width, height, channels, ToOiio(type));
  MetadataToSpec(metadata, &spec);
  if (!options.compression.empty()) spec.attribute("compression", options.compression);
  if (ext == ".jpg" || ext == ".jpeg") spec.attribute("CompressionQuality", options.jpeg_quality);
  if (!out->open(temp_path.string(), spec)) {
    throw Error(DescribeProblem(path.string(), "", "", "cannot write image: " + out->geterror()));
  }
  return out;
}

}  // namespace

void WriteImage(const std::filesystem::path& path, const Image& image,
                const WriteImageOptions& options) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.pixels.size() != size_t(image.width) * image.height * image.channels) {
    throw Error(
        DescribeProblem(path.string(), "", "", "refusing to write an empty or malformed image"));
  }
  AtomicOutput atomic(path);
  auto out = OpenOutput(path, atomic.temp_path(), image.width, image.height, image.channels,
                        image.metadata, options);
  if (!out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data())) {
    throw Error(
        DescribeProblem(path.string(), "", "", "cannot write image data: " + out->geterror()));
  }
  if (!out->close()) {
    throw Error(DescribeProblem(path.string(), "", "", "cannot finish image: " + out->geterror()));
  }
  atomic.Commit();
}

struct ImageRowReader::Impl {
  std::filesystem::path path;
  std::unique_ptr<OIIO::ImageInput> in;
  ImageInfo info;
};

ImageRowReader::ImageRowReader(const std::filesystem::path& path) : impl_(new Impl) {
  impl_->path = path;
  impl_->in = OIIO::ImageInput::open(path.string());
  if (!impl_->in) {
    throw InputError(
        DescribeProblem(path.string(), "", "", "cannot read image: " + OIIO::geterror()));
  }
  const OIIO::ImageSpec& spec = impl_->in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    throw InputError(DescribeProblem(path.string(), "", "", "image has no pixels"));
  }
  ImageInfo& info = impl_->info;
  info.width = spec.width;
  info.height = spec.height;
  info.channels = spec.nchannels;
  info.type = FromOiio(spec.format);
  info.bits_per_sample = spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size() * 8));
  info.format = impl_->in->format_name();
  info.metadata = MetadataFromSpec(spec);
}

ImageRowReader::~ImageRowReader() = default;

const ImageInfo& ImageRowReader::info() const { return impl_->info; }

void ImageRowReader::ReadRows(int y0, int y1, float* out) {
  const ImageInfo& info = impl_->info;
  if (y0 < 0 || y1 <= y0 || y1 > info.height) {
    throw Error(DescribeProblem(impl_->path.string(), "rows",
                                std::to_string(y0) + ".." + std::to_string(y1),
                                "outside the image's " + std::to_string(info.height) + " rows"));
  }
  const OIIO::ImageSpec& spec = impl_->in->spec();
  if (!impl_->in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, 0, 0, info.channels,
                                 OIIO::TypeDesc::FLOAT, out)) {
    throw InputError(DescribeProblem(impl_->path.string(), "", "",
                                     "cannot read image data: " + impl_->in->geterror()));
  }
}

struct ImageRowWriter::Impl {
  std::filesystem::path path;
  std::unique_ptr<AtomicOutput> atomic;
  std::unique_ptr<OIIO::ImageOutput> out;
  int width = 0, height = 0, channels = 0;
  int next_row = 0;
};

ImageRowWriter::ImageRowWriter(const std::filesystem::path& path, int width, int height,
                               int channels, const ImageMetadata& metadata,
                               const WriteImageOptions& options)
    : impl_(new Impl) {
  if (width <= 0 || height <= 0 || channels <= 0) {
    throw Error(
        DescribeProblem(path.string(), "", "", "refusing to write an empty or malformed image"));
  }
  impl_->path = path;
  impl_->width = width;
  impl_->height = height;
  impl_->channels = channels;
  impl_->atomic = std::make_unique<AtomicOutput>(path);
  impl_->out =
      OpenOutput(path, impl_->atomic->temp_path(), width, height, channels, metadata, options);
}

ImageRowWriter::~ImageRowWriter() {
  // Uncommitted: close the writer before AtomicOutput removes its temporary file.
  if (impl_->out) impl_->out->close();
}

void ImageRowWriter::WriteRows(int y0, int y1, const float* rows) {
  if (!impl_->out || y0 != impl_->next_row || y1 <= y0 || y1 > impl_->height) {
    throw Error(DescribeProblem(impl_->path.string(), "rows",
                                std::to_string(y0) + ".." + std::to_string(y1),
                                "rows must be written once each, top to bottom"));
  }
  if (!impl_->out->write_scanlines(y0, y1, 0, OIIO::TypeDesc::FLOAT, rows)) {
    throw Error(DescribeProblem(impl_->path.string(), "", "",
                                "cannot write image data: " + impl_->out->geterror()));
  }
  impl_->next_row = y1;
}

void ImageRowWriter::Commit() {
  if (!impl_->out || impl_->next_row != impl_->height) {
    throw Error(DescribeProblem(impl_->path.string(), "rows", std::to_string(impl_->next_row),
                                "every row must be written before the image is finished"));
  }
  const bool closed = impl_->out->close();
  const std::string error = closed ? "" : impl_->out->geterror();
  impl_->out.reset();
  if (!closed) {
    throw Error(DescribeProblem(impl_->path.string(), "", "", "cannot finish image: " + error));
  }
  impl_->atomic->Commit();
}

int ReductionFactor(int width, int height, double max_megapixels) {
  if (max_megapixels <= 0) return 1;
  const double limit = max_megapixels * 1e6;
  int f = std::max(1, int(std::ceil(std::sqrt(double(width) * height / limit))));
  while (f > 1 && double(width / (f - 1)) * (height / (f - 1)) <= limit) --f;
  while (double(width / f) * (height / f) > limit && f < std::min(width, height)) ++f;
  return f;
}

Image BlockMeans(const Image& image, int f) {
  if (f <= 1) return image;
  Image out(image.width / f, image.height / f, image.channels);
  out.metadata = image.metadata;
  const double n = double(f) * f;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      for (int c = 0; c < image.channels; ++c) {
        double sum = 0;
        for (int v = y * f; v < (y + 1) * f; ++v) {
          for (int u = x * f; u < (x + 1) * f; ++u) sum += image.at(u, v, c);
        }
        out.at(x, y, c) = float(sum / n);
      }
    }
  }
  return out;
}

}  // namespace igi
