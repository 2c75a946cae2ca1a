// igi-synth's room, cameras, options and effects (no rendering), and the effects hidden in
// another renderer's capture (--from).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "recon/mesh.h"
#include "recon/scene.h"
#include "solver/render/sampling.h"
#include "solver/synth/camera_placement.h"
#include "solver/synth/effects.h"
#include "solver/synth/room_builder.h"
#include "solver/synth/synth_mesh.h"
#include "solver/synth/synth_options.h"
#include "solver/synth/synthesize.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/image.h"

namespace igi::synth {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

TEST(SynthOptions, ParsesEffectSpecs) {
  EffectSpec e = ParseEffectSpec("vignetting:k1=-0.3,k2=-0.1");
  EXPECT_EQ(e.name, "vignetting");
  EXPECT_EQ(e.params.at("k1"), "-0.3");
  EXPECT_EQ(e.params.at("k2"), "-0.1");
  EXPECT_TRUE(ParseEffectSpec("pose_error").params.empty());
  EXPECT_THROW(ParseEffectSpec("glare"), InputError);
  EXPECT_EQ(ParseEffectSpec("fresnel:ior=1.7").params.at("ior"), "1.7");
  EXPECT_THROW(ParseEffectSpec("indirect_illumination"), InputError);
  EXPECT_THROW(ParseEffectSpec("vignetting:k1"), InputError);
  EXPECT_THROW(ParseEffectSpec("vignetting:k1=1,k1=2"), InputError);
}

TEST(SynthOptions, ValidateRejectsBadValues) {
  SynthOptions o;
  o.out = "x";
  EXPECT_NO_THROW(o.Validate());
  o.cameras = 0;
  o.spp = 0;
  o.unknowns = {"colour"};
  SynthChoiceFlags choices;
  choices.floor_texture = "marble";
  try {
    o.SetChoices(choices);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().size(), 4u);
  }
}

// Each choice's name parses back to it; igi-synth's choice flags are parsed by SetChoices, and a
// text that names no choice (or a BRDF other than the two Ward models) is one "--FLAG: TEXT:
// RULE" line in its place among the other options' problems.
TEST(SynthOptions, ChoicesRoundTripAndBadTextsAreNamed) {
  for (BracketFormat v : {BracketFormat::kPng, BracketFormat::kTif}) {
    EXPECT_EQ(BracketFormatFromName(BracketFormatName(v)), v);
  }
  for (LampShape v : {LampShape::kSphere, LampShape::kPoint}) {
    EXPECT_EQ(LampShapeFromName(LampShapeName(v)), v);
  }
  for (FloorTexture v : {FloorTexture::kTiles, FloorTexture::kSmooth}) {
    EXPECT_EQ(FloorTextureFromName(FloorTextureName(v)), v);
  }
  EXPECT_EQ(BracketFormatName(BracketFormat::kTif), "tif");
  EXPECT_FALSE(BracketFormatFromName("jpg"));
  EXPECT_FALSE(LampShapeFromName("spot"));
  EXPECT_FALSE(FloorTextureFromName("Tiles"));

  SynthOptions o;
  o.out = "x";
  SynthChoiceFlags flags;
  flags.glossy_brdf = "ward_gmd";
  flags.lamp = "point";
  flags.floor_texture = "smooth";
  flags.bracket_format = "tif";
  o.SetChoices(flags);
  EXPECT_EQ(o.glossy_brdf, recon::BrdfModel::kWardGmd);
  EXPECT_EQ(o.lamp, LampShape::kPoint);
  EXPECT_EQ(o.floor_texture, FloorTexture::kSmooth);
  EXPECT_EQ(o.brackets.format, BracketFormat::kTif);

  SynthOptions bad;
  bad.out = "x";
  bad.cameras = 0;
  SynthChoiceFlags typed;
  typed.glossy_brdf = "lambert";
  typed.lamp = "spot";
  typed.bracket_format = "jpg";
  try {
    bad.SetChoices(typed);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    const std::vector<std::string> want = {
        "--cameras: 0: must be 1..64",
        "--glossy-brdf: lambert: must be ward, ward_gmd, ggx or beckmann",
        "--lamp: spot: must be sphere or point", "--bracket-format: jpg: must be png or tif"};
    EXPECT_EQ(e.problems(), want);
  }
  SynthOptions lambert;
  lambert.out = "x";
  lambert.glossy_brdf = recon::BrdfModel::kLambert;
  EXPECT_THROW(lambert.Validate(), InputError);
}

