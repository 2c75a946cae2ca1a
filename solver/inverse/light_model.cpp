#include "solver/inverse/light_model.h"

#include <algorithm>

#include "solver/inverse/neighbour_mean.h"
#include "solver/inverse/observations.h"
#include "solver/render/brdf.h"
#include "tools/common/parallel.h"

namespace igi::solver {

std::vector<Eigen::Vector3d> NeighbourMean(const ObservationSet& obs,
                                           const std::vector<LightingState>& lightings,
                                           const std::vector<Eigen::Vector3d>& values,
                                           double radius, bool same_photo, int num_threads,
                                           const std::vector<float>* point_radius) {
  std::vector<Eigen::Vector3d> out(obs.size(), Eigen::Vector3d::Zero());
  std::vector<NeighbourPoint> points(obs.size());
  for (size_t i = 0; i < obs.size(); ++i) {
    points[i] = {obs[i].position, obs[i].normal, obs[i].region, obs[i].photo};
  }
  for (const LightingState& st : lightings) {
    if (st.active) {
      NeighbourMean(points, values, st.obs, radius, same_photo, num_threads, &out, point_radius);
    }
  }
  return out;
}

void SmoothIrradiance(const ObservationSet& obs, int num_threads, LightModel* light) {
  double widest = 0;  // the grid's cell
  for (float r : light->smoothing_radius) widest = std::max(widest, double(r));
  const std::vector<Eigen::Vector3d> smooth =
      NeighbourMean(obs, light->lightings, light->e_indirect, widest, false, num_threads,
                    &light->smoothing_radius);
  light->e.resize(obs.size());
  for (size_t i = 0; i < obs.size(); ++i) light->e[i] = light->e_direct[i] + smooth[i];
}

std::vector<Eigen::Vector3d> SpecularTerms(const ObservationSet& obs,
                                           const MaterialEstimate& materials,
                                           const std::vector<std::vector<IncidentLocal>>& incident,
                                           int num_threads, std::vector<Eigen::Vector3d>* offsets) {
  std::vector<Eigen::Vector3d> out(obs.size(), Eigen::Vector3d::Zero());
  offsets->assign(obs.size(), Eigen::Vector3d::Zero());
  ParallelFor(
      0, int64_t(obs.size()),
      [&](int64_t i) {
        const Observation& o = obs[i];
        const MaterialState& m = materials[o.region];
        if (!recon::HasSpecularLobe(m.params.model)) return;
        const Eigen::Vector3d wo =
            materials.LocalFrame(o.region, o.normal.cast<double>()).ToLocal(o.view.cast<double>());
        const double ax = WidenedAlpha(m.params.AlphaX(), o.lobe_blur2);
        const double ay = WidenedAlpha(m.params.AlphaY(), o.lobe_blur2);
        Eigen::Vector3d t = Eigen::Vector3d::Zero(), t0 = t;
        for (const IncidentLocal& inc : incident[i]) {
          const render::LobeWeights w =
              LobeWeight(m.params.model, ax, ay, m.params.ior, wo, inc.Wi().cast<double>());
          if (w.scale > 0) t += w.scale * inc.Value().cast<double>();
          if (w.offset > 0) t0 += w.offset * inc.Value().cast<double>();
        }
        out[i] = t;
        (*offsets)[i] = t0;
      },
      num_threads);
  return out;
}

Eigen::Vector3d DirectSpecularTerm(const render::BrdfParams& p, double blur2,
                                   const render::Frame& frame, const Eigen::Vector3d& view,
                                   const DirectSample* d, int64_t n, Eigen::Vector3d* offset) {
  const double ax = WidenedAlpha(p.AlphaX(), blur2), ay = WidenedAlpha(p.AlphaY(), blur2);
  const Eigen::Vector3d wo = frame.ToLocal(view);
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  offset->setZero();
  for (int64_t k = 0; k < n; ++k) {
    const render::LobeWeights w =
        LobeWeight(p.model, ax, ay, p.ior, wo, frame.ToLocal(d[k].wi.cast<double>()));
    if (w.scale > 0) t += w.scale * d[k].value.cast<double>();
    if (w.offset > 0) *offset += w.offset * d[k].value.cast<double>();
  }
  return t;
}

std::vector<Eigen::Vector3d> DirectSpecularTerms(const recon::Scene& scene,
                                                 const ObservationSet& obs,
                                                 const MaterialEstimate& materials,
                                                 const LightModel& light, int num_threads,
                                                 std::vector<Eigen::Vector3d>* offsets) {
  std::vector<Eigen::Vector3d> out(obs.size(), Eigen::Vector3d::Zero());
  offsets->assign(obs.size(), Eigen::Vector3d::Zero());
  ParallelFor(
      0, int64_t(obs.size()),
      [&](int64_t i) {
        const Observation& o = obs[i];
        const render::BrdfParams& p = materials[o.region].params;
        if (!recon::HasSpecularLobe(p.model)) return;
        const LightingState& st = light.lightings[scene.photos[o.photo].lighting];
        const GatherPoint& gp = st.gather.points[light.point[i]];
        out[i] = DirectSpecularTerm(
            p, o.lobe_blur2, materials.LocalFrame(o.region, o.normal.cast<double>()),
            o.view.cast<double>(), st.gather.direct.data() + gp.direct_begin,
            gp.direct_end - gp.direct_begin, &(*offsets)[i]);
      },
      num_threads);
  return out;
}

// A gather point's direct samples in the local shading frame (for the specular term), with room
// reserved for `more` samples to follow: the list is allocated once at its final size (grown by
// doubling, a glossy observation's 16 + 512 directions took 1024 slots).
std::vector<IncidentLocal> DirectIncident(const LightingState& st, const GatherPoint& gp,
                                          const render::Frame& frame, int64_t more) {
  std::vector<IncidentLocal> inc;
  inc.reserve(size_t(gp.direct_end - gp.direct_begin + more));
  for (int64_t d = gp.direct_begin; d < gp.direct_end; ++d) {
    const DirectSample& ds = st.gather.direct[d];
    inc.push_back({frame.ToLocal(ds.wi.cast<double>()).cast<float>(), ds.value});
  }
  return inc;
}

// Each patch's direct samples grouped into at most four representative directions, for the
// specular part of the radiance it sends toward other points.
void BuildPatchLobes(const PatchSet& patches, const MaterialEstimate& materials,
                     LightingState* st) {
  st->lobe_begin.assign(patches.size() + 1, 0);
  st->lobes.clear();
  for (int p = 0; p < patches.size(); ++p) {
    st->lobe_begin[p] = static_cast<int>(st->lobes.size());
    const GatherPoint& gp = st->gather.points[st->first_patch_point + p];
    const int n = int(gp.direct_end - gp.direct_begin);
    if (n > 0 && recon::HasSpecularLobe(materials[patches.patch_region[p]].params.model)) {
      const int groups = std::min(4, n);
      for (int g = 0; g < groups; ++g) {
        DirectSample rep;
        rep.value.setZero();
        Eigen::Vector3f dir = Eigen::Vector3f::Zero();
        for (int64_t k = gp.direct_begin + g * n / groups;
             k < gp.direct_begin + (g + 1) * n / groups; ++k) {
          const DirectSample& d = st->gather.direct[k];
          rep.value += d.value;
          dir += d.wi * d.value.sum();
        }
        if (!(dir.squaredNorm() > 0)) continue;
        rep.wi = dir.normalized();
        st->lobes.push_back(rep);
      }
    }
  }
  st->lobe_begin[patches.size()] = static_cast<int>(st->lobes.size());
}

namespace {

// The specular radiance patch q sends toward `toward`: its lobe over its representative direct
// samples (BuildPatchLobes).
Eigen::Vector3d PatchSpecular(const PatchSet& patches, const MaterialEstimate& materials,
                              const LightingState& st, int q, const Eigen::Vector3d& toward) {
  const int r = patches.patch_region[q];
  const MaterialState& m = materials[r];
  const bool offset = recon::Info(m.params.model).fresnel == recon::LobeFresnel::kRhoS;
  if (st.lobe_begin[q] == st.lobe_begin[q + 1] || !(offset || m.params.rho_s.maxCoeff() > 0)) {
    return Eigen::Vector3d::Zero();
  }
  const render::Frame frame = materials.LocalFrame(r, patches.normal[q].cast<double>());
  const Eigen::Vector3d wo = frame.ToLocal(toward);
  if (!(wo.z() > 0)) return Eigen::Vector3d::Zero();
  Eigen::Vector3d s = Eigen::Vector3d::Zero(), s0 = s;
  for (int k = st.lobe_begin[q]; k < st.lobe_begin[q + 1]; ++k) {
    const DirectSample& d = st.lobes[k];
    const render::LobeWeights w = LobeWeight(m.params.model, m.params.AlphaX(), m.params.AlphaY(),
                                             m.params.ior, wo, frame.ToLocal(d.wi.cast<double>()));
    s += w.scale * d.value.cast<double>();
    s0 += w.offset * d.value.cast<double>();
  }
  return s.cwiseProduct(m.params.rho_s) + s0;
}

Eigen::Vector3d PatchRadiance(const PatchSet& patches, const MaterialEstimate& materials,
                              const LightingState& st, int q, const Eigen::Vector3d& toward) {
  return st.patch_d[q].cast<double>() + PatchSpecular(patches, materials, st, q, toward);
}

// The specular radiance an indirect sample's glossy hit reflects back along the sample from its
// bounce (solver/inverse/gather.h): the lobe (ρs·scale + offset)(wo, wi)·weight times the diffuse
// radiance of the patch the bounce meets (the specular part of that radiance is left out: second
// order in the lobe).
Eigen::Vector3d BounceRadiance(const PatchSet& patches, const MaterialEstimate& materials,
                               const LightingState& st, const IndirectSample& s) {
  if (s.bounce < 0 || s.patch < 0) return Eigen::Vector3d::Zero();
  const SpecularBounce& b = st.gather.bounces[s.bounce];
  const MaterialState& m = materials[patches.patch_region[s.patch]];
  const bool offset = recon::Info(m.params.model).fresnel == recon::LobeFresnel::kRhoS;
  if (b.patch < 0 || !(offset || m.params.rho_s.maxCoeff() > 0)) return Eigen::Vector3d::Zero();
  const render::LobeWeights w = LobeWeight(m.params.model, m.params.AlphaX(), m.params.AlphaY(),
                                           m.params.ior, b.wo.cast<double>(), b.wi.cast<double>());
  if (!(w.scale > 0) && !(w.offset > 0)) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d lobe = m.params.rho_s * w.scale + Eigen::Vector3d::Constant(w.offset);
  return b.weight * lobe.cwiseProduct(st.patch_d[b.patch].cast<double>());
}

}  // namespace

Eigen::Vector3d IndirectRadiance(const PatchSet& patches, const MaterialEstimate& materials,
                                 const LightingState& st, const IndirectSample& s) {
  if (s.patch < 0) return Eigen::Vector3d::Zero();
  return PatchRadiance(patches, materials, st, s.patch, -s.wi.cast<double>()) +
         BounceRadiance(patches, materials, st, s);
}

// D_q: the diffuse radiance of each patch: the photos' mean over its observations less their
// predicted specular part; patches no photo of the lighting sees get ρd·E/π, times the diffuse
// term's mean over light and view where it is not Lambert's (render::DiffuseMeanFactor).
void UpdatePatchRadiance(const ObservationSet& obs, const PatchSet& patches,
                         const MaterialEstimate& materials, const std::vector<Eigen::Vector3d>& t,
                         const std::vector<Eigen::Vector3d>& t0, int num_threads,
                         LightingState* st) {
  std::vector<Eigen::Vector3d> sum(patches.size(), Eigen::Vector3d::Zero());
  std::vector<int> count(patches.size(), 0);
  for (int i : st->obs) {
    const Observation& o = obs[i];
    const Eigen::Vector3d spec = materials[o.region].params.rho_s.cwiseProduct(t[i]) + t0[i];
    sum[o.patch] += (o.radiance.cast<double>() - spec).cwiseMax(0.0);
    ++count[o.patch];
  }
  for (int sweep = 0; sweep < 2; ++sweep) {
    for (int q = 0; q < patches.size(); ++q) {
      if (count[q] > 0) {
        st->patch_d[q] = (sum[q] / count[q]).cast<float>();
      } else if (const render::BrdfParams& p = materials[patches.patch_region[q]].params;
                 recon::IsReflective(p.model)) {
        st->patch_d[q] =
            (materials.PatchAlbedo(patches, q).cwiseProduct(st->patch_e[q].cast<double>()) /
             render::kPi * render::DiffuseMeanFactor(p))
                .cast<float>();
      } else {
        st->patch_d[q].setZero();
      }
    }
    // Irradiance of every patch from the new radiances (for the unseen ones next sweep).
    ParallelFor(
        0, patches.size(),
        [&](int64_t q) {
          const GatherPoint& gp = st->gather.points[st->first_patch_point + q];
          Eigen::Vector3d e = gp.e_direct.cast<double>();
          for (int64_t k = gp.indirect_begin; k < gp.indirect_end; ++k) {
            const IndirectSample& s = st->gather.indirect[k];
            if (s.patch < 0) continue;
            e += s.weight * IndirectRadiance(patches, materials, *st, s);
          }
          st->patch_e[q] = e.cast<float>();
        },
        num_threads);
  }
}

void IncidentFromPatches(const ObservationSet& obs, const PatchSet& patches,
                         const MaterialEstimate& materials, int num_threads, LightModel* light) {
  const size_t n = obs.size();
  light->e_direct.resize(n);
  light->e_indirect.resize(n);
  light->incident.resize(n);
  light->incident_direct.resize(n, 0);
  for (LightingState& st : light->lightings) {
    if (!st.active) continue;
    ParallelFor(
        0, int64_t(st.obs.size()),
        [&](int64_t k) {
          const int i = st.obs[k];
          const Observation& o = obs[i];
          const GatherPoint& gp = st.gather.points[light->point[i]];
          const bool glossy = materials[o.region].KeepsIncident();
          const render::Frame frame = materials.LocalFrame(o.region, o.normal.cast<double>());
          std::vector<IncidentLocal> inc;
          if (glossy) inc = DirectIncident(st, gp, frame, gp.indirect_end - gp.indirect_begin);
          light->incident_direct[i] = int32_t(inc.size());
          Eigen::Vector3d e = Eigen::Vector3d::Zero();
          for (int64_t d = gp.indirect_begin; d < gp.indirect_end; ++d) {
            const IndirectSample& s = st.gather.indirect[d];
            if (s.patch < 0) continue;
            const Eigen::Vector3d l = IndirectRadiance(patches, materials, st, s);
            e += s.weight * l;
            if (glossy) {
              inc.push_back(
                  {frame.ToLocal(s.wi.cast<double>()).cast<float>(), (s.weight * l).cast<float>()});
            }
          }
          light->e_direct[i] = gp.e_direct.cast<double>();
          light->e_indirect[i] = e;
          light->incident[i] = std::move(inc);
        },
        num_threads);
  }
}

}  // namespace igi::solver
