// igi-synth: writes a synthetic capture with known truth (docs/file-formats.md, truth.json): a
// room scene folder (scene.json, geometry, photos, optional LDR brackets) plus truth.json, with
// optional effects that the photos show and scene.json does not declare.
#include <cstdio>

#include "solver/synth/synth_flags.h"
#include "solver/synth/synthesize.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

int main(int argc, char** argv) {
  CLI::App app{"Write a synthetic room capture with known truth (scene.json, photos, truth.json)",
               "igi-synth"};
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags, /*computes=*/true);
  igi::synth::SynthFlags f;
  igi::synth::AddSynthFlags(app, &f);
  return igi::RunMain(app, flags, argc, argv, [&] {
    const igi::synth::SynthOptions o = igi::synth::FinishSynthFlags(f, flags.threads);
    const igi::synth::SynthSummary s = igi::synth::Synthesize(o);
    std::printf("wrote %s: %zu photos, %zu validation renders, %lld saturated pixels, %.1f s\n",
                o.out.c_str(), s.photos.size(), s.validation.size(),
                static_cast<long long>(s.saturated_pixels), s.seconds);
    return 0;
  });
}