// The room's OBJ reads back through Assimp with every region, UVs and normals.
TEST(SynthRoom, ObjLoadsWithRegionsUvsAndNormals) {
  SynthOptions o;
  const SynthRoom room = BuildRoom(o);
  const fs::path path = fs::temp_directory_path() / "igi_synth_room_test.obj";
  WriteFileAtomic(path, room.mesh.ToObj("test"));
  ProblemList problems;
  recon::MeshLoadSummary summary;
  const recon::TriangleMesh mesh = recon::LoadMesh(path, &problems, &summary);
  fs::remove(path);
  ASSERT_TRUE(problems.empty());
  EXPECT_TRUE(summary.has_uvs);
  EXPECT_TRUE(summary.has_normals);
  EXPECT_EQ(mesh.num_triangles(), room.mesh.triangles.size());
  for (const auto& [name, m] : room.materials.items()) {
    EXPECT_NE(std::find(mesh.region_names.begin(), mesh.region_names.end(), name),
              mesh.region_names.end())
        << name;
  }
  // The room's shell (first 12 triangles) faces inward, the objects outward.
  const Vector3d centre = 0.5 * room.size;
  for (int t = 0; t < int(room.mesh.triangles.size()); ++t) {
    const Vector3d p = room.mesh.positions[room.mesh.triangles[t][0]];
    const double towards_centre = room.mesh.FaceNormal(t).dot(centre - p);
    if (t < 12) {
      EXPECT_GT(towards_centre, 0) << t;
    }
  }
  EXPECT_NEAR(room.mesh.FaceNormal(0).z(), 1.0, 1e-12);
}

TEST(SynthRoom, HasGlossyAndLambertianRegionsATexturedFloorAndTwoLamps) {
  SynthOptions o;
  const SynthRoom room = BuildRoom(o);
  EXPECT_EQ(room.glossy_regions.size(), 4u);
  int lambert = 0;
  for (const auto& [name, m] : room.materials.items()) lambert += m["brdf"] == "lambert";
  EXPECT_GE(lambert, 4);
  EXPECT_TRUE(room.materials["floor"].contains("rho_d_map"));
  EXPECT_EQ(room.floor_albedo_file, "truth/textures/floor_albedo.exr");  // rho_d unknown
  const Vector3d mean = ImageMean(room.floor_albedo);
  EXPECT_NEAR(room.materials["floor"]["rho_d"][0].get<double>(), mean.x(), 1e-12);
  EXPECT_EQ(room.lamps.size(), 2u);
  o.unknowns = {"rho_s"};
  EXPECT_EQ(BuildRoom(o).floor_albedo_file, "textures/floor_albedo.exr");
}

// --floor-texture smooth: the same tiles without detail finer than a few texels (neighbouring
// texels differ by little where the default's grout lines jump by 0.2 or more), the same mean.
TEST(SynthRoom, SmoothFloorTextureIsTheTilesLowPassFiltered) {
  SynthOptions o;
  const Image tiles = BuildRoom(o).floor_albedo;
  o.floor_texture = FloorTexture::kSmooth;
  const SynthRoom room = BuildRoom(o);
  const Image& smooth = room.floor_albedo;
  ASSERT_EQ(smooth.width, tiles.width);
  auto largest_step = [](const Image& img) {
    double step = 0;
    for (int y = 0; y < img.height; ++y) {
      for (int x = 0; x + 1 < img.width; ++x) {
        step = std::max(step, double(std::abs(img.at(x + 1, y, 1) - img.at(x, y, 1))));
      }
    }
    return step;
  };
  EXPECT_GT(largest_step(tiles), 0.2);
  // A tile edge of up to 0.48 (0.6 against grout 0.12) blurred with σ = 2 texels: ≤ 0.48·0.2.
  EXPECT_LT(largest_step(smooth), 0.1);
  EXPECT_NEAR(ImageMean(smooth).y(), ImageMean(tiles).y(), 0.01 * ImageMean(tiles).y());
  EXPECT_NEAR(room.materials["floor"]["rho_d"][1].get<double>(), ImageMean(smooth).y(), 1e-12);
}

