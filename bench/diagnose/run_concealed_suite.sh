#!/usr/bin/env bash
# igi-diagnose on concealed data, full size: one igi-synth capture per hidden effect (and
# pairs, and controls), then a table of what the first kept step named, the final residual against
# the noise floor (the true model's residual at the same samples per pixel over the same pixels),
# the same on the held-out pixels (never fitted: with the materials solved, the albedo maps fit
# part of the photos' noise on the fitted pixels, so the held-out ratio is the honest one), and
# the time.
#
#   [MATERIALS=unknown|given] [SPP=256] [THREADS=2] [CAMERAS=6] [SEED=100] \
#     bench/diagnose/run_concealed_suite.sh [BUILD_DIR] [CASE...]
#
# MATERIALS=unknown (default): scene.json leaves ρd, ρs and α out and igi-diagnose solves them at
# every step (4-18 min per case on the shared 2-core machine); given: igi-synth --unknowns none,
# nothing is solved (1-4 min per case).
# A CASE is an effect (NAME or NAME:k=v,...), several joined by '+', or "none" (a control).
# Default: every effect igi-synth can hide (ambient_light both ways), two pairs and two controls.
# fresnel and specular_lobe_shape cases get a capture that can show them: the lamp 0.6 m high and
# a grazing view of the floor (igi-synth --lamp-position 2,2,0.6 --grazing-cameras 1); at the
# default views, with the materials solved, a Ward lobe refitted in ρs and α stands in for either
# (the suite's specular_lobe_shape capture then named nothing and ended at 1.07× the
# floor held out: the effect was not in the photos to find). With the materials unknown, the
# light_* and ambient_light cases photograph both lightings (--photo-lightings L0,L1: the lamp
# alone, then lamp2 alone): under one lighting, a scale of its only light is a scale of every
# solved albedo, and a soft shadow or an ambient term's shape on a surface is an albedo texture;
# no data from that lighting alone can tell them apart. Under a second lighting the albedos are the
# same and the light is not.
# The i-th case's capture has igi-synth seed SEED + i (SEED=107 none: the 8th case's capture).
# FROM=SCENE.json: instead of igi-synth's room, another renderer's capture (e.g. the shared
# RADIANCE room, ../shared/data/reference/radiance_room/scene.json) with the effects hidden in its
# photos (igi-synth --from: vignetting, exposure_scale, camera_response, pose_error; default
# cases: those four and a control).
# Output: a Markdown table on stdout; the work folders stay under
# ${IGI_BENCH_DIR:-/tmp/igi_concealed_suite}.
set -euo pipefail
BUILD="${1:-build}"
shift || true
BIN="$(cd "$BUILD/bin" && pwd)"
WORK="${IGI_BENCH_DIR:-/tmp/igi_concealed_suite}"
SPP="${SPP:-256}"
MATERIALS="${MATERIALS:-unknown}"
THREADS="${THREADS:-2}"
CAMERAS="${CAMERAS:-6}"
SEED="${SEED:-100}"
FROM="${FROM:-}"
case "$MATERIALS" in
  unknown) UNKNOWNS=() ;;
  given) UNKNOWNS=(--unknowns none) ;;
  *) echo "MATERIALS must be unknown or given" >&2; exit 2 ;;
