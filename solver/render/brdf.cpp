#include "solver/render/brdf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace igi::render {
namespace {

void CheckRgb(const Eigen::Vector3d& rho, const std::string& key,
              std::vector<BrdfParamProblem>* problems) {
  for (int c = 0; c < 3; ++c) {
    if (!(std::isfinite(rho[c]) && rho[c] >= 0.0)) {
      problems->push_back({key + "[" + std::to_string(c) + "]", rho[c], "must be finite and >= 0"});
    }
  }
}

void CheckAlpha(double alpha, const char* key, std::vector<BrdfParamProblem>* problems) {
  if (!(std::isfinite(alpha) && alpha > 0.0)) {
    problems->push_back({key, alpha, "must be finite and > 0"});
  }
}

double Mean(const Eigen::Vector3d& v) { return (v[0] + v[1] + v[2]) / 3.0; }

}  // namespace

std::vector<BrdfParamProblem> CheckBrdfParams(const BrdfParams& params) {
  std::vector<BrdfParamProblem> problems;
  CheckRgb(params.rho_d, "rho_d", &problems);
  if (recon::HasSigma(params.diffuse) && !(std::isfinite(params.sigma) && params.sigma >= 0.0)) {
    problems.push_back({"sigma", params.sigma, "must be finite and >= 0"});
  }
  if (recon::HasSpecularLobe(params.model)) {
    CheckRgb(params.rho_s, "rho_s", &problems);
    if (recon::IsAnisotropic(params.model)) {
      CheckAlpha(params.alpha_x, "alpha_x", &problems);
      CheckAlpha(params.alpha_y, "alpha_y", &problems);
    } else {
      CheckAlpha(params.alpha, "alpha", &problems);
    }
    if (recon::HasFresnel(params.model) && !(std::isfinite(params.ior) && params.ior > 1.0)) {
      problems.push_back({"ior", params.ior, "must be finite and > 1"});
    }
    if (recon::Info(params.model).fresnel == recon::LobeFresnel::kRhoS) {
      for (int c = 0; c < 3; ++c) {
        if (params.rho_s[c] > 1.0) {
          problems.push_back({"rho_s[" + std::to_string(c) + "]", params.rho_s[c],
                              "must be <= 1 (it is F0, the reflectance at normal incidence)"});
        }
      }
    }
  }
  return problems;
}

double OrenNayarMeanG(double cos_o) {
  // A table over θo in 1° steps of a 256 × 256 midpoint quadrature of the cosine-weighted
  // hemisphere (cosθi = √(1 − u), φ = 2πv), interpolated linearly.
  static const std::vector<double> table = [] {
    std::vector<double> t(91);
    constexpr int kN = 256;
    for (int d = 0; d <= 90; ++d) {
      const double theta = std::min(double(d), 89.9) * kPi / 180;
      const Eigen::Vector3d wo(std::sin(theta), 0, std::cos(theta));
      double sum = 0;
      for (int i = 0; i < kN; ++i) {
        for (int j = 0; j < kN; ++j) {
          const double u = (i + 0.5) / kN, phi = 2 * kPi * (j + 0.5) / kN;
          const double r = std::sqrt(u);
          const Eigen::Vector3d wi(r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - u));
          sum += OrenNayarG<double>(wo, wi);
        }
      }
      t[d] = sum / (kN * kN);
    }
    return t;
  }();
  const double deg = std::acos(std::clamp(cos_o, 0.0, 1.0)) * 180 / kPi;
  const int i = std::min(89, int(deg));
  const double w = deg - i;
  return (1 - w) * table[i] + w * table[i + 1];
}

double DiffuseMeanFactor(const BrdfParams& params) {
  switch (params.diffuse) {
    case recon::DiffuseShape::kOrenNayar: {
      // OrenNayarMeanG's mean over the cosine-weighted view (2c dc), by the midpoint rule.
      static const double mean_g = [] {
        constexpr int kN = 512;
        double sum = 0;
        for (int i = 0; i < kN; ++i) {
          const double c = (i + 0.5) / kN;
          sum += OrenNayarMeanG(c) * 2 * c / kN;
        }
        return sum;
      }();
      return OrenNayarA(params.sigma) + OrenNayarB(params.sigma) * mean_g;
    }
    case recon::DiffuseShape::kCoated:
      return kMeanCoatTransmission * kMeanCoatTransmission;  // on both sides
    case recon::DiffuseShape::kLambert:
      break;
  }
  return 1.0;
}