// Each highlight camera sits on the mirror direction of the lamp about the surface normal at its
// target point, sees that point unoccluded near the image centre.
TEST(SynthCameras, HighlightCamerasMirrorTheLamp) {
  SynthOptions o;
  o.cameras = 6;
  const SynthRoom room = BuildRoom(o);
  const auto cams = PlaceCameras(room, o);
  ASSERT_EQ(cams.size(), 6u);
  int highlight = 0;
  for (const PlacedCamera& c : cams) {
    const Vector3d eye = c.camera.CenterInWorld();
    for (int i = 0; i < 3; ++i) {
      EXPECT_GT(eye[i], 0.1);
      EXPECT_LT(eye[i], room.size[i] - 0.1);
    }
    if (c.target_region.empty()) continue;
    ++highlight;
    const Vector3d p = c.highlight_point;
    const auto hit = IntersectRay(room.mesh, eye, (p - eye).normalized());
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->distance, (p - eye).norm(), 1e-6);  // nothing in between
    EXPECT_EQ(room.mesh.region_names[room.mesh.triangle_region[hit->triangle]], c.target_region);
    const Vector3d n = room.mesh.FaceNormal(hit->triangle);
    const Vector3d l = (room.lamps[0].position - p).normalized();
    const Vector3d v = (eye - p).normalized();
    EXPECT_NEAR((2 * n.dot(l) * n - l).dot(v), 1.0, 1e-9);  // v is l mirrored about n
    EXPECT_NEAR(c.highlight_pixel.x(), 0.5 * o.width, 1e-6);
    EXPECT_NEAR(c.highlight_pixel.y(), 0.5 * o.height, 1e-6);
  }
  EXPECT_EQ(highlight, 4);
  // Deterministic for a seed.
  const auto again = PlaceCameras(room, o);
  EXPECT_TRUE(
      again[2].camera.cam_from_world.ToMatrix().isApprox(cams[2].camera.cam_from_world.ToMatrix()));
}

// Share of a camera's pixels (a coarse grid of rays) whose first hit is `region`.
double RegionShare(const SynthRoom& room, const recon::Camera& camera, const std::string& region) {
  int hits = 0, total = 0;
  for (int y = 4; y < camera.height; y += 8) {
    for (int x = 4; x < camera.width; x += 8) {
      const Vector3d dir = camera.WorldRayFromImg({x + 0.5, y + 0.5});
      const auto hit = IntersectRay(room.mesh, camera.CenterInWorld(), dir);
      ++total;
      if (hit && room.mesh.region_names[room.mesh.triangle_region[hit->triangle]] == region) ++hits;
    }
  }
  return double(hits) / total;
}

