#!/usr/bin/env bash
# The detection limits of igi-diagnose's photo effects on another renderer's capture: the shared
# RADIANCE room (../shared/data/reference/radiance_room, 4 photos) box-filtered to 160×120, each
# effect hidden at three strengths (igi-synth --from) in all 4 photos and in 3 (cam0_L1 left
# out), the materials given, diagnosed as CI does (--spp 128 --holdout-block-px 8). The control
# (nothing hidden) is diagnosed with several seeds for the false-alarm rate. Prints one row per
# run: photos, effect, strength, the first kept step (named or not), the held-out residual at the
# baseline and after, the control's held-out residual (the floor of a photo effect: the source
# scene is the true model) and the time.
#
#   [SEEDS="1 2 3 4"] bench/diagnose/run_radiance_limits.sh [BUILD_DIR]
#
# Needs oiiotool (Debian's openimageio-tools) for the box filter.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
BUILD="${1:-build}"
BIN="$(cd "$BUILD/bin" && pwd)"
SRC="$ROOT/../shared/data/reference/radiance_room"
WORK="${IGI_BENCH_DIR:-/tmp/igi_radiance_limits}"
SEEDS="${SEEDS:-1 2 3 4}"
FLAGS="--spp 128 --holdout-block-px 8 --threads 2 --quiet"
rm -rf "$WORK"
mkdir -p "$WORK"

# The half-size rooms: every photo box-filtered 2×2, the PINHOLE parameters halved; room4 keeps
# the 4 photos, room3 leaves cam0_L1 out.
half_room() {  # OUT KEEP_L1
  mkdir -p "$1/photos"
  for f in "$SRC"/photos/*.exr; do
    oiiotool "$f" --resize:filter=box 160x120 -o "$1/photos/$(basename "$f")"
  done
  /usr/bin/python3 - "$SRC/scene.json" "$1/scene.json" "$SRC" "$2" <<'EOF'
import json, sys
src, out, root, keep_l1 = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4] == "1"
d = json.load(open(src))
for g in d["geometry"]:
    g["file"] = root + "/" + g["file"]
for cam in d["cameras"].values():
    cam["width"] //= 2
    cam["height"] //= 2
    cam["params"] = [v / 2 for v in cam["params"]]
if not keep_l1:
    d["photos"] = [p for p in d["photos"] if p["lighting"] != "L1"]
json.dump(d, open(out, "w"), indent=1)
EOF
}
half_room "$WORK/room4" 1
half_room "$WORK/room3" 0

# One run: ROOM EFFECT_SPEC SEED -> "first kept step|baseline held out|final held out|seconds".
diagnose() {
  local room="$1" spec="$2" seed="$3" dir
  dir="$(mktemp -d "$WORK/run.XXXXXX")"
  local effect=()
  [ -n "$spec" ] && effect=(--effect "$spec")
  "$BIN/igi-synth" --from "$room/scene.json" --out "$dir/capture" --unknowns none --quiet \
    "${effect[@]}" >/dev/null
  local t0=$SECONDS
  "$BIN/igi-diagnose" "$dir/capture/scene.json" --out "$dir/diag" $FLAGS --seed "$seed" \
    >/dev/null || true
  local seconds=$((SECONDS - t0))
  /usr/bin/python3 - "$dir/diag/diagnosis.json" "$seconds" <<'EOF'
import json, sys
try:
    d = json.load(open(sys.argv[1]))
except OSError:
    print("failed|-|-|" + sys.argv[2]); sys.exit()
steps = [s["effect"] for s in d["steps"]]
print("%s|%.4f|%.4f|%s" % (steps[0] if steps else "-", d["baseline"]["held_out_residual"],
                           d["final"]["held_out_residual"], sys.argv[2]))
EOF
  rm -rf "$dir"
}

echo "| photos | effect | strength | first kept step | held out: baseline | final | control | s |"
echo "|---|---|---|---|---|---|---|---|"
for n in 4 3; do
  room="$WORK/room$n"
  alarms=0
  control=""
  for seed in $SEEDS; do
    IFS='|' read -r first base fin secs <<<"$(diagnose "$room" "" "$seed")"
    [ "$first" != "-" ] && alarms=$((alarms + 1))
    control="${control:-$fin}"
    echo "| $n | none (seed $seed) | - | $first | $base | $fin | $fin | $secs |"
  done
  echo "| $n | none: false alarms | - | $alarms of $(wc -w <<<"$SEEDS") | | | | |"
  while read -r effect param values extra; do
    for v in ${values//,/ }; do
      spec="$effect:$param=$v${extra:+,$extra}"
      if [ "$effect" = pose_error ]; then
        spec="$spec,translation_m=$(/usr/bin/python3 -c "print(0.02 * $v)")"
      fi
      IFS='|' read -r first base fin secs <<<"$(diagnose "$room" "$spec" 1)"
      echo "| $n | $effect | $param $v | $first | $base | $fin | $control | $secs |"
    done
  done <<'CASES'
vignetting k1 -0.05,-0.1,-0.25 k2=0
exposure_scale scale 1.05,1.1,1.3 photo=photos/cam1_L0.exr
camera_response exponent 0.95,0.9,0.8
pose_error rotation_deg 0.25,0.5,1 camera=cam1
CASES
done
