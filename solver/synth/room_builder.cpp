#include "solver/synth/room_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "solver/render/sampling.h"

namespace igi::synth {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

Json Rgb(const Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json Lambert(const Vector3d& rho_d) { return Json{{"brdf", "lambert"}, {"rho_d", Rgb(rho_d)}}; }

Json Glossy(const std::string& brdf, const Vector3d& rho_d, double rho_s, double alpha) {
  return Json{{"brdf", brdf}, {"rho_d", Rgb(rho_d)}, {"rho_s", rho_s}, {"alpha", alpha}};
}

// Floor tiles: 4 × 4 tiles of 1 m, each with its own albedo, dark grout, and a faint grain
// (`grain` false: none).
Image MakeFloorTexture(uint64_t seed, bool grain_on = true) {
  constexpr int kSize = 128;
  constexpr int kTiles = 4;
  Image img(kSize, kSize, 3);
  render::Pcg32 tile_rng(seed, 0x7115);
  std::vector<Vector3d> tile_albedo;
  for (int i = 0; i < kTiles * kTiles; ++i) {
    const double base = 0.30 + 0.30 * tile_rng.UniformDouble();
    tile_albedo.emplace_back(base * 1.05, base * 0.95, base * 0.80);
  }
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const int tile_px = kSize / kTiles;
      const int tx = x / tile_px, ty = y / tile_px;
      const int lx = x % tile_px, ly = y % tile_px;
      const bool grout = lx < 1 || ly < 1;
      render::Pcg32 grain_rng(seed ^ 0x9a11, uint64_t(y) * kSize + x);
      const double grain = grain_on ? 1.0 + 0.06 * (grain_rng.UniformDouble() - 0.5) : 1.0;
      const Vector3d a = grout ? Vector3d(0.12, 0.12, 0.11) : tile_albedo[ty * kTiles + tx] * grain;
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = float(a[c]);
    }
  }
  return img;
}

// Separable Gaussian blur (σ in texels, ±3σ support, indices clamped at the edges).
Image GaussianBlur(const Image& in, double sigma) {
  const int radius = static_cast<int>(std::ceil(3 * sigma));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) {
    sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  }
  for (double& k : kernel) k /= sum;
  Image tmp = in, out = in;
  for (int pass = 0; pass < 2; ++pass) {
    const Image& src = pass == 0 ? in : tmp;
    Image& dst = pass == 0 ? tmp : out;
    for (int y = 0; y < in.height; ++y) {
      for (int x = 0; x < in.width; ++x) {
        for (int c = 0; c < in.channels; ++c) {
          double v = 0;
          for (int k = -radius; k <= radius; ++k) {
            const int xi = pass == 0 ? std::clamp(x + k, 0, in.width - 1) : x;
            const int yi = pass == 1 ? std::clamp(y + k, 0, in.height - 1) : y;
            v += kernel[k + radius] * src.at(xi, yi, c);
          }
          dst.at(x, y, c) = float(v);
        }
      }
    }
  }
  return out;
}

// Value noise in [0, 1]: octaves of bilinearly interpolated random grids (4 to 256 cells across),
// equal amplitudes, contrast-stretched and posterised, for features at every scale.
std::vector<float> ValueNoise(int size, uint64_t seed) {
  std::vector<double> sum(size_t(size) * size, 0.0);
  for (int cells = 4, octave = 0; cells <= 256; cells *= 2, ++octave) {
    render::Pcg32 rng(seed, 0x5eed + octave);
    std::vector<double> grid(size_t(cells + 1) * (cells + 1));
    for (double& g : grid) g = rng.UniformDouble();
    for (int y = 0; y < size; ++y) {
      const double gy = (y + 0.5) * cells / size;
      const int iy = std::min(int(gy), cells - 1);
      const double fy = gy - iy;
      for (int x = 0; x < size; ++x) {
        const double gx = (x + 0.5) * cells / size;
        const int ix = std::min(int(gx), cells - 1);
        const double fx = gx - ix;
        auto g = [&](int i, int j) { return grid[size_t(j) * (cells + 1) + i]; };
        sum[size_t(y) * size + x] += (1 - fy) * ((1 - fx) * g(ix, iy) + fx * g(ix + 1, iy)) +
                                     fy * ((1 - fx) * g(ix, iy + 1) + fx * g(ix + 1, iy + 1));
      }
    }
  }
  double mean = 0, sq = 0;
  for (double v : sum) mean += v, sq += v * v;
  mean /= double(sum.size());
  const double sd = std::sqrt(std::max(sq / double(sum.size()) - mean * mean, 1e-12));
  std::vector<float> out(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) {
    // Posterised to 4 levels: blobs of every size with sharp edges, which SIFT localises well.
    const double v = std::clamp(0.5 + 0.25 * (sum[i] - mean) / sd, 0.0, 0.999);
    out[i] = float(std::floor(4 * v) / 3);
  }
  return out;
}