// --ceiling-cameras N: the last N overview cameras see the ceiling (the default views never do,
// and a region no photo sees cannot be solved); the other cameras are unchanged.
TEST(SynthCameras, CeilingCamerasSeeTheCeiling) {
  SynthOptions o;
  o.cameras = 8;
  const SynthRoom room = BuildRoom(o);
  const auto plain = PlaceCameras(room, o);
  o.ceiling_cameras = 2;
  const auto up = PlaceCameras(room, o);
  ASSERT_EQ(up.size(), 8u);
  for (int i = 0; i < 8; ++i) {
    const double share = RegionShare(room, up[i].camera, "ceiling");
    std::printf("cam%d ceiling share %.2f (default view %.2f)\n", i, share,
                RegionShare(room, plain[i].camera, "ceiling"));
    if (i < 6) {
      EXPECT_TRUE(up[i].camera.cam_from_world.ToMatrix().isApprox(
          plain[i].camera.cam_from_world.ToMatrix()));
      // The overview cameras look down: no ceiling (a highlight camera may catch an edge).
      if (i >= 4) {
        EXPECT_EQ(RegionShare(room, plain[i].camera, "ceiling"), 0.0);
      }
    } else {
      EXPECT_GT(share, 0.2) << "cam" << i;  // measured 0.48, 0.50
    }
  }
  o.ceiling_cameras = 9;
  EXPECT_THROW(o.Validate(), Error);
}

// --grazing-cameras N (with a low lamp): N more cameras, after the others, each the mirror view of
// the lamp's highlight on the floor at 60-80 deg from the normal (Fresnel shows there); the room's
// default lamp (2.4 m high) allows no such view, which is one clear error.
TEST(SynthCameras, GrazingCamerasSeeTheFloorsHighlightAtGrazingIncidence) {
  SynthOptions o;
  o.cameras = 4;
  o.lamp_position = Vector3d(2, 2, 0.6);
  o.grazing_cameras = 2;
  const SynthRoom room = BuildRoom(o);
  EXPECT_EQ(room.lamps[0].position, Vector3d(2, 2, 0.6));
  const auto cams = PlaceCameras(room, o);
  ASSERT_EQ(cams.size(), 6u);
  for (int i = 4; i < 6; ++i) {
    const PlacedCamera& c = cams[i];
    EXPECT_EQ(c.target_region, "floor");
    const Vector3d eye = c.camera.CenterInWorld(), p = c.highlight_point;
    const auto hit = IntersectRay(room.mesh, eye, (p - eye).normalized());
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->distance, (p - eye).norm(), 1e-6);
    const Vector3d n = room.mesh.FaceNormal(hit->triangle);
    const Vector3d l = (room.lamps[0].position - p).normalized();
    const Vector3d v = (eye - p).normalized();
    EXPECT_NEAR((2 * n.dot(l) * n - l).dot(v), 1.0, 1e-9);
    const double incidence = std::acos(n.dot(l)) * 180 / render::kPi;
    EXPECT_GT(incidence, 60.0) << "cam" << i;
    EXPECT_LT(incidence, 80.0) << "cam" << i;
  }
  o.lamp_position.reset();
  EXPECT_THROW(PlaceCameras(BuildRoom(o), o), InputError);
  o.lamp_position = Vector3d(5, 2, 0.6);
  EXPECT_THROW(o.Validate(), InputError);
}

TEST(SynthCameras, LookAtFollowsColmapAxes) {
  const recon::Camera cam = LookAtCamera("c", {2, 0.3, 1.5}, {2, 3, 1.5}, 160, 120, 60);
  // Looking along +y with z up: camera x = world +x, camera y = world -z.
  const Eigen::Matrix3d r = cam.cam_from_world.rotation.toRotationMatrix();
  EXPECT_TRUE(r.row(0).isApprox(Eigen::RowVector3d(1, 0, 0)));
  EXPECT_TRUE(r.row(1).isApprox(Eigen::RowVector3d(0, 0, -1)));
  EXPECT_TRUE(cam.CenterInWorld().isApprox(Vector3d(2, 0.3, 1.5)));
  EXPECT_NEAR(cam.focal_x_px(), 80 / std::tan(3.14159265358979323846 / 6), 1e-9);
}

struct Fixture {
  SynthOptions options;
  SynthRoom room;
  std::vector<PlacedCamera> cameras;
  SynthScenes scenes;
  PhotoEffects post;
  std::vector<std::string> photos = {"photos/cam0_L0.exr", "photos/cam1_L0.exr"};

