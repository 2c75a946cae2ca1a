#!/usr/bin/env bash
# A concealed capture of the shared RADIANCE reference room rendered by Blender Cycles, one effect
# hidden in its photos, for igi-diagnose: the room's 4 photos (3 cameras, 2 lightings, 320x240),
# its Lambertian variant (glossy_box's 5 % lobe dropped: cycles_scene.py renders diffuse
# materials), declared without the effect.
#
# usage: bench/diagnose/make_cycles_capture.sh OUT_DIR EFFECT
#   EFFECT: as bench/diagnose/cycles_capture.py takes it ("none" for a control), e.g.
#           light_intensity:light=lamp,factor=1.3
#   env: SPP=256 SEED=1 THREADS=2   Cycles' samples per pixel, seed, threads
#        MATERIALS=given|unknown    declared with the rho_d values, or without them (solved)
#        PHOTOS="cam0_L0 cam1_L0 ..." the photos to keep (default: all 4)
#        SCALE=1                    the cameras' size (and intrinsics) times this
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
ROOM="${IGI_SHARED_DATA_DIR:-$ROOT/../shared/data}/reference/radiance_room"

command -v blender >/dev/null || { echo "blender not installed (apt-get install blender)"; exit 2; }
[[ "$MATERIALS" == given || "$MATERIALS" == unknown ]] ||
  { echo "MATERIALS=$MATERIALS: given or unknown"; exit 2; }
mkdir -p "$OUT/photos"
OUT="$(cd "$OUT" && pwd)"

/usr/bin/python3 - "$ROOM/scene.json" "$OUT" "$MATERIALS" "$EFFECT" "$PHOTOS" "$SCALE" <<'EOF'
import json, os, sys
src, out, materials, effect, keep, scale = sys.argv[1:7]
scale = float(scale)
doc = json.load(open(src))
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
