# A concealed capture rendered by Blender Cycles: every photo of a declared scene.json (its
# cameras and lightings) rendered with one effect hidden in it, for igi-diagnose to find on data
# another renderer made (its own light sampling, pixel filter and noise). Run headless:
#   blender -b --factory-startup -noaudio -P cycles_capture.py -- --scene DECLARED.json \
#       --out DIR --effect EFFECT --spp 256 --seed 1 --threads 2
# The scene is built as bench/render/cycles_scene.py builds it (Lambertian materials with their
# rho_d, COLMAP pinhole cameras), sphere lights as Cycles' own sphere lights (point lights with a
# radius, sampled over the sphere), rendered with Cycles' own pixel filter (Blackman-Harris,
# 1.5 px) and no denoising. Writes DIR/photos/<file>.exr
# (32-bit linear) for every photo of the scene, the files its "photos" entries name.
#
# EFFECT (docs/diagnose-effects.md names; "none" for a control):
#   light_intensity:light=NAME,factor=F       the light's radiance times F
#   light_source_extent:light=NAME,radius=R   the sphere light of radius R, the same intensity
#   light_emission_profile:light=NAME,power=N[,axis=X/Y/Z][,peak=P]
#                                             the light's emission times P·cos^N of the angle from
#                                             the axis (default straight down; P default 1: the
#                                             peak intensity the declared one)
#   missing_geometry:center=X/Y/Z,size=X/Y/Z,rho=R
#                                             a grey box the geometry lacks
#   specular_reflection:region=NAME,rho_s=S,alpha=A[,distribution=beckmann|ggx]
#                                             the region's diffuse albedo plus a microfacet lobe
#                                             (Cycles' Glossy BSDF, alpha = roughness^2)
#   anisotropic_reflection:region=NAME,rho_s=S,alpha_x=AX,alpha_y=AY[,tangent=X/Y/Z]
#                                             the same with Cycles' Anisotropic BSDF, alpha_x
#                                             along the tangent (default the world's x axis)
import json
import math
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "render"))
from cycles_scene import (add_camera, add_geometry, configure, diffuse_material,  # noqa: E402
                          glossy_material)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    args = {"spp": "256", "seed": "1", "threads": "0", "effect": "none"}
    for i in range(0, len(argv) - 1, 2):
        args[argv[i].lstrip("-")] = argv[i + 1]
    for key in ("scene", "out"):
        if key not in args:
            sys.exit(f"cycles_capture.py: missing --{key}")
    return args


def parse_effect(spec):
    name, _, rest = spec.partition(":")
    params = {}
    for item in filter(None, rest.split(",")):
        key, _, value = item.partition("=")
        params[key] = value
    return name, params


def vec(text):
    return [float(x) for x in text.split("/")]


def profile_nodes(light_data, axis, power):
    """The light's emission times max(0, d·axis)^power, d the direction it leaves in (the
    normal of a point light's shading, in its object frame: the world's, unrotated)."""
    light_data.use_nodes = True
    nodes, links = light_data.node_tree.nodes, light_data.node_tree.links
    em = next(n for n in nodes if n.type == "EMISSION")
    coords = nodes.new("ShaderNodeTexCoord")
    dot = nodes.new("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    dot.inputs[1].default_value = axis
    links.new(coords.outputs["Normal"], dot.inputs[0])
    clamp = nodes.new("ShaderNodeMath")
    clamp.operation = "MAXIMUM"
    clamp.inputs[1].default_value = 0.0
    links.new(dot.outputs["Value"], clamp.inputs[0])
    pw = nodes.new("ShaderNodeMath")
    pw.operation = "POWER"
    pw.inputs[1].default_value = power
    links.new(clamp.outputs["Value"], pw.inputs[0])
    links.new(pw.outputs["Value"], em.inputs["Strength"])


def add_lights(doc, lighting, effect, params):
    """Each sphere light of the lighting as Cycles' own sphere light (a point light of the
    sphere's radius, power 4π·intensity, intensity = radiance·π r²), the effect applied."""
    for name in doc["lightings"][lighting]:
        light = doc["lights"][name]
        if light["type"] != "sphere":
            sys.exit(f"cycles_capture.py: light {name}: only sphere lights are supported")
        rad = light["radiance"]
        rad = [rad] * 3 if isinstance(rad, (int, float)) else list(rad)
        radius = light["radius"]
        mine = params.get("light") == name
        if mine and effect == "light_intensity":
            rad = [v * float(params["factor"]) for v in rad]
        if mine and effect == "light_source_extent":
            r = float(params["radius"])
            rad = [v * (radius / r) ** 2 for v in rad]  # the same intensity, L·π r²
            radius = r
        data = bpy.data.lights.new(name, "POINT")
        peak = max(rad)
        data.color = (rad[0] / peak, rad[1] / peak, rad[2] / peak)
        data.energy = peak * 4 * math.pi * math.pi * radius * radius
        data.shadow_soft_size = radius
        if mine and effect == "light_emission_profile":
            axis = Vector(vec(params.get("axis", "0/0/-1"))).normalized()
            profile_nodes(data, tuple(axis), float(params["power"]))
            data.energy *= float(params.get("peak", "1"))
        obj = bpy.data.objects.new(name, data)
        obj.location = light["center"]
        bpy.context.scene.collection.objects.link(obj)


def add_box(params):
    center, size = vec(params["center"]), vec(params["size"])
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=center)
    obj = bpy.context.active_object
    obj.scale = size
    rho = float(params.get("rho", "0.6"))
    obj.data.materials.append(diffuse_material("missing_box", [rho] * 3))


def lobe_of(effect, params):
    """make_material for add_geometry: the effect's region with its hidden lobe."""
    if effect not in ("specular_reflection", "anisotropic_reflection"):
        return None

    def make(name, rho_d):
        if name != params["region"]:
            return None
        dist = params.get("distribution", "beckmann").upper()
        if effect == "specular_reflection":
            return glossy_material(name, rho_d, float(params["rho_s"]), float(params["alpha"]),
                                   distribution=dist)
        return glossy_material(name, rho_d, float(params["rho_s"]), float(params["alpha_x"]),
                               float(params["alpha_y"]), tuple(vec(params.get("tangent", "1/0/0"))),
                               distribution=dist)
    return make


def render_photo(doc, scene_dir, photo, effect, params, args):
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    scene = bpy.context.scene
    add_geometry(scene_dir, doc, lobe_of(effect, params))
    add_lights(doc, photo["lighting"], effect, params)
    if effect == "missing_geometry":
        add_box(params)
    w, h = add_camera(doc, photo["camera"])
    out = os.path.join(args["out"], photo["file"])
    configure(scene, w, h, dict(args, out=out))
    # Cycles' own pixel filter, not igi's box.
    scene.cycles.filter_type = "BLACKMAN_HARRIS"
    scene.cycles.filter_width = 1.5
    bpy.ops.render.render(write_still=True)
    print(f"CYCLES_PHOTO {out}", flush=True)


def main():
    args = parse_args()
    with open(args["scene"]) as f:
        doc = json.load(f)
    effect, params = parse_effect(args["effect"])
    known = ("none", "light_intensity", "light_source_extent", "light_emission_profile",
             "missing_geometry", "specular_reflection", "anisotropic_reflection")
    if effect not in known:
        sys.exit(f"cycles_capture.py: --effect {effect}: not one of {', '.join(known)}")
    scene_dir = os.path.dirname(os.path.abspath(args["scene"]))
    for photo in doc["photos"]:
        render_photo(doc, scene_dir, photo, effect, params, args)


main()