  Fixture() : room(BuildRoom(options)), cameras(PlaceCameras(room, options)) {
    Json base = {{"materials", room.materials},
                 {"lights", room.LightsJson()},
                 {"lightings", room.LightingsJson()},
                 {"geometry", Json::array({Json{{"file", "geometry/room.obj"}}})},
                 {"cameras", Json::object()}};
    for (const PlacedCamera& c : cameras)
      base["cameras"][c.camera.name] = recon::CameraJson(c.camera);
    scenes.true_scene = base;
    scenes.declared_scene = base;
  }
  Json Apply(const std::string& spec) {
    return ApplyEffects({ParseEffectSpec(spec)}, room, cameras, photos, 5, &scenes, &post);
  }
};

TEST(SynthEffects, VignettingDarkensCornersByTheStatedFactor) {
  Fixture f;
  const Json list = f.Apply("vignetting:k1=-0.2,k2=-0.1");
  EXPECT_EQ(list[0]["effect"], "vignetting");
  EXPECT_NEAR(list[0]["params"]["corner_factor"].get<double>(), 0.7, 1e-12);
  const recon::Camera& cam = f.cameras[0].camera;
  Image img(cam.width, cam.height, 3, 1.0f);
  f.post.ApplyBeforeSensor("photos/cam0_L0.exr", cam, &img);
  // The corner pixel's centre is half a pixel in from the corner.
  const double dx = 0.5 * cam.width - 0.5, dy = 0.5 * cam.height - 0.5;
  const double r2 =
      (dx * dx + dy * dy) / (0.25 * (cam.width * cam.width + cam.height * cam.height));
  EXPECT_NEAR(img.at(0, 0), 1 - 0.2 * r2 - 0.1 * r2 * r2, 1e-6);
  EXPECT_NEAR(img.at(cam.width / 2, cam.height / 2), 1.0, 1e-4);
  EXPECT_TRUE(f.scenes.true_scene == f.scenes.declared_scene);  // scene untouched
}

TEST(SynthEffects, ExposureScaleMultipliesOnePhoto) {
  Fixture f;
  f.Apply("exposure_scale:photo=photos/cam1_L0.exr,scale=1.5");
  Image a(8, 8, 3, 2.0f), b(8, 8, 3, 2.0f);
  f.post.ApplyBeforeSensor("photos/cam0_L0.exr", f.cameras[0].camera, &a);
  f.post.ApplyBeforeSensor("photos/cam1_L0.exr", f.cameras[1].camera, &b);
  EXPECT_EQ(a.at(3, 3), 2.0f);
  EXPECT_FLOAT_EQ(b.at(3, 3), 3.0f);
}

TEST(SynthEffects, CameraResponseIsAPowerLaw) {
  Fixture f;
  f.Apply("camera_response:exponent=0.5,reference=4");
  Image img(2, 1, 3, 16.0f);
  f.post.ApplyAfterSensor(&img);
  EXPECT_FLOAT_EQ(img.at(0, 0), 8.0f);  // 4·(16/4)^0.5
}

TEST(SynthEffects, PoseErrorDeclaresAPoseOffByTheStatedAngle) {
  Fixture f;
  const Json list = f.Apply("pose_error:camera=cam1,rotation_deg=2,translation_m=0.05");
  const Json& d = f.scenes.declared_scene["cameras"]["cam1"];
  const Json& t = f.scenes.true_scene["cameras"]["cam1"];
  auto quat = [](const Json& c) {
    return Eigen::Quaterniond(c["qvec"][0].get<double>(), c["qvec"][1].get<double>(),
                              c["qvec"][2].get<double>(), c["qvec"][3].get<double>());
  };
  auto centre = [&](const Json& c) {
    const Vector3d tv(c["tvec"][0].get<double>(), c["tvec"][1].get<double>(),
                      c["tvec"][2].get<double>());
    return Vector3d(-(quat(c).conjugate() * tv));
  };
  EXPECT_NEAR(quat(d).angularDistance(quat(t)) * 180 / 3.14159265358979323846, 2.0, 1e-9);
  EXPECT_NEAR((centre(d) - centre(t)).norm(), 0.05, 1e-9);
  EXPECT_EQ(f.scenes.declared_scene["cameras"]["cam0"], f.scenes.true_scene["cameras"]["cam0"]);
  EXPECT_EQ(list[0]["params"]["camera"], "cam1");
}

