#!/usr/bin/env bash
# Scale benchmark: igi-solve's (or igi-diagnose's, STAGE=diagnose, or igi-run's end to end,
# STAGE=run) wall time, CPU time and peak memory as the photos grow in size and number, and the
# recovered parameters against the truth at each size.
#
# Captures: igi-synth rooms (the default room: glossy floor with a texture, glossy and matte
# boxes, a sphere, one lamp) of N photos at M megapixels (4:3), rendered once at SPP paths per
# pixel and cached outside the repository ($IGI_SCALE_CACHE, default ~/.cache/igi-scale). Each is
# solved (or diagnosed) with default flags (--threads $THREADS), and beside it the same capture downscaled to
# 0.5 MP (oiiotool --resize, intrinsics scaled): the user's alternative to a full-size solve,
# and the peer of each row (same machine, same run).
#
# Usage: bench/scale/run_scale_bench.sh [BUILD_DIR] [-- EXTRA FLAGS of the stage's tool]
#   PHOTOS="8 30" MEGAPIXELS="0.5 3 12 24" SPP=16 THREADS=2 STAGE=solve|diagnose|run PEER=1
#   IGI_SCALE_KEEP=1
# A diagnosis's rows give its kept steps and final/baseline residual in place of the observations,
# and the errors of its improved scene's materials (solved on the analysed capture). STAGE=run
# runs `igi-run --hdr-photos` (solve, diagnose, report), scored as a diagnosis, and prints each
# stage's wall and CPU seconds. PEER=0 leaves out the downscaled peer.
# Prints one markdown table (for bench/RESULTS.md) and the growth exponents of wall time and
# peak memory in pixels per photo (at each photo count) and in photos (at each size).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build}"
[[ $# -gt 0 ]] && shift
[[ "${1:-}" == "--" ]] && shift
EXTRA=("$@")
PHOTOS="${PHOTOS:-8 30}"
MEGAPIXELS="${MEGAPIXELS:-0.5 3 12 24}"
SPP="${SPP:-16}"
THREADS="${THREADS:-2}"
STAGE="${STAGE:-solve}"
CACHE="${IGI_SCALE_CACHE:-$HOME/.cache/igi-scale}"
SYNTH="$BUILD/bin/igi-synth"
PEER="${PEER:-1}"
[[ "$STAGE" == solve || "$STAGE" == diagnose || "$STAGE" == run ]] ||
  { echo "STAGE: $STAGE: solve, diagnose or run" >&2; exit 2; }
TOOL="$BUILD/bin/igi-$STAGE"
PY=/usr/bin/python3
for t in "$SYNTH" "$TOOL"; do
  [[ -x "$t" ]] || { echo "no $t: ninja -C $BUILD igi-synth igi-$STAGE" >&2; exit 2; }
done
command -v oiiotool >/dev/null || { echo "no oiiotool (Debian openimageio-tools)" >&2; exit 2; }
WORK="$(mktemp -d "${TMPDIR:-/tmp}/igi_scale_bench.XXXXXX")"
# IGI_SCALE_KEEP=1 keeps the outputs (the folder is printed) for a look at each region.
if [[ -n "${IGI_SCALE_KEEP:-}" ]]; then echo "outputs: $WORK" >&2; else trap 'rm -rf "$WORK"' EXIT; fi
mkdir -p "$CACHE"

# Width and height of M megapixels at 4:3, even.
size_of() { $PY -c "import math,sys; m=float(sys.argv[1]); w=int(round(math.sqrt(m*1e6*4/3)/2))*2; print(w, int(round(w*3/4/2))*2)" "$1"; }

# capture N M: the cached capture's folder (rendered on first use).
capture() {
  local n=$1 mp=$2 dir="$CACHE/room_n$1_mp$2_spp$SPP"
  if [[ ! -f "$dir/truth.json" ]]; then
    read -r w h < <(size_of "$mp")
    rm -rf "$dir.tmp"
    "$SYNTH" --out "$dir.tmp" --cameras "$n" --width "$w" --height "$h" --spp "$SPP" --seed 1 \
      --threads "$THREADS" --quiet >&2
    mv "$dir.tmp" "$dir"
  fi
  echo "$dir"
}

# downscaled SRC DST MP: SRC's capture with every photo resized to MP megapixels.
downscaled() {
  local src=$1 dst=$2 mp=$3
  read -r w h < <(size_of "$mp")
  mkdir -p "$dst"
  $PY - "$src" "$dst" "$w" "$h" <<'PYEOF'
import json, os, subprocess, sys
src, dst, w, h = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
doc = json.load(open(os.path.join(src, "scene.json")))
for g in doc.get("geometry", []):
    g["file"] = os.path.join(src, g["file"])
for cam in doc["cameras"].values():
    sx, sy = w / cam["width"], h / cam["height"]
    p = cam["params"]
    p[0] *= sx; p[1] *= sy; p[2] *= sx; p[3] *= sy
    cam["width"], cam["height"] = w, h
os.makedirs(os.path.join(dst, "photos"), exist_ok=True)
for ph in doc["photos"]:
    out = os.path.join(dst, "photos", os.path.basename(ph["file"]))
    subprocess.run(["oiiotool", os.path.join(src, ph["file"]), "--resize", f"{w}x{h}", "-o", out],
                   check=True)
    ph["file"] = out
    if ph.get("mask"):
        raise SystemExit("masks are not downscaled")
json.dump(doc, open(os.path.join(dst, "scene.json"), "w"), indent=1)
PYEOF
}

# run SCENE OUT: "wall_s cpu_s peak_gib" of the stage's tool (igi-run: of its largest stage's
# process), its output in OUT.
run() {
  local scene=$1 out=$2 args
  if [[ "$STAGE" == run ]]; then args=(--hdr-photos --scene "$scene"); else args=("$scene"); fi
  /usr/bin/time -f "%e %U %S %M" -o "$out.time" \
    "$TOOL" "${args[@]}" --out "$out" --threads "$THREADS" --quiet "${EXTRA[@]}" >/dev/null 2>"$out.log" || {
    local rc=$?
    [[ $rc -eq 3 ]] || { echo "igi-$STAGE failed ($rc): $(tail -1 "$out.log")" >&2; echo "nan nan nan"; return; }
  }
  awk '{printf "%s %.1f %.2f\n", $1, $2 + $3, $4 / 1048576}' "$out.time"
}

# errors OUT TRUTH: "rho_d_max% rho_s_max% alpha_max% observations available" (a diagnosis:
# "... kept_steps final/baseline"; igi-run: its diagnosis's). A region given an albedo map whose
# truth is a texture is scored against the texture's mean over the texels the map's photos see
# (its seen_file), as its written rho_d is that map's mean over them: what the photos do not
# show of a texture is no error of the solve.
errors() {
  $PY - "$1" "$2" <<'PYEOF'
import json, os, subprocess, sys
out, truth = sys.argv[1], sys.argv[2]
if os.path.isdir(out + "/05-diagnose"):
    out += "/05-diagnose"
try:
    solved = json.load(open(out + "/scene.json"))["materials"]
    if os.path.exists(out + "/diagnosis.json"):
        d = json.load(open(out + "/diagnosis.json"))
        kept = "+".join(s["effect"] for s in d["steps"]) or "-"
        ratio = d["final"]["residual"] / d["baseline"]["residual"]
        report = {"observations": kept, "observation_draw": {"available": f"{ratio:.3f}"}}
    else:
        report = json.load(open(out + "/report.json"))
except Exception:
    print("nan nan nan nan nan"); raise SystemExit
true = json.load(open(truth))["materials"]
def stats_avg(args):
    text = subprocess.run(["oiiotool"] + args + ["--printstats"], check=True,
                          capture_output=True, text=True).stdout
    line = next(l for l in text.splitlines() if "Stats Avg:" in l)
    return [float(v) for v in line.split(":", 1)[1].replace("(float)", "").split()]
truth_scene = os.path.join(os.path.dirname(truth), json.load(open(truth)).get("scene", ""))
truth_materials = json.load(open(truth_scene))["materials"]
def seen_truth(name):
    # The true texture's mean over the map's seen texels, or None.
    tex = truth_materials.get(name, {}).get("rho_d_map")
    region = next((r for r in report.get("regions", []) if r.get("name") == name), {})
    seen = region.get("albedo_map", {}).get("seen_file")
    if not tex or not seen:
        return None
    seen = os.path.join(out, seen)
    info = subprocess.run(["oiiotool", "--info", seen], check=True, capture_output=True,
                          text=True).stdout
    w, h = (int(v) for v in info.split(":", 1)[1].split(",")[0].split(" x "))
    mask = stats_avg([seen, "--ch", "0", "--mulc", "1"])[0]
    texel = stats_avg([os.path.join(os.path.dirname(truth_scene), tex), "--resize:filter=box",
                       f"{w}x{h}", seen, "--ch", "0,0,0", "--mul"])
    return [v / mask for v in texel] if mask > 0 else None
def rel(a, b):
    a = a if isinstance(a, list) else [a] * 3
    b = b if isinstance(b, list) else [b] * 3
    return max(abs(x - y) / abs(y) for x, y in zip(a, b) if y)
worst = {"rho_d": 0.0, "rho_s": 0.0, "alpha": 0.0}
for name, t in true.items():
    s = solved.get(name, {})
    seen = seen_truth(name) if "rho_d" in s else None
    for k in worst:
        want = seen if k == "rho_d" and seen else t.get(k)
        if k in s and isinstance(want, (list, float, int)):
            worst[k] = max(worst[k], rel(s[k], want))
d = report.get("observation_draw", {})
print(f"{100*worst['rho_d']:.2f} {100*worst['rho_s']:.2f} {100*worst['alpha']:.2f} "
      f"{report['observations']} {d.get('available', 'nan')}")
PYEOF
}

echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "commit: $(git -C "$ROOT" rev-parse --short HEAD), igi-$STAGE --threads $THREADS ${EXTRA[*]}"
echo
# stages OUT: igi-run's stage markers as "stage wall s / CPU s" (nothing for the other stages).
stages() {
  $PY - "$1" <<'PYEOF'
import json, os, sys
out = sys.argv[1]
parts = []
for s in sorted(os.listdir(out)) if os.path.isdir(out) else []:
    m = os.path.join(out, s, "stage.json")
    if os.path.exists(m):
        d = json.load(open(m))
        cpu = d.get("details", {}).get("cpu_seconds")
        parts.append(f"{s} {d.get('seconds', float('nan')):.0f} s" + (f" / {cpu:.0f} CPU s" if cpu else ""))
print(", ".join(parts))
PYEOF
}

if [[ "$STAGE" == solve ]]; then
  echo "| photos | MP | run | wall s | CPU s | peak GiB | obs | available | ρd max % | ρs max % | α max % | wall / peer | peak / peer |"
else
  echo "| photos | MP | run | wall s | CPU s | peak GiB | kept steps | final / baseline | ρd max % | ρs max % | α max % | wall / peer | peak / peer |"
fi
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
ROWS="$WORK/rows.txt"
: > "$ROWS"
for n in $PHOTOS; do
  for mp in $MEGAPIXELS; do
    dir=$(capture "$n" "$mp")
    read -r fw fc fp < <(run "$dir/scene.json" "$WORK/full_n${n}_mp${mp}")
    read -r fd fs fa fo favail < <(errors "$WORK/full_n${n}_mp${mp}" "$dir/truth.json")
    [[ "$STAGE" == run ]] && echo "stages ($n photos, $mp MP): $(stages "$WORK/full_n${n}_mp${mp}")" >&2
    if [[ "$PEER" == 0 ]]; then
      echo "| $n | $mp | capture | $fw | $fc | $fp | $fo | $favail | $fd | $fs | $fa | — | — |"
      echo "$n $mp $fw $fp" >> "$ROWS"
      continue
    fi
    small="$WORK/small_n${n}_mp${mp}"
    downscaled "$dir" "$small" 0.5
    read -r sw sc sp < <(run "$small/scene.json" "$small/out")
    read -r sd ss sa so savail < <(errors "$small/out" "$dir/truth.json")
    echo "| $n | $mp | capture | $fw | $fc | $fp | $fo | $favail | $fd | $fs | $fa | $($PY -c "print(f'{$fw/$sw:.2f}')") | $($PY -c "print(f'{$fp/$sp:.2f}')") |"
    echo "| $n | $mp | peer (0.5 MP) | $sw | $sc | $sp | $so | $savail | $sd | $ss | $sa | 1 | 1 |"
    echo "$n $mp $fw $fp" >> "$ROWS"
  done
done
echo
# Growth exponents: least-squares slope of log(cost) against log(pixels per photo) per photo
# count, and against log(photos) per size.
$PY - "$ROWS" <<'PYEOF'
import math, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
rows = [(int(n), float(mp), float(w), float(p)) for n, mp, w, p in rows]
def slope(xs, ys):
    if len(xs) < 2: return float("nan")
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    den = sum((x - mx) ** 2 for x in lx)
    return sum((x - mx) * (y - my) for x, y in zip(lx, ly)) / den if den else float("nan")
for n in sorted({r[0] for r in rows}):
    sub = [r for r in rows if r[0] == n]
    print(f"photos {n}: growth in pixels per photo: wall {slope([r[1] for r in sub], [r[2] for r in sub]):.2f}, "
          f"peak memory {slope([r[1] for r in sub], [r[3] for r in sub]):.2f}")
for mp in sorted({r[1] for r in rows}):
    sub = [r for r in rows if r[1] == mp]
    print(f"{mp} MP: growth in photos: wall {slope([r[0] for r in sub], [r[2] for r in sub]):.2f}, "
          f"peak memory {slope([r[0] for r in sub], [r[3] for r in sub]):.2f}")
PYEOF
