#!/usr/bin/env bash
# What each stage of igi-run --demo adds to the recovered parameters (the solver's own
# tolerances, plus what HDR and registration add). From a finished demo
# folder (igi-run --demo --out DEMO), the solve is repeated three ways, each with the demo's
# options (every third pixel, no refinement rounds; bench_solve_truth):
#   registered: the demo's HDR maps and registered poses, every photo's exposure_scale the scale
#               the demo solved from the matte box (what 04-solve did);
#   true_poses: the same HDR maps with igi-synth's true cameras;
#   true_radiance: igi-synth's linear radiance (the renders before bracketing and the response)
#               with the true cameras, exposure_scale 1.
# registered − true_poses is what registration adds, true_poses − true_radiance what the
# response recovery and the HDR merge add (besides the scale, which the demo divides out with k),
# and true_radiance is the solver alone on the demo's capture.
#
#   bench/solver/run_demo_split.sh DEMO_DIR [BUILD_DIR] [WORK_DIR]
#
# Prints, per variant, each region's stage-1 row of bench_solve_truth (ρd per channel against
# truth.json's area mean, ρs, α, in %) and the written ρd against the truth over the map's seen
# texels (what demo_summary.json compares). About 1 min of 2 cores per variant.
set -euo pipefail
DEMO="$(cd "$1" && pwd)"
BUILD="$(cd "${2:-build}" && pwd)"
WORK="${3:-/tmp/igi_demo_split}"
mkdir -p "$WORK"
python3 - "$DEMO" "$WORK" <<'PY'
import copy, json, os, shutil, sys
demo, work = sys.argv[1], sys.argv[2]
reg = json.load(open(os.path.join(demo, "03-register", "scene.json")))
true_cams = json.load(open(os.path.join(demo, "00-capture", "synth", "truth", "scene.json")))["cameras"]
scale = json.load(open(os.path.join(demo, "04-solve", "report.json")))["photo_scale"]["scale"]
def absolute(p):
    return p if os.path.isabs(p) else os.path.normpath(os.path.join(demo, "03-register", p))
for variant in ("registered", "true_poses", "true_radiance"):
    d = os.path.join(work, variant)
    os.makedirs(d, exist_ok=True)
    s = copy.deepcopy(reg)
    for g in s["geometry"]:
        g["file"] = absolute(g["file"])
    for m in s["materials"].values():
        if "rho_d_map" in m:
            m["rho_d_map"] = absolute(m["rho_d_map"])
    for p in s["photos"]:
        p["file"], p["exposure_scale"] = absolute(p["file"]), scale
        if "mask" in p:
            p["mask"] = absolute(p["mask"])
    if variant != "registered":
        for name in s["cameras"]:
            s["cameras"][name] = true_cams[name.rsplit("_", 1)[0]]
    if variant == "true_radiance":
        for p in s["photos"]:
            p["file"] = os.path.join(demo, "00-capture", "synth", "truth", "radiance",
                                     p["camera"] + ".exr")
            p["exposure_scale"] = 1.0
            p.pop("mask", None)
    json.dump(s, open(os.path.join(d, "scene.json"), "w"), indent=1)
    truth = os.path.join(demo, "00-capture", "synth", "truth.json")
    shutil.copyfile(truth, os.path.join(d, "truth.json"))
    link = os.path.join(d, "truth")  # truth.json's texture paths are relative to the capture
    if os.path.lexists(link):
        os.remove(link)
    os.symlink(os.path.join(demo, "00-capture", "synth", "truth"), link)
PY
for variant in registered true_poses true_radiance; do
  echo "== $variant"
  (cd "$WORK/$variant" && "$BUILD/bench/bench_solve_truth" . stride=3 refine=0 threads=2 \
     > out.txt 2> log.txt)
  grep -E "^[a-z_0-9]+ +1 |^region " "$WORK/$variant/out.txt"
  grep -E "scene.json's rho_d [-+0-9]" "$WORK/$variant/out.txt" | sed 's/ of the truth over.*//'
done