TEST(SynthEffects, SceneEffectsChangeOnlyTheTrueScene) {
  Fixture f;
  const Json list = f.Apply("anisotropic_reflection");
  EXPECT_EQ(f.scenes.true_scene["materials"]["glossy_box"]["brdf"], "ward_aniso");
  EXPECT_EQ(f.scenes.declared_scene["materials"]["glossy_box"]["brdf"], "ward");
  EXPECT_FALSE(f.scenes.true_scene["materials"]["glossy_box"].contains("alpha"));
  f.Apply("light_source_extent:radius=0.2");
  EXPECT_EQ(f.scenes.true_scene["lights"]["lamp"]["radius"], 0.2);
  EXPECT_EQ(f.scenes.declared_scene["lights"]["lamp"]["radius"], 0.04);
  f.Apply("missing_geometry");
  EXPECT_EQ(f.scenes.true_scene["geometry"].size(), 2u);
  EXPECT_EQ(f.scenes.declared_scene["geometry"].size(), 1u);
  EXPECT_EQ(f.scenes.extra_files.count("truth/geometry/missing_object.obj"), 1u);
  f.Apply("ambient_light:radiance=0.5");
  EXPECT_EQ(f.scenes.true_scene["lightings"]["L0"].size(), 2u);
  EXPECT_EQ(f.scenes.true_scene["lights"]["ambient"]["type"], "ambient");  // the default kind
  EXPECT_FALSE(f.scenes.declared_scene["lights"].contains("ambient"));
  f.Apply("light_emission_profile:cos_power=3");
  EXPECT_EQ(f.scenes.true_scene["lights"]["lamp"]["type"], "spot");
  EXPECT_EQ(f.scenes.declared_scene["lights"]["lamp"]["type"], "sphere");
  f.Apply("specular_lobe_shape:regions=floor/wall_y4");
  EXPECT_EQ(f.scenes.true_scene["materials"]["floor"]["brdf"], "ward_gmd");
  EXPECT_EQ(f.scenes.declared_scene["materials"]["floor"]["brdf"], "ward");
  f.Apply("light_intensity:light=lamp2,factor=2");
  EXPECT_DOUBLE_EQ(f.scenes.true_scene["lights"]["lamp2"]["radiance"][0].get<double>(),
                   2 * f.scenes.declared_scene["lights"]["lamp2"]["radiance"][0].get<double>());
  f.Apply("specular_reflection:region=glossy_sphere");
  EXPECT_EQ(f.scenes.declared_scene["materials"]["glossy_sphere"]["brdf"], "lambert");
  EXPECT_FALSE(f.scenes.declared_scene["materials"]["glossy_sphere"].contains("rho_s"));
}

// diffuse_shape: the regions without a lobe take Oren–Nayar's term (σ 0.4 by default) or the
// coated base's (no parameter) in the true scene only.
TEST(SynthEffects, DiffuseShapeChangesTheTrueDiffuseTerm) {
  Fixture f;
  const Json on = f.Apply("diffuse_shape:regions=matte_box,sigma=0.3");
  EXPECT_EQ(on[0]["params"]["to"], "oren_nayar");
  EXPECT_EQ(f.scenes.true_scene["materials"]["matte_box"]["diffuse"], "oren_nayar");
  EXPECT_EQ(f.scenes.true_scene["materials"]["matte_box"]["sigma"], 0.3);
  EXPECT_FALSE(f.scenes.declared_scene["materials"]["matte_box"].contains("diffuse"));
  Fixture g;
  const Json coated = g.Apply("diffuse_shape:to=coated");
  EXPECT_EQ(coated[0]["params"]["to"], "coated");
  for (const std::string& region : coated[0]["params"]["regions"]) {
    EXPECT_EQ(g.scenes.true_scene["materials"][region]["diffuse"], "coated") << region;
    EXPECT_FALSE(g.scenes.true_scene["materials"][region].contains("sigma")) << region;
    EXPECT_FALSE(g.scenes.declared_scene["materials"][region].contains("diffuse")) << region;
  }
  EXPECT_THROW(g.Apply("diffuse_shape:to=rough"), InputError);
}

