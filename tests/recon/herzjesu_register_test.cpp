// Registration against real ground-truth cameras: the Herz-Jesu-P8 photos (Strecha et al., CVPR
// 2008; ../shared/data/real/strecha_herzjesu_p8, cameras measured with a laser-scanned reference)
// registered by igi-register's job, side by side with COLMAP 3.8 alone: the model the same run's
// mapper wrote (principal point at the image centre), before igi refines it. Per photo: the
// rotation error after the similarity that best aligns the recovered camera centres to the
// measured ones (Umeyama; photos alone have no frame or scale), the centre error after it (mm),
// and the focal error against K.txt (%).
//
// The quarter-size case runs in the normal suite (about 15 s on 2 cores); the full-size case
// (6 MP SIFT: 1.6 min on 2 idle cores, 2.5 min beside other work) is named Slow* and labelled
// slow (IGI_SLOW=1).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "recon/camera.h"
#include "recon/colmap_model.h"
#include "recon/register_job.h"
#include "tests/temp_dir.h"
#include "tools/common/json.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Vector3d;

const fs::path kHerzJesu = fs::path(IGI_SHARED_DATA_DIR) / "real" / "strecha_herzjesu_p8";

// The measured cameras: K.txt and per photo cam_from_world's rotation and the centre (metres).
struct GroundTruth {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // full size, px
  std::map<std::string, Matrix3d> cam_from_world;
  std::map<std::string, Vector3d> centre;
};

// gt_cameras/NAME.camera: 3 rows of K, a row of zeros, 3 rows of R (columns: the camera axes in
// the world), the centre t, then width and height; cam_from_world = Rᵀ.
GroundTruth ReadGroundTruth() {
  GroundTruth gt;
  std::ifstream k(kHerzJesu / "K.txt");
  double m[9];
  for (double& v : m) k >> v;
  gt.fx = m[0], gt.cx = m[2], gt.fy = m[4], gt.cy = m[5];
  for (const auto& entry : fs::directory_iterator(kHerzJesu / "gt_cameras")) {
    std::ifstream in(entry.path());
    double v[24];
    for (double& x : v) in >> x;
    Matrix3d r;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r(i, j) = v[12 + 3 * i + j];
    }
    const std::string name = entry.path().stem().string();  // "0000.jpg"
    gt.cam_from_world[name] = r.transpose();
    gt.centre[name] = Vector3d(v[21], v[22], v[23]);
  }
  return gt;
}

struct PhotoError {
  double rotation_deg = 0;
  double centre_mm = 0;
};

struct ModelErrors {
  std::map<std::string, PhotoError> photos;
  double fx_pct = 0, fy_pct = 0;  // focal lengths against K.txt's (scaled to the photos' size)
  double cx_px = 0, cy_px = 0;    // principal point, at the photos' size
  double max_rotation_deg = 0, rms_centre_mm = 0;
};

// The errors of `model` (registered from photos `downscale` times smaller than the originals).
ModelErrors Evaluate(const ColmapModel& model, const GroundTruth& gt, int downscale) {
  const int n = static_cast<int>(model.images.size());
  Eigen::Matrix3Xd recovered(3, n), measured(3, n);
  std::vector<const ColmapImage*> images;
  for (const auto& [id, image] : model.images) {
    const Camera camera = CameraOfImage(model, image);
    recovered.col(static_cast<int>(images.size())) = camera.CenterInWorld();
    measured.col(static_cast<int>(images.size())) = gt.centre.at(image.name);
    images.push_back(&image);
  }
  // measured ≈ s Q recovered + T.
  const Eigen::Matrix4d sim = Eigen::umeyama(recovered, measured, true);
  const double scale = sim.block<3, 1>(0, 0).norm();
  const Matrix3d q = sim.block<3, 3>(0, 0) / scale;
  ModelErrors e;
  double sum_sq = 0;
  for (int i = 0; i < n; ++i) {
    const Camera camera = CameraOfImage(model, *images[i]);
    // The recovered camera in the measured frame: cam_from_world R Qᵀ.
    const Matrix3d r = camera.cam_from_world.rotation.toRotationMatrix() * q.transpose();
    PhotoError p;
    p.rotation_deg =
        Eigen::AngleAxisd(r * gt.cam_from_world.at(images[i]->name).transpose()).angle() * 180 /
        M_PI;
    p.centre_mm =
        1000 * ((sim * recovered.col(i).homogeneous()).head<3>() - measured.col(i)).norm();
    e.photos[images[i]->name] = p;
    e.max_rotation_deg = std::max(e.max_rotation_deg, p.rotation_deg);
    sum_sq += p.centre_mm * p.centre_mm;
  }
  e.rms_centre_mm = std::sqrt(sum_sq / std::max(1, n));
  const Camera camera = CameraOfImage(model, *images[0]);
  e.fx_pct = 100 * (camera.focal_x_px() * downscale / gt.fx - 1);
  e.fy_pct = 100 * (camera.focal_y_px() * downscale / gt.fy - 1);
  e.cx_px = camera.principal_x_px();
  e.cy_px = camera.principal_y_px();
  return e;
}