// `base` colour modulated by value noise between 0.25x and 1.25x (capped at 0.95).
Image NoiseTexture(const Vector3d& base, uint64_t seed) {
  constexpr int kSize = 512;
  const std::vector<float> noise = ValueNoise(kSize, seed);
  Image img(kSize, kSize, 3);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const double m = 0.25 + noise[size_t(y) * kSize + x];
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = float(std::min(0.95, base[c] * m));
    }
  }
  return img;
}

// --textured-walls: every region but the floor gets a noise texture of its colour; the floor's
// tiles are modulated by noise too.
void TextureEveryRegion(const SynthOptions& options, bool rho_d_known, SynthRoom* room) {
  uint64_t index = 0;
  for (auto& [name, m] : room->materials.items()) {
    ++index;
    if (name == "floor") {
      const std::vector<float> noise = ValueNoise(room->floor_albedo.width, options.seed ^ 0xf1);
      for (size_t i = 0; i < noise.size(); ++i) {
        for (int c = 0; c < 3; ++c) room->floor_albedo.pixels[3 * i + c] *= 0.4f + 1.2f * noise[i];
      }
      m["rho_d"] = Rgb(ImageMean(room->floor_albedo));
      continue;
    }
    const std::vector<double> rgb = m["rho_d"].get<std::vector<double>>();
    Image texture = NoiseTexture({rgb[0], rgb[1], rgb[2]}, options.seed * 1000 + index);
    const std::string file = (rho_d_known ? "textures/" : "truth/textures/") + name + "_albedo.exr";
    m["rho_d"] = Rgb(ImageMean(texture));
    m["rho_d_map"] = file;
    room->region_textures.emplace_back(file, std::move(texture));
  }
}

// The poster's stripes: vertical bands of 10 cm (10 texels of 1 cm) cycling through red, yellow,
// blue and white, so that each channel's mean differs from the others' and from the grey mean.
Image MakePosterTexture() {
  constexpr int kWidth = 120, kHeight = 90, kStripe = 10;
  const std::array<Vector3d, 4> colours = {Vector3d(0.75, 0.15, 0.12), Vector3d(0.80, 0.70, 0.15),
                                           Vector3d(0.12, 0.25, 0.70), Vector3d(0.85, 0.85, 0.80)};
  Image img(kWidth, kHeight, 3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const Vector3d& a = colours[(x / kStripe) % colours.size()];
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = float(a[c]);
    }
  }
  return img;
}

// The poster: 1.2 m × 0.9 m on wall_x4 (x = s.x), centred at y = 2.0 m, z = 1.45 m, 5 mm into
// the room, facing −x; u runs along −y (left to right seen from the room), v up. Returns its
// centre.
Vector3d AddPoster(const Vector3d& s, SynthMesh* mesh) {
  const double x = s.x() - 0.005, y0 = 1.4, y1 = 2.6, z0 = 1.0, z1 = 1.9;
  mesh->AddQuad({x, y1, z0}, {x, y0, z0}, {x, y0, z1}, {x, y1, z1}, "poster",
                {Vector2d(0, 0), Vector2d(1, 0), Vector2d(1, 1), Vector2d(0, 1)});
  return {x, 0.5 * (y0 + y1), 0.5 * (z0 + z1)};
}

void AddRoomShell(const Vector3d& s, SynthMesh* mesh) {
  auto uv = [](double u0, double v0, double u1, double v1) {
    return std::array<Vector2d, 4>{Vector2d(u0, v0), Vector2d(u1, v0), Vector2d(u1, v1),
                                   Vector2d(u0, v1)};
  };
  // Inward-facing: counter-clockwise seen from inside the room. Floor UVs: u = x/sx, v = y/sy.
  mesh->AddQuad({0, 0, 0}, {s.x(), 0, 0}, {s.x(), s.y(), 0}, {0, s.y(), 0}, "floor",
                uv(0, 0, 1, 1));
  mesh->AddQuad({0, 0, s.z()}, {0, s.y(), s.z()}, {s.x(), s.y(), s.z()}, {s.x(), 0, s.z()},
                "ceiling", uv(0, 0, 1, 1));
  mesh->AddQuad({0, 0, 0}, {0, s.y(), 0}, {0, s.y(), s.z()}, {0, 0, s.z()}, "wall_x0",
                uv(0, 0, 1, 1));
  mesh->AddQuad({s.x(), s.y(), 0}, {s.x(), 0, 0}, {s.x(), 0, s.z()}, {s.x(), s.y(), s.z()},
                "wall_x4", uv(0, 0, 1, 1));
  mesh->AddQuad({s.x(), 0, 0}, {0, 0, 0}, {0, 0, s.z()}, {s.x(), 0, s.z()}, "wall_y0",
                uv(0, 0, 1, 1));
  mesh->AddQuad({0, s.y(), 0}, {s.x(), s.y(), 0}, {s.x(), s.y(), s.z()}, {0, s.y(), s.z()},
                "wall_y4", uv(0, 0, 1, 1));
}