// fresnel: the glossy regions become *_fresnel in the true scene only, with the ior; it
// composes with the effects that rename the model (before or after them).
TEST(SynthEffects, FresnelWeightsTheTrueGlossyRegionsOnly) {
  Fixture f;
  const Json list = f.Apply("fresnel:regions=floor/glossy_box,ior=1.6");
  const Json& params = list[0]["params"];
  EXPECT_EQ(list[0]["effect"], "fresnel");
  EXPECT_EQ(params["ior"], 1.6);
  EXPECT_NEAR(params["f0"].get<double>(), std::pow(0.6 / 2.6, 2), 1e-15);
  EXPECT_EQ(params["regions"]["floor"]["true_brdf"], "ward_fresnel");
  EXPECT_EQ(params["regions"]["floor"]["declared_brdf"], "ward");
  EXPECT_EQ(f.scenes.true_scene["materials"]["floor"]["brdf"], "ward_fresnel");
  EXPECT_EQ(f.scenes.true_scene["materials"]["floor"]["ior"], 1.6);
  EXPECT_EQ(f.scenes.declared_scene["materials"]["floor"]["brdf"], "ward");
  EXPECT_FALSE(f.scenes.declared_scene["materials"]["floor"].contains("ior"));
  EXPECT_EQ(f.scenes.true_scene["materials"]["glossy_sphere"]["brdf"], "ward");  // not listed
  // Effects that rename the model keep the Fresnel weight.
  f.Apply("anisotropic_reflection");
  EXPECT_EQ(f.scenes.true_scene["materials"]["glossy_box"]["brdf"], "ward_aniso_fresnel");
  f.Apply("specular_lobe_shape:regions=floor");
  EXPECT_EQ(f.scenes.true_scene["materials"]["floor"]["brdf"], "ward_gmd_fresnel");
  // A microfacet region takes its own anisotropic form.
  Fixture ggx;
  ggx.scenes.true_scene["materials"]["glossy_box"]["brdf"] = "ggx";
  ggx.Apply("anisotropic_reflection");
  EXPECT_EQ(ggx.scenes.true_scene["materials"]["glossy_box"]["brdf"], "ggx_aniso");
  f.Apply("fresnel:regions=floor,ior=2");  // again: the model stays, the ior changes
  EXPECT_EQ(f.scenes.true_scene["materials"]["floor"]["brdf"], "ward_gmd_fresnel");
  EXPECT_EQ(f.scenes.true_scene["materials"]["floor"]["ior"], 2.0);
  EXPECT_THROW(f.Apply("fresnel:ior=1"), InputError);
  EXPECT_THROW(f.Apply("fresnel:regions=matte_box"), InputError);
}

TEST(SynthEffects, BadParametersAreInputErrors) {
  Fixture f;
  EXPECT_THROW(f.Apply("vignetting:k3=1"), InputError);
  EXPECT_THROW(f.Apply("vignetting:k1=-0.9,k2=-0.1"), InputError);
  EXPECT_THROW(f.Apply("pose_error:camera=nope"), InputError);
  EXPECT_THROW(f.Apply("anisotropic_reflection:tangent=0/0/0"), InputError);
  EXPECT_THROW(f.Apply("exposure_scale:scale=abc"), InputError);
}

}  // namespace
}  // namespace igi::synth