double SpecularLobeProbability(const BrdfParams& params, const Eigen::Vector3d& wo) {
  if (!recon::HasSpecularLobe(params.model)) return 0.0;
  const double diffuse = Mean(params.rho_d);
  double specular = Mean(params.rho_s);
  if (recon::Info(params.model).fresnel == recon::LobeFresnel::kRhoS) {
    const double m = std::pow(1.0 - std::clamp(wo.z(), 0.0, 1.0), 5);
    specular = specular * (1.0 - m) + m;
  }
  const double total = diffuse + specular;
  return total > 0.0 ? specular / total : 0.0;
}

namespace brdf_internal {

BrdfEval EvalGlossyBrdfAndPdf(const BrdfParams& params, const Eigen::Vector3d& wo,
                              const Eigen::Vector3d& wi) {
  BrdfEval out;
  if (!(wo.z() > 0.0)) return out;
  const bool above = wi.z() > 0.0;
  const double p_specular = SpecularLobeProbability(params, wo);
  if (above) out.f = params.rho_d * (kInvPi * DiffuseFactor(params, wo, wi));
  out.pdf = (1.0 - p_specular) * CosineHemispherePdf(wi.z());

  const double ax = params.AlphaX();
  const double ay = params.AlphaY();
  const Eigen::Vector3d h = wo + wi;
  if (!(h.z() > 0.0)) return out;  // no half vector of the upper hemisphere maps here
  if (recon::IsMicrofacet(params.model)) {
    out.pdf += p_specular * microfacet::ReflectedPdf(recon::Lobe(params.model), ax, ay, wo, h);
    if (above) {
      const LobeWeights w = SpecularWeights<double>(params.model, ax, ay, params.ior, wo, wi);
      out.f += params.rho_s * w.scale + Eigen::Vector3d::Constant(w.offset);
    }
    return out;
  }
  // Ward's lobes, sharing the unnormalised half vector and the Gaussian of its slopes between f
  // and pdf.
  const double hz2 = h.z() * h.z();
  const double slope_x = h.x() / ax;
  const double slope_y = h.y() / ay;
  const double lobe = std::exp(-(slope_x * slope_x + slope_y * slope_y) / hz2);
  const double h2 = h.squaredNorm();
  // Half-vector density lobe/(π αx αy cos³θh) times the Jacobian 1/(4 wo·ĥ), with
  // cosθh = h.z/|h| and wo·ĥ = |h|/2 (since |wo + wi|² = 2 + 2 wo·wi).
  out.pdf += p_specular * lobe * h2 / (2.0 * kPi * ax * ay * hz2 * h.z());
  if (above) {
    double s = recon::IsGmd(params.model)
                   ? h2 * lobe / (kPi * ax * ay * hz2 * hz2)
                   : lobe / (4.0 * kPi * ax * ay * std::sqrt(wo.z() * wi.z()));
    if (recon::HasFresnel(params.model)) s *= FresnelWeight<double>(params.ior, wo, wi);
    out.f += params.rho_s * s;
  }
  return out;
}

BrdfSample SampleGlossyBrdf(const BrdfParams& params, const Eigen::Vector3d& wo, double u_lobe,
                            const Eigen::Vector2d& u) {
  BrdfSample sample;
  if (!(wo.z() > 0.0)) return sample;
  if (u_lobe < SpecularLobeProbability(params, wo)) {
    sample.lobe = BrdfLobe::kSpecular;
    // Ward's lobes draw as Beckmann's microfacets do (Gaussian slopes).
    const recon::LobeShape shape = recon::Lobe(params.model) == recon::LobeShape::kGgx
                                       ? recon::LobeShape::kGgx
                                       : recon::LobeShape::kBeckmann;
    const Eigen::Vector3d h =
        microfacet::SampleHalfVector(shape, params.AlphaX(), params.AlphaY(), wo, u);
    const double wo_dot_h = wo.dot(h);
    if (!(wo_dot_h > 0.0)) return sample;  // wo would mirror to the back of h: a failed draw
    sample.wi = (2.0 * wo_dot_h * h - wo).normalized();
  } else {
    sample.lobe = BrdfLobe::kDiffuse;
    sample.wi = SampleCosineHemisphere(u);
  }
  const BrdfEval eval = EvalGlossyBrdfAndPdf(params, wo, sample.wi);
  sample.f = eval.f;
  sample.pdf = eval.pdf;
  if (sample.Valid()) sample.weight = sample.f * (sample.wi.z() / sample.pdf);
  return sample;
}

}  // namespace brdf_internal

double BrdfPdf(const BrdfParams& params, const Eigen::Vector3d& wo, const Eigen::Vector3d& wi) {
  return EvalBrdfAndPdf(params, wo, wi).pdf;
}

}  // namespace igi::render