void PrintTable(const std::string& title, const ModelErrors& colmap, const ModelErrors& igi) {
  std::printf("%s\n| photo | rotation COLMAP / igi (deg) | centre COLMAP / igi (mm) |\n",
              title.c_str());
  for (const auto& [name, c] : colmap.photos) {
    const PhotoError& i = igi.photos.at(name);
    std::printf("| %s | %.3f / %.3f | %.1f / %.1f |\n", name.c_str(), c.rotation_deg,
                i.rotation_deg, c.centre_mm, i.centre_mm);
  }
  std::printf("| worst, RMS | %.3f / %.3f | RMS %.1f / %.1f |\n", colmap.max_rotation_deg,
              igi.max_rotation_deg, colmap.rms_centre_mm, igi.rms_centre_mm);
  std::printf("focal fx, fy against K.txt: COLMAP %+.3f %%, %+.3f %%; igi %+.3f %%, %+.3f %%\n",
              colmap.fx_pct, colmap.fy_pct, igi.fx_pct, igi.fy_pct);
  std::printf("principal point: COLMAP %.2f, %.2f px; igi %.2f, %.2f px\n", colmap.cx_px,
              colmap.cy_px, igi.cx_px, igi.cy_px);
}

// The photos downscaled `factor` times (area averaging) into `dir`.
void WriteDownscaled(const fs::path& dir, int factor) {
  fs::create_directories(dir);
  for (const auto& entry : fs::directory_iterator(kHerzJesu / "images")) {
    const cv::Mat full = cv::imread(entry.path().string());
    cv::Mat small;
    cv::resize(full, small, cv::Size(full.cols / factor, full.rows / factor), 0, 0, cv::INTER_AREA);
    cv::imwrite((dir / entry.path().filename()).string(), small, {cv::IMWRITE_JPEG_QUALITY, 95});
  }
}

// COLMAP's own model of the run (the largest under colmap/models/).
ColmapModel ColmapAlone(const fs::path& out) {
  ColmapModel best;
  for (const auto& entry : fs::directory_iterator(out / "colmap" / "models")) {
    ColmapModel model = ReadColmapModel(entry.path());
    if (model.images.size() > best.images.size()) best = std::move(model);
  }
  return best;
}

struct Registered {
  ModelErrors colmap, igi;
  Json refinement;  // report.json's "intrinsics_refinement"
};

// Registers `images` (photos `downscale` times smaller than the originals) with igi-register's
// defaults but `camera_model`, and measures COLMAP's and igi's models.
Registered RegisterAndMeasure(const fs::path& images, const fs::path& out, int downscale,
                              calib::ColmapCameraModel camera_model) {
  RegisterOptions options;
  options.images = images.string();
  options.out = out.string();
  options.colmap.camera_model = camera_model;
  const RegisterSummary summary = Register(options, ValidateRegisterInputs(options));
  EXPECT_EQ(summary.registered, 8u);
  EXPECT_TRUE(summary.unregistered.empty());
  const GroundTruth gt = ReadGroundTruth();
  const ColmapModel colmap = ColmapAlone(out);
  EXPECT_EQ(colmap.images.size(), 8u);
  Registered r;
  r.colmap = Evaluate(colmap, gt, downscale);
  r.igi = Evaluate(ReadColmapModel(out / "sparse"), gt, downscale);
  r.refinement = ReadJsonFile(out / "report.json")["intrinsics_refinement"];
  return r;
}

