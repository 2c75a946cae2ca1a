#pragma once
// missing_geometry (docs/diagnose-effects.md): an object in the photos that the geometry lacks.
//
// 1. Blobs: per photo, coherent regions where the photo and the model differ by much more than
//    the noise (a 3×3-smoothed relative residual above a threshold, isolated pixels removed,
//    connected regions of a minimum area kept). Held-out and invalid pixels are "unknown".
// 2. Surface blobs: a blob pixel whose modelled surface point most of the other cameras that see
//    it also show in a blob is a change on the modelled surface (a shadow, a stain, a texture):
//    the photos agree on the surface point. The other blob pixels show something in front of
//    the surfaces. Most, not all: a blob near the threshold is missed by the odd photo's noise.
// 3. Carving: a voxel grid over the scene's bounding box; a voxel is carved ("something there
//    the model lacks") when at least two cameras see it (it lies in front of the modelled surface
//    along their pixel ray) with its projection in a blob, and no photo that sees it shows a
//    known pixel outside the blobs there. Carved once from the object blobs (surface blobs
//    unknown), once from every blob.
// 4. Object and shadow: voxels carved from the object blobs off the modelled surfaces (farther
//    than 1.5 voxels) form the object (26-connected components); voxels carved from every blob
//    on the surfaces and attached to it are its shadow. The object's box reaches down to the
//    surface it stands on.
// 5. Exclusion: per photo a mask (1 = keep) covering the projection of the object's hull and of
//    its shadow layer, dilated, with the blob pixels it touches; combined with the photo's mask.
//
// The blobs come from the fitted (not held-out) pixels only, so the masks predict where the
// held-out residual lies: the candidate's score is the share of the held-out residual² inside
// the masks. Its significance is the contrast of residual² inside vs outside masks that never saw
// the pixels scored (blocks as units, a Mann–Whitney rank test stratified over folds): the
// held-out blocks with the masks above, and each share of the fitted blocks with masks carved
// again without it (cross-fitting). The held-out blocks alone hold a quarter of a small object's
// pixels: an object seen small by two photos left a handful of blocks to rank.
//
// Last, the surface behind it: an object hides the modelled surface from the photos that see it
// in front, while other photos see that surface as modelled; a change on the surface (a texture's
// tiles, whose blobs in a few photos can carve together off the floor by chance) shows alike
// from every side. The residual where other photos see the surface point behind each pixel of
// the object's projection (not through the object, outside its shadow from their lights),
// regressed on the residual at that pixel, must stay below max_surface_slope.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "recon/camera.h"
#include "recon/scene.h"
#include "solver/diagnose/candidates.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/inverse/photo_model.h"
#include "tools/common/image.h"

namespace igi::diagnose {

struct MissingGeometryOptions {
  double voxels_per_extent = 80;      // voxel = the scene box's largest extent / this
  double min_relative = 0.12;         // blob threshold on the smoothed relative residual, at least
  double median_factor = 4;           // ... and this many times the photo's median
  double min_area_fraction = 0.0015;  // a blob covers at least this share of the image
  // ... and at least this many pixels, >= 1.
  int min_area_px = 12;
  int min_views = 2;        // photos that see a carved voxel in a blob
  int min_core_voxels = 8;  // an object has at least this many off-surface voxels
  int dilate_px = 3;        // the masks' margin
  // The significance test's cross-fitting: the pixels split into this many folds of blocks (the
  // held-out blocks, and equal shares of the fitted ones); each fold is scored with masks carved
  // without it. 1: the held-out blocks only.
  int folds = 4;
  // The residual² per pixel inside the masks, pooled over the folds, at least this many times the
  // level outside them: a missing object's pixels differ from the model by far more than the
  // noise; a phantom carved from a few blobs on a grazing floor's highlights does not, though
  // its rank test may pass.
  double min_contrast = 2;
  // Where other photos see the modelled surface behind the object (unoccluded by it, outside its
  // shadow), their residual regressed on the residual inside its projections: a slope of at least
  // this is a change on the surface, not an object: an object hides the surface from one side
  // only, a change on it shows alike from every side (measured: docs/diagnose.md). Judged over
  // at least min_agreement_pairs pixel pairs.
  double max_surface_slope = 0.5;
  int min_agreement_pairs = 30;