namespace igi::synth {
namespace {

namespace fs = std::filesystem;

fs::path RadianceRoom() {
  return fs::path(IGI_SHARED_DATA_DIR) / "reference" / "radiance_room" / "scene.json";
}

// --from: another renderer's capture (the shared RADIANCE room) given the photo effects: each
// photo is the source's times the vignetting and its exposure scale, through the response; the
// declared pose of pose_error's camera is off, the true scene is the source's; nothing is
// rendered and the source is not touched.
TEST(SynthFrom, HidesThePhotoEffectsInAnotherRenderersCapture) {
  const fs::path out = test::UniqueTempDir("igi_synth_from");
  SynthOptions o;
  o.out = out / "capture";
  o.from = RadianceRoom();
  o.unknowns = {"rho_d"};
  o.effects = {ParseEffectSpec("vignetting:k1=-0.3,k2=0"),
               ParseEffectSpec("exposure_scale:photo=photos/cam1_L0.exr,scale=1.25"),
               ParseEffectSpec("camera_response:exponent=0.8,reference=1"),
               ParseEffectSpec("pose_error:camera=cam2,rotation_deg=1,translation_m=0.02")};
  const SynthSummary s = Synthesize(o);
  ASSERT_EQ(s.photos.size(), 4u);
  const recon::Scene source = recon::LoadScene(RadianceRoom());
  const recon::Scene declared = recon::LoadScene(o.out / "scene.json");
  const recon::Scene truth = recon::LoadScene(o.out / "truth" / "scene.json");
  ASSERT_EQ(declared.photos.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const Image src = ReadImage(source.photos[i].file, 3);
    const Image got = ReadImage(declared.photos[i].file, 3);
    const recon::Camera& cam = source.cameras[source.photos[i].camera];
    const double scale = declared.photos[i].file.filename() == "cam1_L0.exr" ? 1.25 : 1.0;
    ASSERT_EQ(got.width, src.width);
    for (const auto& [x, y] : {std::pair{0, 0}, {cam.width / 2, cam.height / 2}, {17, 200}}) {
      const double dx = x + 0.5 - cam.principal_x_px(), dy = y + 0.5 - cam.principal_y_px();
      const double r2 =
          (dx * dx + dy * dy) / (0.25 * (cam.width * cam.width + cam.height * cam.height));
      const double want = std::pow(src.at(x, y, 1) * scale * (1 - 0.3 * r2), 0.8);
      EXPECT_NEAR(got.at(x, y, 1), want, 1e-5 * want) << i << ": " << x << "," << y;
    }
  }
  // The declared cam2 is off by the stated angle; the true one is the source's.
  const Eigen::Quaterniond qd = declared.cameras[2].cam_from_world.rotation,
                           qs = source.cameras[2].cam_from_world.rotation,
                           qt = truth.cameras[2].cam_from_world.rotation;
  EXPECT_NEAR(qd.angularDistance(qs) * 180 / render::kPi, 1.0, 1e-6);
  EXPECT_NEAR(qt.angularDistance(qs), 0, 1e-9);
  EXPECT_NEAR(declared.cameras[0].cam_from_world.rotation.angularDistance(
                  source.cameras[0].cam_from_world.rotation),
              0, 1e-9);
  // Materials: rho_d left out of the declared scene; the truth's are the source's.
  const Json d = ReadJsonFile(o.out / "scene.json"), t = ReadJsonFile(o.out / "truth.json");
  EXPECT_FALSE(d["materials"]["floor"].contains("rho_d"));
  EXPECT_EQ(t["materials"], source.document["materials"]);
  ASSERT_EQ(t["effects"].size(), 4u);
  EXPECT_EQ(t["effects"][1]["params"]["photo"], "photos/cam1_L0.exr");
  fs::remove_all(out);
}

TEST(SynthFrom, AnEffectThatNeedsARenderIsAnInputError) {
  const fs::path out = test::UniqueTempDir("igi_synth_from_bad");
  SynthOptions o;
  o.out = out / "capture";
  o.from = RadianceRoom();
  o.effects = {ParseEffectSpec("light_intensity")};
  try {
    Synthesize(o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("light_intensity"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("changes what is rendered"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(o.out));
  fs::remove_all(out);
}

}  // namespace
}  // namespace igi::synth
