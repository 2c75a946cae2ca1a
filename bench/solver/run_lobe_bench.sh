#!/usr/bin/env bash
# The cost of a microfacet lobe in igi-solve: the igi-synth room (every material value unknown)
# rendered twice from the same seed, cameras and paths, once with Ward lobes on its glossy
# regions and once with another model's (default ggx), each solved REPS times, the two alternating
# so that load from other processes hits both alike. The peer is the Ward solve: the table gives
# the median solve time (report.json's timing.total_s) of each, their ratio, and each glossy
# region's rho_s and alpha error against the capture's truth.
#
# Usage: bench/solver/run_lobe_bench.sh [BUILD_DIR]
#   MODEL=ggx REPS=3 SPP=256 THREADS=2 environment variables; extra igi-solve flags in SOLVE_ARGS.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build}"
MODEL="${MODEL:-ggx}"
REPS="${REPS:-3}"
SPP="${SPP:-256}"
THREADS="${THREADS:-2}"
read -r -a SOLVE_ARGS <<< "${SOLVE_ARGS:-}"
for tool in igi-synth igi-solve; do
  [[ -x "$BUILD/bin/$tool" ]] || { echo "no $BUILD/bin/$tool: ninja -C $BUILD $tool" >&2; exit 2; }
done

WORK="$(mktemp -d "${TMPDIR:-/tmp}/igi_lobe_bench.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

for m in ward "$MODEL"; do
  "$BUILD/bin/igi-synth" --out "$WORK/$m" --glossy-brdf "$m" --spp "$SPP" --threads "$THREADS" \
    --unknowns rho_d,rho_s,alpha --quiet
done
for rep in $(seq 1 "$REPS"); do
  for m in ward "$MODEL"; do
    "$BUILD/bin/igi-solve" "$WORK/$m/scene.json" --out "$WORK/$m/solved$rep" --threads "$THREADS" \
      --quiet "${SOLVE_ARGS[@]}"
  done
done

/usr/bin/python3 - "$WORK" "$MODEL" "$REPS" <<'EOF'
import json, statistics, sys
work, model, reps = sys.argv[1], sys.argv[2], int(sys.argv[3])
rows = {}
for m in ("ward", model):
    times = [json.load(open(f"{work}/{m}/solved{r}/report.json"))["timing"]["total_s"]
             for r in range(1, reps + 1)]
    report = json.load(open(f"{work}/{m}/solved1/report.json"))
    truth = json.load(open(f"{work}/{m}/truth.json"))["materials"]
    errors = []
    for region in report["regions"]:
        t = truth[region["name"]]
        if "rho_s" not in t:
            continue
        fit = region.get("refined") or region["paper"]
        rho_s = sum(fit["rho_s"]) / 3
        errors.append(f"{region['name']} {100 * (rho_s / t['rho_s'] - 1):+.1f}/"
                      f"{100 * (fit['alpha'] / t['alpha'] - 1):+.1f}")
    rows[m] = (statistics.median(times), times, errors)
ward = rows["ward"][0]
print(f"| model | median solve s | runs | / ward | rho_s / alpha error % (glossy regions) |")
print("|---|---|---|---|---|")
for m, (med, times, errors) in rows.items():
    print(f"| {m} | {med:.1f} | {' '.join(f'{t:.1f}' for t in times)} | {med / ward:.2f} | "
          f"{'; '.join(errors)} |")
EOF
