#include "solver/diagnose/effect.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <set>
#include <tuple>

#include "solver/diagnose/residual_fit.h"
#include "tools/common/parallel.h"

namespace igi::diagnose {

void Effect::AddFits(const CandidateContext&, const RecordFits&, const KeyFilter&,
                     std::vector<CandidateTask>*) const {}

std::optional<CandidateResult> Effect::Locate(const DiagnosisModel&, const KeyFilter&) {
  return std::nullopt;
}

std::optional<CandidateResult> Effect::TryFirst(const DiagnosisModel&, int) { return std::nullopt; }

std::optional<CandidateResult> Effect::TryLast(const DiagnosisModel&) { return std::nullopt; }

TrialPlan Effect::PlanTrial(CandidateResult* c, const DiagnosisModel& m) {
  recon::SceneDocument doc(m.declared);
  Write(*c, &doc);
  return {std::move(doc).json(), m.maps, std::nullopt};
}

std::optional<Refinement> Effect::Refine(const CandidateResult&, const Json&, const recon::Scene&,
                                         const Simulation&, const DiagnosisModel&) const {
  return std::nullopt;
}

HeldOutScope Effect::Scope(const CandidateResult& c, const DiagnosisModel&) const {
  return SupportScope(c);
}

Judgement Effect::Judge(const CandidateResult& c, const HeldOutOutcome& outcome,
                        const HeldOutScope& scope, const DiagnoseOptions& o) const {
  Judgement j;
  j.gain = outcome.gain;
  j.z = outcome.z;
  j.kept = j.gain >= o.min_gain && j.z >= o.min_z;
  j.verdict =
      j.kept ? fmt::format("kept: held-out residual² down {:.1f}% ({:.1f} standard errors over {})",
                           100 * j.gain, j.z, scope.units)
             : fmt::format(
                   "rejected: held-out residual² changed by {:.1f}% ({:.1f} standard "
                   "errors): the model does not earn its {}",
                   -100 * j.gain, j.z,
                   c.num_params >= 0 ? fmt::format("{} parameter(s)", c.num_params)
                                     : std::string("albedo per texel"));
  return j;
}

void Effect::DescribeKept(CandidateResult*, const recon::Scene&) const {}

Effect* FindEffect(const std::vector<std::unique_ptr<Effect>>& effects, const std::string& name) {
  for (const auto& e : effects) {
    if (e->Name() == name) return e.get();
  }
  return nullptr;
}

std::vector<CandidateResult> EvaluateCandidates(const std::vector<std::unique_ptr<Effect>>& effects,
                                                const CandidateContext& cx,
                                                const std::vector<PixelRecord>& records,
                                                const std::vector<std::string>& excluded) {
  int num_cells = 0;
  std::vector<int> cells = RecordCells(cx.model, records, cx.cell_m, &num_cells);
  const ResidualFitter f(records, std::move(cells), num_cells, cx.materials_solved, cx.block_px);
  // The searches' subsample (none when the records are few).
  std::unique_ptr<RecordSubset> search;
  if (const int stride = SearchStride(records, cx.search_records); stride > 1) {
    search = std::make_unique<RecordSubset>(cx.model, records, cx.cell_m, cx.materials_solved,
                                            cx.block_px, stride);
  }
  const KeyFilter allowed = [&](const std::string& key) {
    return std::find(excluded.begin(), excluded.end(), key) == excluded.end();
  };
  const RecordFits fits{f, search.get()};
  std::vector<CandidateTask> tasks;
  for (const auto& e : effects) e->AddFits(cx, fits, allowed, &tasks);
  std::vector<CandidateResult> results(tasks.size());
  ParallelFor(0, int64_t(tasks.size()), [&](int64_t i) {
    const auto start = std::chrono::steady_clock::now();
    results[size_t(i)] = tasks[size_t(i)].run();
    const CandidateResult& c = results[size_t(i)];
    spdlog::debug("igi-diagnose: candidate {} evaluated in {:.1f} s: {}", c.Key(),
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                  c.valid ? fmt::format("predicted held-out gain {:.2f}%, z {:.1f}, {}",
                                        100 * c.Gain(), c.z, c.params.dump())
                          : "not valid" + (c.note.empty() ? std::string() : ": " + c.note));
  });
  std::vector<CandidateResult> out;
  for (size_t i = 0; i < tasks.size(); ++i) {
    CandidateResult& c = results[i];
    if (tasks[i].drop_empty && !c.valid && c.note.empty()) continue;
    out.push_back(std::move(c));
  }
  return out;
}

namespace {

// The blocks of `blocks` (photo, block x, block y).
BlockFilter BlockSetFilter(std::set<std::tuple<size_t, int, int>> blocks) {
  auto set = std::make_shared<const std::set<std::tuple<size_t, int, int>>>(std::move(blocks));
  return [set](size_t photo, int bx, int by) { return set->count({photo, bx, by}) > 0; };
}

}  // namespace

HeldOutScope SupportScope(const CandidateResult& c) {
  HeldOutScope scope;
  if (c.support_blocks.size() < 2) return scope;
  std::set<std::tuple<size_t, int, int>> blocks;
  for (const auto& b : c.support_blocks) blocks.insert({size_t(b[0]), b[1], b[2]});
  scope.blocks = BlockSetFilter(std::move(blocks));
  scope.units =
      fmt::format("the {} held-out blocks where it changes the model", c.support_blocks.size());
  return scope;
}

HeldOutScope RegionScope(const CandidateResult& c, const DiagnosisModel& m) {
  HeldOutScope support = SupportScope(c);
  if (support.blocks || !c.params.contains("region") || !c.params["region"].is_string()) {
    return support;
  }
  const int index = m.model.FindMaterial(c.params["region"].get<std::string>());  // -1: no block
  std::set<std::tuple<size_t, int, int>> blocks;
  const int block_px = m.holdout.block_px;
  for (const PixelRecord& r : m.records) {
    if (r.region == index && r.held_out) {
      blocks.insert({size_t(r.photo), r.x / block_px, r.y / block_px});
    }
  }
  HeldOutScope scope;
  scope.blocks = BlockSetFilter(std::move(blocks));
  return scope;
}

}  // namespace igi::diagnose
