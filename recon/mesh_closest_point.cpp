#include "recon/mesh_closest_point.h"

#include <embree3/rtcore.h>

#include <limits>

#include "tools/common/error.h"

namespace igi::recon {

Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

struct MeshClosestPoint::Impl {
  const TriangleMesh* mesh = nullptr;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
};

namespace {

struct QueryState {
  const TriangleMesh* mesh;
  Eigen::Vector3d p;
  ClosestPoint best;
  double best_distance = std::numeric_limits<double>::infinity();
};

bool QueryTriangle(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<QueryState*>(args->userPtr);
  const TriangleMesh& mesh = *state->mesh;
  const Eigen::Vector3i& t = mesh.triangles[args->primID];
  const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
  const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
  const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
  const Eigen::Vector3d q = ClosestPointOnTriangle(state->p, a, b, c);
  const double d = (q - state->p).norm();
  if (d >= state->best_distance) return false;
  state->best_distance = d;
  state->best.point = q;
  state->best.distance_m = d;
  state->best.triangle = static_cast<int>(args->primID);
  args->query->radius = static_cast<float>(d);
  return true;
}

}  // namespace

MeshClosestPoint::MeshClosestPoint(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  impl_->mesh = &mesh;
  impl_->device = rtcNewDevice(nullptr);
  if (impl_->device == nullptr) throw Error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.positions.size()));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
  }
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = static_cast<unsigned>(mesh.triangles[i][k]);
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl_->scene);
}

MeshClosestPoint::~MeshClosestPoint() {
  if (impl_->scene != nullptr) rtcReleaseScene(impl_->scene);
  if (impl_->device != nullptr) rtcReleaseDevice(impl_->device);
}

std::optional<ClosestPoint> MeshClosestPoint::Query(const Eigen::Vector3d& p,
                                                    double max_distance_m) const {
  RTCPointQuery query;
  query.x = static_cast<float>(p.x());
  query.y = static_cast<float>(p.y());
  query.z = static_cast<float>(p.z());
  query.radius = static_cast<float>(std::min(max_distance_m, 1e30));
  query.time = 0;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  QueryState state{impl_->mesh, p, {}, std::numeric_limits<double>::infinity()};
  rtcPointQuery(impl_->scene, &query, &context, QueryTriangle, &state);
  if (state.best.triangle < 0 || state.best_distance > max_distance_m) return std::nullopt;
  state.best.normal = impl_->mesh->FaceNormal(state.best.triangle).cast<double>();
  return state.best;
}

std::optional<MeshRayHit> MeshClosestPoint::Intersect(const Eigen::Vector3d& origin,
                                                      const Eigen::Vector3d& direction,
                                                      double t_min, double t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(direction.x());
  rh.ray.dir_y = static_cast<float>(direction.y());
  rh.ray.dir_z = static_cast<float>(direction.z());
  rh.ray.tnear = static_cast<float>(t_min);
  rh.ray.tfar = static_cast<float>(std::min(t_max, 1e30));
  rh.ray.time = 0;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return MeshRayHit{static_cast<int>(rh.hit.primID), rh.ray.tfar, rh.hit.u, rh.hit.v};
}

}  // namespace igi::recon
