#!/usr/bin/env bash
# Inverse solver benchmark: how igi-solve's time scales with photos x pixels, and the share of it
# spent casting rays, on the reference room (shared data reference/radiance_room) with every
# material value stripped (only each region's "brdf" kept). The truth of glossy_box
# (ward_gmd: rho_s 0.05, alpha 0.1, rho_d (0.2, 0.3, 0.6)) is printed beside the estimates.
#
# The peer of each run is the smallest run of the same invocation (1 photo, the largest stride):
# the table prints each run's time relative to it and the time per 1000 observations, so the
# scaling reads off the same machine in the same run.
#
# Usage: bench/solver/run_solve_bench.sh [BUILD_DIR] [-- EXTRA igi-solve FLAGS]
#   PHOTOS="1 2 3 4" STRIDES="3 2" THREADS=2 environment variables choose the grid.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build}"
[[ $# -gt 0 ]] && shift
[[ "${1:-}" == "--" ]] && shift
EXTRA=("$@")
SOLVE="$BUILD/bin/igi-solve"
DATA="${IGI_SHARED_DATA_DIR:-/work/shared/data}/reference/radiance_room"
PHOTOS="${PHOTOS:-1 2 3 4}"
STRIDES="${STRIDES:-3 2}"
THREADS="${THREADS:-2}"

[[ -x "$SOLVE" ]] || { echo "no $SOLVE: ninja -C $BUILD igi-solve" >&2; exit 2; }
[[ -f "$DATA/scene.json" ]] || { echo "no $DATA/scene.json" >&2; exit 2; }

WORK="$(mktemp -d "${TMPDIR:-/tmp}/igi_solve_bench.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

# Stripped scenes with the first N photos, absolute paths (the data folder is never written).
python3 - "$DATA" "$WORK" $PHOTOS <<'EOF'
import json, os, sys
data, work, counts = sys.argv[1], sys.argv[2], [int(n) for n in sys.argv[3:]]
doc = json.load(open(os.path.join(data, "scene.json")))
for g in doc["geometry"]:
    g["file"] = os.path.join(data, g["file"])
for light in doc["lights"].values():
    if "file" in light:
        light["file"] = os.path.join(data, light["file"])
doc["materials"] = {k: {"brdf": m["brdf"]} for k, m in doc["materials"].items()}
photos = doc["photos"]
for p in photos:
    p["file"] = os.path.join(data, p["file"])
    if p.get("mask"):
        p["mask"] = os.path.join(data, p["mask"])
for n in counts:
    d = os.path.join(work, f"photos{n}")
    os.makedirs(d, exist_ok=True)
    doc["photos"] = photos[:n]
    json.dump(doc, open(os.path.join(d, "scene.json"), "w"), indent=1)
EOF

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); igi-solve --threads $THREADS ${EXTRA[*]}"
for n in $PHOTOS; do
  for s in $STRIDES; do
    out="$WORK/out_p${n}_s${s}"
    start=$(date +%s.%N)
    rc=0
    "$SOLVE" "$WORK/photos$n/scene.json" --out "$out" --threads "$THREADS" --quiet \
      --pixel-stride "$s" "${EXTRA[@]}" 2>"$out.err" || rc=$?
    end=$(date +%s.%N)
    echo "$n $s $rc $(echo "$end - $start" | bc) $(cut -d' ' -f1 /proc/loadavg)" >>"$WORK/runs.txt"
    if [[ $rc -ne 0 && $rc -ne 3 ]]; then
      echo "photos=$n stride=$s: igi-solve exit $rc" >&2
      cat "$out.err" >&2
    fi
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$WORK" "$DATA" <<'EOF'
import json, os, sys
work, data = sys.argv[1], sys.argv[2]
truth = json.load(open(os.path.join(data, "scene.json")))["materials"]
rows = []
for line in open(os.path.join(work, "runs.txt")):
    n, s, rc, wall, load = line.split()
    rep_path = os.path.join(work, f"out_p{n}_s{s}", "report.json")
    rep = json.load(open(rep_path)) if os.path.exists(rep_path) else None
    rows.append((int(n), int(s), rc, float(wall), load, rep))
ok = [r for r in rows if r[5]]
if not ok:
    sys.exit("no run wrote report.json")
base = min(ok, key=lambda r: (r[0], -r[1]))
base_t = base[5]["timing"]["total_s"]


def f(v, digits=3):
    return "-" if v is None else f"{v:.{digits}f}"


def albedo_error(rep, stage):
    # Mean over the solved regions and channels of |rho_d - truth| / truth (region means).
    errs = []
    for r in rep["regions"]:
        fit = r[stage]
        if r["status"] == "unobserved" or not fit.get("rho_d"):
            continue
        want = truth[r["name"]]["rho_d"]
        errs += [abs(g - w) / w for g, w in zip(fit["rho_d"], want)]
    return 100 * sum(errs) / len(errs) if errs else None


def glossy(rep, stage):
    g = next(r for r in rep["regions"] if r["name"] == "glossy_box")[stage]
    if not g.get("rho_d"):
        return "-"
    return f"{f(g.get('rho_s', [None])[0])} / {f(g.get('alpha'))}"


print()
print("| photos | stride | observations | wall s | solve s | x smallest | s per 1k obs | ray share "
      "| render residual paper / refined | mean ρd error % paper / refined "
      "| glossy_box ρs / α paper (truth 0.05 / 0.1) | refined | exit | load |")
print("|" + "---|" * 14)
for n, s, rc, wall, load, rep in rows:
    if rep is None:
        print(f"| {n} | {s} | - | {wall:.1f} | - | - | - | - | - | - | - | - | {rc} | {load} |")
        continue
    t = rep["timing"]
    obs = rep["observations"]
    st = rep["stages"]
    print(f"| {n} | {s} | {obs} | {wall:.1f} | {t['total_s']:.1f} | {t['total_s'] / base_t:.2f} "
          f"| {1000 * t['total_s'] / max(obs, 1):.3f} | {t['ray_casting_share']:.2f} "
          f"| {f(st['paper']['render_residual'])} / {f(st['refined']['render_residual'])} "
          f"| {f(albedo_error(rep, 'paper'), 1)} / {f(albedo_error(rep, 'refined'), 1)} "
          f"| {glossy(rep, 'paper')} | {glossy(rep, 'refined')} | {rc} | {load} |")
EOF