esac
CASES=("$@")
if [ ${#CASES[@]} -eq 0 ] && [ -n "$FROM" ]; then
  CASES=(vignetting exposure_scale:photo=photos/cam1_L0.exr camera_response pose_error:camera=cam1
         none)
elif [ ${#CASES[@]} -eq 0 ]; then
  CASES=(vignetting exposure_scale camera_response ambient_light
         ambient_light:radiance=0.1 ambient_light:kind=panel light_emission_profile
         light_intensity specular_reflection specular_lobe_shape fresnel:regions=floor anisotropic_reflection
         light_source_extent pose_error missing_geometry
         vignetting+exposure_scale light_emission_profile+camera_response none none)
fi
mkdir -p "$WORK"

floor_model() {  # capture folder -> truth/true_model.json (true lights/materials + photo effects)
  python3 - "$1" <<'PY'
import json, sys, os
cap = sys.argv[1]
t = json.load(open(os.path.join(cap, "truth", "scene.json")))
d = json.load(open(os.path.join(cap, "scene.json")))
truth = json.load(open(os.path.join(cap, "truth.json")))
photos = d["photos"]
def up(f):  # relative to the capture -> relative to truth/
    return f if os.path.isabs(f) else "../" + f
for p in photos:
    p["file"] = up(p["file"])
    if isinstance(p.get("mask"), str):
        p["mask"] = up(p["mask"])
for e in truth["effects"]:
    n, q = e["effect"], e["params"]
    if n == "vignetting":
        for c in t["cameras"].values():
            c["vignetting"] = {"k1": q["k1"], "k2": q["k2"]}
    elif n == "exposure_scale":
        for p in photos:
            if p["file"] == up(q["photo"]):
                p["exposure_scale"] = q["scale"]
    elif n == "camera_response":
        for p in photos:
            p["response"] = {"exponent": q["exponent"], "reference": q["reference"]}
    elif n == "pose_error":
        pass  # truth/scene.json keeps the true poses
t["photos"] = photos
json.dump(t, open(os.path.join(cap, "truth", "true_model.json"), "w"), indent=1)
PY
}

echo "| hidden | first kept step (after maps) | all kept steps | baseline | final | floor | final/floor | held-out final/floor | wall s | CPU s |"
echo "|---|---|---|---|---|---|---|---|---|---|"
i=0
for case in "${CASES[@]}"; do
  i=$((i + 1))
  dir="$WORK/$i-$case"
  rm -rf "$dir"
  effects=()
  if [ "$case" != none ]; then
    IFS='+' read -ra names <<< "$case"
    for n in "${names[@]}"; do effects+=(--effect "$n"); done
  fi
  # fresnel shows only at grazing incidence: a low lamp and a grazing view of the floor.
  design=()
  case "$case" in
    fresnel*|specular_lobe_shape*) design=(--lamp-position 2,2,0.6 --grazing-cameras 1) ;;
    light_*|ambient_light*) if [ "$MATERIALS" = unknown ]; then design=(--photo-lightings L0,L1); fi ;;
  esac
  if [ -n "$FROM" ]; then
    "$BIN/igi-synth" --from "$FROM" --out "$dir/capture" --seed $((SEED + i)) --quiet \
        "${UNKNOWNS[@]}" "${effects[@]}" > /dev/null
  else
    "$BIN/igi-synth" --out "$dir/capture" --cameras "$CAMERAS" --width 160 --height 120 \
        --spp 64 --lamp point --seed $((SEED + i)) --threads "$THREADS" --quiet \
        "${UNKNOWNS[@]}" "${design[@]}" "${effects[@]}" > /dev/null
  fi
  start=$(date +%s)
  /usr/bin/time -f "%U %S" -o "$dir/cpu.txt" \
    "$BIN/igi-diagnose" "$dir/capture/scene.json" --out "$dir/diag" --spp "$SPP" \
      --holdout-block-px 8 --refine-iterations 0 --threads "$THREADS" --quiet || true
  end=$(date +%s)
  cpu=$(awk '{printf "%.0f", $1 + $2}' "$dir/cpu.txt" 2>/dev/null || echo "?")
  floor_model "$dir/capture"
  "$BIN/igi-diagnose" "$dir/capture/truth/true_model.json" --out "$dir/floor" --spp "$SPP" \
      --holdout-block-px 8 --max-steps 0 --threads "$THREADS" --quiet || true
  python3 - "$dir" "$case" $((end - start)) "$cpu" <<'PY'
import json, sys, os
d, case, secs, cpu = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
try:
    g = json.load(open(os.path.join(d, "diag", "diagnosis.json")))
    fb = json.load(open(os.path.join(d, "floor", "diagnosis.json")))["baseline"]
except Exception as e:
    print(f"| {case} | (failed: {e}) | | | | | | | {secs} | {cpu} |"); sys.exit(0)
f, fh = fb["residual"], fb["held_out_residual"]
kept = [s["effect"] for s in g["steps"]]
named = [k for k in kept if k != "albedo_texture"]
first = named[0] if named else "(none)"
b, fin, finh = g["baseline"]["residual"], g["final"]["residual"], g["final"]["held_out_residual"]
print(f"| {case} | {first} | {', '.join(kept) or '-'} | {b:.4f} | {fin:.4f} | {f:.4f} | {fin / f:.2f} | {finh / fh:.2f} | {secs} | {cpu} |")
PY
done
