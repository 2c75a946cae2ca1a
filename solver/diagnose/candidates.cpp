#include "solver/diagnose/candidates.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "solver/diagnose/residual_fit.h"

namespace igi::diagnose {

std::vector<std::string> PhotoFiles(const recon::Scene& model) {
  std::vector<std::string> out;
  for (const recon::Photo& p : model.photos) out.push_back(p.file.filename().string());
  return out;
}

void FillScores(const ResidualFit& fit, CandidateResult* out) {
  out->train_before = fit.train_before;
  out->train_after = fit.train_after;
  out->held_before = fit.held_before;
  out->held_after = fit.held_after;
  out->z = fit.z;
}

std::vector<CandidateResult*> RankForTrials(std::vector<CandidateResult>& candidates,
                                            double min_gain, double min_z) {
  std::vector<CandidateResult*> ranked;
  for (CandidateResult& c : candidates) {
    // A fit that leaves less than nothing on the held-out pixels (a predicted gain above 100 %:
    // the fall of its residual² exceeds the residual² itself) has run away: a fit failure, not
    // a prediction.
    if (c.valid && c.held_after < 0) {
      c.valid = false;
      c.note = fmt::format(
          "a fit failure: it explains more than the residual holds (held-out residual² {:.3g} "
          "before, {:.3g} after)",
          c.held_before, c.held_after);
      continue;
    }
    if (c.valid && c.Gain() >= min_gain && c.z >= min_z) ranked.push_back(&c);
  }
  std::stable_sort(
      ranked.begin(), ranked.end(),
      [](const CandidateResult* a, const CandidateResult* b) { return a->Gain() > b->Gain(); });
  if (ranked.size() > 2 && ranked[0]->effect == ranked[1]->effect) {
    const auto other =
        std::find_if(ranked.begin() + 2, ranked.end(),
                     [&](const CandidateResult* c) { return c->effect != ranked[0]->effect; });
    if (other != ranked.end()) std::rotate(ranked.begin() + 1, other, other + 1);
  }
  return ranked;
}

std::string CandidateResult::Key() const {
  for (const char* k : {"region", "light", "camera"}) {
    if (params.contains(k) && params[k].is_string()) {
      // A kept emission profile is refitted once (its own key).
      const std::string refit = params.contains("refined_from") ? ":refit" : "";
      return effect + ":" + params[k].get<std::string>() + refit;
    }
  }
  return effect;
}

}  // namespace igi::diagnose