// What igi must do at any size: no photo turned more than COLMAP turned it, centres as close,
// and the focal lengths as close to K.txt within igi's own focal uncertainty (3 standard
// deviations of the adjustment's f: the principal point and f are correlated, so freeing the
// one moves the other by about that much).
void ExpectNoWorseThanColmap(const Registered& r) {
  for (const auto& [name, c] : r.colmap.photos) {
    EXPECT_LE(r.igi.photos.at(name).rotation_deg, c.rotation_deg) << name;
  }
  EXPECT_LE(r.igi.rms_centre_mm, r.colmap.rms_centre_mm);
  const Json& fit = r.refinement["adjustments"].back()["cameras"][0];
  const double focal_tolerance_pct =
      300 * fit["focal_sigma_px"].get<double>() / fit["focal_px"].get<double>();
  EXPECT_LE(std::abs(r.igi.fx_pct), std::abs(r.colmap.fx_pct) + focal_tolerance_pct);
  EXPECT_LE(std::abs(r.igi.fy_pct), std::abs(r.colmap.fy_pct) + focal_tolerance_pct);
}

// A quarter of the size (768×512), igi-register's defaults (SIMPLE_RADIAL self-calibrated): the
// principal point is kept (K.txt's is 3.8 px left of and 4.3 px above the centre here, 6 standard
// deviations), the aspect ratio is not (K.txt's fy / fx = 1.0017 is under 3 of its standard
// deviations at this size), and the rotation COLMAP's centred principal point leaves (about 0.5
// degrees on every photo) shrinks to under 0.25 degrees: measured worst 0.15-0.19 in three
// matchings (SIFT positions are 4x coarser against the focal length than at full size).
TEST(HerzJesuRegisterTest, QuarterSizeRefinesThePrincipalPoint) {
  const fs::path dir = test::UniqueTempDir("igi_herzjesu_quarter");
  constexpr int kDownscale = 4;
  WriteDownscaled(dir / "images", kDownscale);
  const Registered r = RegisterAndMeasure(dir / "images", dir / "out", kDownscale,
                                          calib::ColmapCameraModel::kSimpleRadial);
  PrintTable("Herz-Jesu-P8, quarter size, SIMPLE_RADIAL", r.colmap, r.igi);
  ASSERT_EQ(r.igi.photos.size(), 8u);
  EXPECT_EQ(r.refinement["kept"]["1"], "principal_point") << r.refinement.dump(1);
  ExpectNoWorseThanColmap(r);
  EXPECT_LE(r.igi.max_rotation_deg, 0.25);
  // K.txt's principal point at this size, within 3 px (3 of its standard deviations here; K.txt
  // does not say its pixel-centre convention, which moves it by 0.375 px at this size).
  const GroundTruth gt = ReadGroundTruth();
  EXPECT_NEAR(r.igi.cx_px, gt.cx / kDownscale, 3.0);
  EXPECT_NEAR(r.igi.cy_px, gt.cy / kDownscale, 3.0);
  fs::remove_all(dir);
}

// Full size (3072×2048) with a PINHOLE camera (the photos were undistorted by the benchmark's
// authors): the principal point is kept and every photo is within 0.1 degrees of its measured
// rotation. Measured worst 0.089-0.097 over four matchings: the bar is at this benchmark's floor.
// What remains is mostly one turn of about 0.07 degrees common to every photo, about the line of
// cameras, where the centres' similarity is least determined; K.txt's own intrinsics held fixed
// leave 0.13 degrees.
TEST(HerzJesuRegisterTest, SlowFullSizeWithinATenthOfADegree) {
  const fs::path dir = test::UniqueTempDir("igi_herzjesu_full");
  const Registered r =
      RegisterAndMeasure(kHerzJesu / "images", dir / "out", 1, calib::ColmapCameraModel::kPinhole);
  PrintTable("Herz-Jesu-P8, full size, PINHOLE", r.colmap, r.igi);
  ASSERT_EQ(r.igi.photos.size(), 8u);
  EXPECT_EQ(r.refinement["kept"]["1"], "principal_point") << r.refinement.dump(1);
  ExpectNoWorseThanColmap(r);
  for (const auto& [name, p] : r.igi.photos) EXPECT_LE(p.rotation_deg, 0.1) << name;
  const GroundTruth gt = ReadGroundTruth();
  EXPECT_NEAR(r.igi.cx_px, gt.cx, 4.0);  // 4 standard deviations at full size
  EXPECT_NEAR(r.igi.cy_px, gt.cy, 4.0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::recon
