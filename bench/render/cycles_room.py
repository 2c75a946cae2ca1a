# Blender (Cycles) twin of the radiance_room scene, Lambertian variant, for the time-to-noise
# benchmark (bench/render/run_cycles_bench.sh). Run headless:
#   blender -b --factory-startup -P cycles_room.py -- --scene DIR/scene.json --camera cam0 \
#       --lighting L0 --spp 64 --seed 1 --threads 2 --out out.exr [--lamp mesh|light]
# It builds the scene from scene.json itself (no .blend file): the OBJ geometry as given (z up,
# metres), every material a Diffuse BSDF (roughness 0 = Lambertian) with rho_d as colour (a
# material with a specular lobe gets rho_d only: the "Lambertian variant"), each sphere light of
# the lighting as an emissive ico-sphere (emission strength = radiance: Cycles' emission of
# strength 1 is radiance 1) or, with --lamp light, as Cycles' sphere light (a point light of
# that radius and the same radiance), the COLMAP pinhole camera (square pixels, principal point at the
# centre), a box pixel filter of 1 px (the pixel mean, like igi), no denoising, no adaptive
# sampling, no clamping, bounce limits of 64, CPU. Writes a 32-bit float linear EXR and prints
# "CYCLES_RENDER_SECONDS <s>" (the render call only: scene sync, BVH build and sampling).
import json
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_scene import add_camera, add_geometry, add_sphere_lights, configure  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    args = {"camera": "cam0", "lighting": "L0", "spp": "16", "seed": "0", "threads": "0",
            "lamp": "mesh"}
    for i in range(0, len(argv) - 1, 2):
        args[argv[i].lstrip("-")] = argv[i + 1]
    for key in ("scene", "out"):
        if key not in args:
            sys.exit(f"cycles_room.py: missing --{key}")
    return args


def main():
    args = parse_args()
    with open(args["scene"]) as f:
        doc = json.load(f)
    for obj in list(bpy.data.objects):  # the factory startup's cube, lamp and camera
        bpy.data.objects.remove(obj, do_unlink=True)
    scene = bpy.context.scene
    add_geometry(os.path.dirname(os.path.abspath(args["scene"])), doc)
    add_sphere_lights(doc, args["lighting"], args["lamp"])
    w, h = add_camera(doc, args["camera"])
    configure(scene, w, h, args)
    start = time.monotonic()
    bpy.ops.render.render(write_still=True)
    print(f"CYCLES_RENDER_SECONDS {time.monotonic() - start:.4f}", flush=True)


main()
