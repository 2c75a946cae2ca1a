#!/usr/bin/env bash
# igi-diagnose on captures another renderer made: the shared RADIANCE room's photos rendered by
# Blender Cycles with one light or geometry effect hidden in each (make_cycles_capture.sh), and a
# control. Prints a table: the first kept step after any albedo_texture step, every kept step,
# the baseline and final held-out residuals, the true model's held-out residual (the declared
# scene with the hidden effect written in igi's terms, diagnosed with no step) and their ratio,
# and the time.
#
#   [MATERIALS=given|unknown] [CYCLES_SPP=128] [SPP=32] [SPP_MAX=0] [THREADS=2] \
#     bench/diagnose/run_cycles_suite.sh [BUILD_DIR] [CASE...]
#
# A CASE is an EFFECT of cycles_capture.py (NAME:k=v,...) or "none". Captures are cached under
# ${IGI_BENCH_DIR:-/tmp/igi_cycles_suite}/captures (delete them to render again). SPP and SPP_MAX
# are igi-diagnose's --spp and --spp-max.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
BUILD="${1:-build}"
shift || true
BIN="$(cd "$BUILD/bin" && pwd)"
WORK="${IGI_BENCH_DIR:-/tmp/igi_cycles_suite}"
MATERIALS="${MATERIALS:-given}"
CYCLES_SPP="${CYCLES_SPP:-128}"
SPP="${SPP:-32}"
SPP_MAX="${SPP_MAX:-0}"
THREADS="${THREADS:-2}"
CASES=("$@")
if [ ${#CASES[@]} -eq 0 ]; then
  CASES=(light_intensity:light=lamp,factor=1.3 light_emission_profile:light=lamp,power=1,peak=2
         light_source_extent:light=lamp,radius=0.3 none)
fi

# The declared scene with the hidden effect written in igi's terms: the true model.
true_model() {  # capture_dir effect -> capture_dir/true_model.json
  /usr/bin/python3 - "$1" "$2" <<'PY'
import json, math, os, sys
cap, spec = sys.argv[1], sys.argv[2]
doc = json.load(open(os.path.join(cap, "scene.json")))
name, _, rest = spec.partition(":")
q = dict(kv.split("=", 1) for kv in rest.split(",") if kv)
if name in ("light_intensity", "light_source_extent", "light_emission_profile"):
    l = doc["lights"][q["light"]]
    r, rad = l["radius"], l["radiance"]
    if name == "light_intensity":
        l["radiance"] = [v * float(q["factor"]) for v in rad]
    elif name == "light_source_extent":
        r2 = float(q["radius"])
        l["radius"], l["radiance"] = r2, [v * (r / r2) ** 2 for v in rad]
    else:
        axis = [float(x) for x in q.get("axis", "0/0/-1").split("/")]
        doc["lights"][q["light"]] = {
            "type": "spot", "position": l["center"], "direction": axis,
            "intensity": [v * math.pi * r * r * float(q.get("peak", "1")) for v in rad],
            "profile": {"cos_power": float(q["power"])}}
elif name != "none":
    sys.exit(2)  # no true model in igi's terms (missing_geometry)
json.dump(doc, open(os.path.join(cap, "true_model.json"), "w"), indent=1)
PY
}

echo "| hidden (Cycles, $CYCLES_SPP spp) | first kept step (after maps) | all kept steps | baseline held out | final held out | true model held out | final/true | render paths | wall s |"
echo "|---|---|---|---|---|---|---|---|---|"
for case in "${CASES[@]}"; do
  key="$(echo "$case" | tr ':,=/' '_-__')"
  cap="$WORK/captures/$MATERIALS-$CYCLES_SPP-$key"
  if [ ! -s "$cap/scene.json" ]; then
    SPP="$CYCLES_SPP" THREADS="$THREADS" MATERIALS="$MATERIALS" \
      "$HERE/make_cycles_capture.sh" "$cap" "$case" > "$WORK/make-$key.log" 2>&1
  fi
  dir="$WORK/runs/$MATERIALS-$SPP-$SPP_MAX-$key"
  rm -rf "$dir"
  mkdir -p "$dir"
  start=$(date +%s)
  "$BIN/igi-diagnose" "$cap/scene.json" --out "$dir/diag" --spp "$SPP" --spp-max "$SPP_MAX" \
    --threads "$THREADS" --quiet > "$dir/diag.log" 2>&1 || true
  end=$(date +%s)
  truth="-"
  if true_model "$cap" "$case" 2> /dev/null; then
    "$BIN/igi-diagnose" "$cap/true_model.json" --out "$dir/true" --spp "$SPP" \
      --spp-max "$SPP_MAX" --max-steps 0 --threads "$THREADS" --quiet > /dev/null 2>&1 || true
    truth="$dir/true/diagnosis.json"
  fi
  /usr/bin/python3 - "$dir/diag/diagnosis.json" "$truth" "$case" $((end - start)) <<'PY'
import json, sys
path, truth, case, secs = sys.argv[1:5]
try:
    g = json.load(open(path))
except Exception as e:
    print(f"| {case} | (failed: {e}) | | | | | | | {secs} |"); sys.exit(0)
kept = [s["effect"] for s in g["steps"]]
named = [k for k in kept if k != "albedo_texture"]
t = json.load(open(truth))["baseline"]["held_out_residual"] if truth != "-" else None
b, f = g["baseline"]["held_out_residual"], g["final"]["held_out_residual"]
spp = g.get("render_noise", {}).get("spp", "")
print(f"| {case} | {named[0] if named else '(none)'} | {', '.join(kept) or '-'} | {b:.4f} | {f:.4f} | "
      f"{'%.4f' % t if t else '-'} | {'%.2f' % (f / t) if t else '-'} | {spp} | {secs} |")
PY
done