bool Contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

}  // namespace

Json LampJson(const SynthLamp& lamp) {
  const Json pos = Rgb(lamp.position);
  if (lamp.radius <= 0) {
    return Json{{"type", "point"},
                {"position", pos},
                {"intensity", Rgb(Vector3d::Constant(lamp.intensity))}};
  }
  const double radiance = lamp.intensity / (std::numbers::pi * lamp.radius * lamp.radius);
  return Json{{"type", "sphere"},
              {"center", pos},
              {"radius", lamp.radius},
              {"radiance", Rgb(Vector3d::Constant(radiance))}};
}

Json SynthRoom::LightsJson() const {
  Json lights = Json::object();
  for (const SynthLamp& lamp : lamps) lights[lamp.name] = LampJson(lamp);
  return lights;
}

Json SynthRoom::LightingsJson() const {
  return Json{{"L0", Json::array({lamps[0].name})}, {"L1", Json::array({lamps[1].name})}};
}

Eigen::Vector3d ImageMean(const Image& image) {
  Vector3d sum = Vector3d::Zero();
  const size_t n = size_t(image.width) * image.height;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c)
      sum[c] += image.pixels[i * image.channels + std::min(c, image.channels - 1)];
  }
  return sum / double(std::max<size_t>(n, 1));
}

SynthRoom BuildRoom(const SynthOptions& options) {
  SynthRoom room;
  const std::string g(recon::BrdfModelName(options.glossy_brdf));
  AddRoomShell(room.size, &room.mesh);
  room.mesh.AddBox({2.8, 2.6}, 0.0, {0.9, 0.7, 0.6}, 25.0, "glossy_box");
  room.mesh.AddSphere({1.3, 1.4, 0.35}, 0.35, 16, 32, "glossy_sphere");
  room.mesh.AddBox({0.9, 3.1}, 0.0, {0.6, 0.6, 1.4}, -15.0, "matte_box");

  room.floor_albedo = options.floor_texture == FloorTexture::kSmooth
                          ? GaussianBlur(MakeFloorTexture(options.seed, false), 2.0)
                          : MakeFloorTexture(options.seed);
  const bool rho_d_known = !Contains(options.unknowns, "rho_d");
  room.floor_albedo_file =
      rho_d_known ? "textures/floor_albedo.exr" : "truth/textures/floor_albedo.exr";
  Json floor = Glossy(g, ImageMean(room.floor_albedo), 0.04, 0.15);
  floor["rho_d_map"] = room.floor_albedo_file;

  Json& m = room.materials;
  m = Json::object();
  m["floor"] = floor;
  m["ceiling"] = Lambert({0.8, 0.8, 0.8});
  m["wall_x0"] = Lambert({0.6, 0.3, 0.25});
  m["wall_x4"] = Lambert({0.3, 0.5, 0.35});
  m["wall_y0"] = Lambert({0.5, 0.5, 0.5});
  m["wall_y4"] = Glossy(g, {0.55, 0.55, 0.45}, 0.05, 0.07);
  m["glossy_box"] = Glossy(g, {0.1, 0.2, 0.5}, 0.08, 0.05);
  m["glossy_sphere"] = Glossy(g, {0.5, 0.15, 0.1}, 0.1, 0.1);
  m["matte_box"] =
      options.satin ? Glossy(g, {0.6, 0.6, 0.55}, 0.03, 0.25) : Lambert({0.7, 0.7, 0.7});
  if (options.textured_walls) TextureEveryRegion(options, rho_d_known, &room);
  room.glossy_regions = {"glossy_box", "glossy_sphere", "floor", "wall_y4"};
  if (options.satin) room.glossy_regions.push_back("matte_box");
  if (options.poster) {
    room.poster_center = AddPoster(room.size, &room.mesh);
    Image texture = MakePosterTexture();
    const std::string file =
        rho_d_known ? "textures/poster_albedo.exr" : "truth/textures/poster_albedo.exr";
    m["poster"] = Lambert(ImageMean(texture));
    m["poster"]["rho_d_map"] = file;
    room.region_textures.emplace_back(file, std::move(texture));
  }

  const double radius = options.lamp == LampShape::kPoint ? 0.0 : 0.04;
  room.lamps.push_back(
      {"lamp", options.lamp_position.value_or(Eigen::Vector3d(2.3, 1.7, 2.4)), 30.0, radius});
  room.lamps.push_back({"lamp2", {0.8, 0.9, 2.2}, 25.0, radius});
  return room;
}

}  // namespace igi::synth
