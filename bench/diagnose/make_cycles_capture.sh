#!/usr/bin/env bash
# A concealed capture of the shared RADIANCE reference room rendered by Blender Cycles, one effect
# hidden in its photos, for igi-diagnose: the room's 4 photos (3 cameras, 2 lightings, 320x240),
# its Lambertian variant (glossy_box's 5 % lobe dropped; a material effect gives its region a
# Cycles microfacet lobe), declared without the effect.
#
# usage: bench/diagnose/make_cycles_capture.sh OUT_DIR EFFECT
#   EFFECT: as bench/diagnose/cycles_capture.py takes it ("none" for a control), e.g.
#           light_intensity:light=lamp,factor=1.3
#   env: SPP=256 SEED=1 THREADS=2   Cycles' samples per pixel, seed, threads
#        MATERIALS=given|unknown    declared with the rho_d values, or without them (solved)
#        PHOTOS="cam0_L0 cam1_L0 ..." the photos to keep (default: all 4)
#        SCALE=1                    the cameras' size (and intrinsics) times this
#        CAMERAS="NAME=X/Y/Z>TX/TY/TZ ..." more cameras (cam0's intrinsics), each at X/Y/Z
#                                   looking at TX/TY/TZ, photographed under every lighting
# A material effect's region is declared as the effect's model would leave it: diffuse for
# specular_reflection, an isotropic Ward lobe of alpha sqrt(alpha_x alpha_y) and the hidden
# rho_s for anisotropic_reflection (without rho_s and alpha with MATERIALS=unknown).
# Writes OUT_DIR/scene.json (the declared scene, photos and geometry by absolute path),
# OUT_DIR/photos/*.exr and OUT_DIR/hidden.json (the effect). Needs Debian's blender.
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
OUT="${1:?usage: make_cycles_capture.sh OUT_DIR EFFECT}"
EFFECT="${2:?usage: make_cycles_capture.sh OUT_DIR EFFECT}"
SPP="${SPP:-256}"
SEED="${SEED:-1}"
THREADS="${THREADS:-2}"
MATERIALS="${MATERIALS:-given}"
PHOTOS="${PHOTOS:-}"
SCALE="${SCALE:-1}"
CAMERAS="${CAMERAS:-}"
ROOM="${IGI_SHARED_DATA_DIR:-$ROOT/../shared/data}/reference/radiance_room"

command -v blender >/dev/null || { echo "blender not installed (apt-get install blender)"; exit 2; }
[[ "$MATERIALS" == given || "$MATERIALS" == unknown ]] ||
  { echo "MATERIALS=$MATERIALS: given or unknown"; exit 2; }
mkdir -p "$OUT/photos"
OUT="$(cd "$OUT" && pwd)"

/usr/bin/python3 - "$ROOM/scene.json" "$OUT" "$MATERIALS" "$EFFECT" "$PHOTOS" "$SCALE" \
  "$CAMERAS" <<'EOF'
import json, math, os, sys
src, out, materials, effect, keep, scale, extra = sys.argv[1:8]
scale = float(scale)
doc = json.load(open(src))


def look_at(center, target):
    """COLMAP's cam_from_world (qvec w, x, y, z; tvec) of a camera at `center` looking at
    `target` with the world's z up: rows right, down, forward."""
    f = [t - c for t, c in zip(target, center)]
    n = math.sqrt(sum(v * v for v in f))
    f = [v / n for v in f]
    r = [f[1], -f[0], 0.0]  # f x (0, 0, 1)
    n = math.sqrt(sum(v * v for v in r))
    r = [v / n for v in r]
    d = [f[1] * r[2] - f[2] * r[1], f[2] * r[0] - f[0] * r[2], f[0] * r[1] - f[1] * r[0]]
    m = [r, d, f]
    w = math.sqrt(max(0.0, 1 + m[0][0] + m[1][1] + m[2][2])) / 2
    q = [w, (m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w),
         (m[1][0] - m[0][1]) / (4 * w)]
    t = [-sum(m[i][j] * center[j] for j in range(3)) for i in range(3)]
    return q, t


first = doc["cameras"][sorted(doc["cameras"])[0]]
for item in extra.split():
    name, _, rest = item.partition("=")
    at, _, target = rest.partition(">")
    q, t = look_at([float(v) for v in at.split("/")], [float(v) for v in target.split("/")])
    doc["cameras"][name] = dict(first, qvec=q, tvec=t)
    for lighting in sorted(doc["lightings"]):
        doc["photos"].append({"file": f"photos/{name}_{lighting}.exr", "camera": name,
                              "lighting": lighting})
for cam in doc["cameras"].values():
    cam["width"], cam["height"] = round(cam["width"] * scale), round(cam["height"] * scale)
    cam["params"] = [v * scale for v in cam["params"]]
for g in doc["geometry"]:
    g["file"] = os.path.join(os.path.dirname(src), g["file"])
for name, m in doc["materials"].items():
    rho = m["rho_d"]
    doc["materials"][name] = {"brdf": "lambert", "rho_d": rho} if materials == "given" \
        else {"brdf": "lambert"}
photos = []
for p in doc["photos"]:
    stem = os.path.splitext(os.path.basename(p["file"]))[0]
    if keep and stem not in keep.split():
        continue
    photos.append({"file": os.path.join(out, "photos", stem + ".exr"), "camera": p["camera"],
                   "lighting": p["lighting"]})
doc["photos"] = photos
kind, _, rest = effect.partition(":")
params = dict(item.partition("=")[::2] for item in rest.split(",") if item)
if kind == "anisotropic_reflection":
    m = doc["materials"][params["region"]]
    m["brdf"] = "ward"
    if materials == "given":
        m["rho_s"] = float(params["rho_s"])
        m["alpha"] = math.sqrt(float(params["alpha_x"]) * float(params["alpha_y"]))
json.dump(doc, open(os.path.join(out, "scene.json"), "w"), indent=1)
# The render's own copy keeps the values (Cycles renders them) and names the photos it writes.
render = dict(doc)
render["materials"] = json.load(open(src))["materials"]  # the cameras as scaled
render["photos"] = [dict(p, file=os.path.relpath(p["file"], out)) for p in photos]
json.dump(render, open(os.path.join(out, "render_scene.json"), "w"), indent=1)
json.dump({"effect": effect, "renderer": "Blender Cycles"},
          open(os.path.join(out, "hidden.json"), "w"), indent=1)
EOF

blender -b --factory-startup -noaudio -P "$HERE/cycles_capture.py" -- \
  --scene "$OUT/render_scene.json" --out "$OUT" --effect "$EFFECT" --spp "$SPP" --seed "$SEED" \
  --threads "$THREADS" 2>&1 | grep -E "CYCLES_PHOTO|Error|error" || true
rm -f "$OUT/render_scene.json"
for p in $(/usr/bin/python3 -c "import json,sys; print(' '.join(p['file'] for p in json.load(open(sys.argv[1]))['photos']))" "$OUT/scene.json"); do
  [[ -s "$p" ]] || { echo "make_cycles_capture.sh: $p was not rendered"; exit 1; }
done
echo "capture in $OUT (hidden: $EFFECT)"
