#!/usr/bin/env bash
# Time to reach a noise level on the reference room (Lambertian variant): igi's path tracer
# against Blender Cycles (CPU), same scene, camera, resolution and thread count, same run.
#
# usage: bench/render/run_cycles_bench.sh [BUILD_DIR]      (default: build)
#   env: TARGET=0.15     relative RMS luminance noise to reach (one render)
#        THREADS=2       render threads, both sides
#        PILOT_SPP=16    first sample count; later counts follow from the measured noise
#        CAMERA=cam0 LIGHTING=L0
#        LAMP=light      Cycles' lamp: "light" = its sphere light (point light of the lamp's
#                        radius and radiance), "mesh" = an emissive ico-sphere mesh
#
# Noise: two renders with different seeds, A and B; one render's noise is
# sqrt(mean((Y_A - Y_B)^2) / 2) / mean(Y), Y the luminance (bench_image_noise). Each side starts
# at PILOT_SPP and raises spp to PILOT * (noise / TARGET)^2 * 1.1 until the noise is <= TARGET.
# Time = the render call (igi: Renderer construction + Render; Cycles: bpy render call = scene
# sync, BVH build, sampling), mean of the two seeds. The Lambertian variant is the reference
# room with glossy_box made lambert with its rho_d (its 5 % specular lobe dropped).
# Needs Debian's blender (apt-get install blender); not part of the project's dependencies.
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
BUILD="$(cd "${1:-$ROOT/build}" && pwd)"
TARGET="${TARGET:-0.15}"
THREADS="${THREADS:-2}"
PILOT_SPP="${PILOT_SPP:-16}"
CAMERA="${CAMERA:-cam0}"
LIGHTING="${LIGHTING:-L0}"
LAMP="${LAMP:-light}"
ROOM="${IGI_SHARED_DATA_DIR:-$ROOT/../shared/data}/reference/radiance_room"
NOISE="$BUILD/bench/bench_image_noise"
IGI="$BUILD/bench/bench_render_image"

command -v blender >/dev/null || { echo "blender not installed (apt-get install blender)"; exit 1; }
[[ -x "$NOISE" && -x "$IGI" ]] || { echo "build bench_image_noise and bench_render_image first"; exit 1; }

WORK="$(mktemp -d /tmp/igi_cycles_bench.XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
python3 - "$ROOM/scene.json" "$WORK/scene.json" <<'EOF'
import json, os, sys
src, dst = sys.argv[1], sys.argv[2]
doc = json.load(open(src))
for g in doc["geometry"]:
    g["file"] = os.path.join(os.path.dirname(src), g["file"])
for name, m in doc["materials"].items():
    if m["brdf"] != "lambert":
        doc["materials"][name] = {"brdf": "lambert", "rho_d": m["rho_d"]}
doc.pop("photos", None)
json.dump(doc, open(dst, "w"), indent=1)
EOF

# render SIDE SPP SEED OUT -> prints the render-call seconds
render() {
  local side=$1 spp=$2 seed=$3 out=$4
  if [[ $side == igi ]]; then
    "$IGI" "$WORK/scene.json" "$CAMERA" "$LIGHTING" "$spp" "$seed" "$THREADS" "$out" |
      awk '/IGI_RENDER_SECONDS/ {print $2}'
  else
    blender -b --factory-startup -noaudio -P "$HERE/cycles_room.py" -- --scene "$WORK/scene.json" \
      --camera "$CAMERA" --lighting "$LIGHTING" --spp "$spp" --seed "$seed" --threads "$THREADS" \
      --lamp "$LAMP" --out "$out" 2>&1 | awk '/CYCLES_RENDER_SECONDS/ {print $2}'
  fi
}

echo "target noise $TARGET, $THREADS threads, camera $CAMERA, lighting $LIGHTING, Cycles lamp $LAMP, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
printf "%-7s %7s %10s %9s %12s\n" side spp seconds noise "t@target s"
# The two sides alternate level by level, so that load from other processes hits both alike.
declare -A FINAL_T FINAL_EFF SPP DONE
SPP[igi]=$PILOT_SPP; SPP[cycles]=$PILOT_SPP; DONE[igi]=0; DONE[cycles]=0
for iter in 1 2 3 4 5 6; do
  for side in igi cycles; do
    [[ ${DONE[$side]} == 1 ]] && continue
    spp=${SPP[$side]}
    t1=$(render $side "$spp" 1 "$WORK/${side}_a.exr")
    t2=$(render $side "$spp" 2 "$WORK/${side}_b.exr")
    noise=$("$NOISE" "$WORK/${side}_a.exr" "$WORK/${side}_b.exr" | awk '{print $6}')
    t=$(awk -v a="$t1" -v b="$t2" 'BEGIN {print (a + b) / 2}')
    # Time to reach TARGET at this efficiency (noise^2 * time is constant for an unbiased MC).
    eff=$(awk -v t="$t" -v n="$noise" -v g="$TARGET" 'BEGIN {printf "%.3f", t * (n / g)^2}')
    printf "%-7s %7d %10.3f %9.4f %12s\n" "$side" "$spp" "$t" "$noise" "$eff"
    FINAL_T[$side]=$t
    FINAL_EFF[$side]=$eff
    cp "$WORK/${side}_a.exr" "$WORK/${side}_final.exr"
    if awk -v n="$noise" -v g="$TARGET" 'BEGIN {exit !(n <= g)}'; then DONE[$side]=1; fi
    SPP[$side]=$(awk -v s="$spp" -v n="$noise" -v g="$TARGET" \
      'BEGIN {x = int(s * (n / g)^2 * 1.1) + 1; if (x <= s) x = s + 1; print x}')
  done
done
echo "time to noise <= $TARGET (measured, last row of each side): igi ${FINAL_T[igi]} s, Cycles ${FINAL_T[cycles]} s," \
  "Cycles/igi = $(awk -v a="${FINAL_T[cycles]}" -v b="${FINAL_T[igi]}" 'BEGIN {printf "%.2f", a / b}')"
echo "efficiency (t * (noise/target)^2): igi ${FINAL_EFF[igi]} s, Cycles ${FINAL_EFF[cycles]} s," \
  "Cycles/igi = $(awk -v a="${FINAL_EFF[cycles]}" -v b="${FINAL_EFF[igi]}" 'BEGIN {printf "%.2f", a / b}')"
echo "same image? igi vs Cycles at their final spp: $("$NOISE" --compare "$WORK/igi_final.exr" "$WORK/cycles_final.exr")"