  void Validate() const;
};

// A photo's view for carving: its camera, the modelled surface's distance along each pixel's ray
// (infinity where the ray escapes), and the blob state per pixel: 1 blob, 0 clear, −1 unknown.
struct CarveView {
  recon::Camera camera;
  int camera_id = 0;  // views of one camera (several lightings) count as one view
  Image depth_m;      // 1 channel
  Image state;        // 1 channel
};

struct VoxelGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // the min corner
  double voxel_m = 0.05;
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();

  int64_t Count() const { return int64_t(dims.x()) * dims.y() * dims.z(); }
  int64_t Index(int x, int y, int z) const { return (int64_t(z) * dims.y() + y) * dims.x() + x; }
  Eigen::Vector3i Cell(int64_t i) const;
  Eigen::Vector3d Center(int64_t i) const;
  // A grid over `box` with cubes of `voxel_m`.
  static VoxelGrid Over(const Eigen::AlignedBox3d& box, double voxel_m);
};

struct CarvedObject {
  // The centroid of the carved volume in its box (the visual hull, whose roof the cameras see
  // from above raises the box's top: the centroid lies nearer the object's centre), the box.
  Eigen::Vector3d center = Eigen::Vector3d::Zero(), size_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  int core_voxels = 0;                 // off the modelled surfaces
  std::vector<int64_t> box_voxels;     // every voxel of its bounding box
  std::vector<int64_t> volume_voxels;  // the carved ones among them (its visual hull)
  std::vector<int64_t> shadow_voxels;  // carved voxels on the surfaces attached to it
};

// The blob state of one photo (1 blob, 0 clear, −1 unknown): `usable` (1 channel) marks the
// pixels whose residual may be used. Unusable pixels where `infer` is 1 get a state from their
// neighbours (blob inside the blobs' closing over infer_px, clear elsewhere), not unknown.
Image FindResidualBlobs(const Image& recorded, const Image& sim, const Image& usable,
                        const MissingGeometryOptions& options, const Image* infer = nullptr,
                        int infer_px = 0);

// Carves the grid (see the file comment): 1 per carved voxel; min_views distinct cameras.
std::vector<uint8_t> CarveVoxels(const std::vector<CarveView>& views, const VoxelGrid& grid,
                                 int min_views);

// Voxels within 1.5 voxels of the mesh's triangles: 1 per such voxel.
std::vector<uint8_t> NearSurfaceVoxels(const recon::TriangleMesh& mesh, const VoxelGrid& grid);

// The views with their "surface" blob pixels made unknown: those whose modelled surface point
// more of the other cameras that see it (and know) show in a blob than clear — a change on the
// modelled surface (a shadow, a stain, a texture), which carving would otherwise raise into a
// phantom volume above it.
std::vector<CarveView> WithoutSurfaceBlobs(const std::vector<CarveView>& views, double margin_m);

// The objects, largest first: off-surface voxels of `carved_object` (carved from the views
// without surface blobs); their boxes grow into, and their shadows are the attached surface
// voxels of, `carved_all` (carved from every blob).
std::vector<CarvedObject> CarvedObjects(const std::vector<uint8_t>& carved_object,
                                        const std::vector<uint8_t>& carved_all,
                                        const std::vector<uint8_t>& near_surface,
                                        const VoxelGrid& grid, int min_core_voxels);

// 1 where the voxels seen by `view` project (their cubes' image footprints), dilated by
// `dilate_px`.
Image ProjectVoxels(const CarveView& view, const VoxelGrid& grid,
                    const std::vector<int64_t>& voxels, int dilate_px);

struct MissingGeometryResult {
  CandidateResult candidate;      // effect "missing_geometry"; valid when an object was found
  std::vector<Image> keep_masks;  // per photo, 1 = keep (the photo's own mask included)
  std::vector<Image> excluded;    // per photo, 1 = excluded as the object or its shadow
};

// Locates missing geometry from the residual of `model` (sims: its simulated photos) and writes
// the masks into mask_dir (PNG, one per photo; the candidate's params "mask_files" name them).
MissingGeometryResult LocateMissingGeometry(const recon::Scene& model, const PhotoSet& photos,
                                            const std::vector<Image>& sims,
                                            const std::vector<PixelRecord>& records,
                                            const solver::PixelHoldout& holdout,
                                            const std::filesystem::path& mask_dir,
                                            const MissingGeometryOptions& options = {});

// `photos` with the excluded pixels made invalid.
PhotoSet MaskedPhotoSet(const PhotoSet& photos, const std::vector<Image>& excluded);

}  // namespace igi::diagnose
