# Blender (Cycles) scenes built from an igi scene.json, without a .blend file: the OBJ geometry as
# given (z up, metres), every material a Diffuse BSDF (roughness 0 = Lambertian) with rho_d as
# colour (a material with a specular lobe gets rho_d only, unless the caller gives it a lobe:
# glossy_material, Cycles' Beckmann or GGX microfacet lobes), sphere lights as emissive ico-spheres
# (emission strength = radiance: Cycles' emission of strength 1 is radiance 1) or Cycles' own
# sphere lights, the COLMAP pinhole camera, and the render settings of an unbiased comparison.
# Used by cycles_room.py (the time-to-noise benchmark) and bench/diagnose/cycles_capture.py
# (captures with effects hidden in them). Import it with this folder on sys.path, inside Blender.
import math
import os
import sys

import bpy
from mathutils import Matrix, Quaternion, Vector


def read_obj(path):
    """Vertices and (material, triangle) list of a simple OBJ (v, f, usemtl)."""
    verts, faces, material = [], [], None
    with open(path) as f:
        for line in f:
            tok = line.split()
            if not tok:
                continue
            if tok[0] == "v":
                verts.append(tuple(float(x) for x in tok[1:4]))
            elif tok[0] == "usemtl":
                material = tok[1]
            elif tok[0] == "f":
                idx = [int(t.split("/")[0]) - 1 for t in tok[1:]]
                for k in range(1, len(idx) - 1):
                    faces.append((material, (idx[0], idx[k], idx[k + 1])))
    return verts, faces


def diffuse_material(name, rgb):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (rgb[0], rgb[1], rgb[2], 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def glossy_material(name, rho_d, rho_s, alpha_x, alpha_y=None, tangent=(1, 0, 0),
                    distribution="BECKMANN"):
    """A Diffuse BSDF of colour rho_d plus a microfacet lobe of colour rho_s (Cycles' Glossy
    BSDF, or its Anisotropic BSDF when alpha_y differs from alpha_x, the lobe's x axis along
    `tangent` projected into the surface). Cycles' roughness r is the distribution's
    alpha = r^2; its anisotropy a in [0, 1) gives alpha_x = r^2 (1 - a), alpha_y = r^2 / (1 - a)."""
    alpha_y = alpha_x if alpha_y is None else alpha_y
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (rho_d[0], rho_d[1], rho_d[2], 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    rho_s = [rho_s] * 3 if isinstance(rho_s, (int, float)) else rho_s
    alpha0 = math.sqrt(alpha_x * alpha_y)
    if abs(alpha_x - alpha_y) <= 1e-9 * alpha0:
        lobe = nodes.new("ShaderNodeBsdfGlossy")
    else:
        lobe = nodes.new("ShaderNodeBsdfAnisotropic")
        # a >= 0 draws the lobe out along y: alpha_x <= alpha_y; otherwise along x.
        if alpha_x <= alpha_y:
            lobe.inputs["Anisotropy"].default_value = 1 - math.sqrt(alpha_x / alpha_y)
        else:
            lobe.inputs["Anisotropy"].default_value = math.sqrt(alpha_y / alpha_x) - 1
        t = nodes.new("ShaderNodeCombineXYZ")
        t.inputs[0].default_value, t.inputs[1].default_value, t.inputs[2].default_value = tangent
        links.new(t.outputs["Vector"], lobe.inputs["Tangent"])
    lobe.distribution = distribution
    lobe.inputs["Color"].default_value = (rho_s[0], rho_s[1], rho_s[2], 1.0)
    lobe.inputs["Roughness"].default_value = math.sqrt(alpha0)
    add = nodes.new("ShaderNodeAddShader")
    links.new(diffuse.outputs["BSDF"], add.inputs[0])
    links.new(lobe.outputs["BSDF"], add.inputs[1])
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(add.outputs["Shader"], out.inputs["Surface"])
    return mat


def emission_material(name, radiance):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    em = nodes.new("ShaderNodeEmission")
    peak = max(radiance)
    em.inputs["Color"].default_value = (radiance[0] / peak, radiance[1] / peak, radiance[2] / peak, 1)
    em.inputs["Strength"].default_value = peak
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(em.outputs["Emission"], out.inputs["Surface"])
    return mat


def add_geometry(scene_dir, doc, make_material=None):
    """The scene's meshes; each material from make_material(name, rho_d) when it returns one,
    else a Diffuse BSDF of its rho_d."""
    for geo in doc["geometry"]:
        verts, faces = read_obj(os.path.join(scene_dir, geo["file"]))
        names = sorted({m for m, _ in faces})
        mesh = bpy.data.meshes.new("room")
        mesh.from_pydata(verts, [], [f for _, f in faces])
        for name in names:
            rho = doc["materials"][name].get("rho_d", [0.5, 0.5, 0.5])
            rho = [rho] * 3 if isinstance(rho, (int, float)) else rho
            mat = make_material(name, rho) if make_material else None
            mesh.materials.append(mat or diffuse_material(name, rho))
        for poly, (m, _) in zip(mesh.polygons, faces):
            poly.material_index = names.index(m)
            poly.use_smooth = False
        mesh.update()
        bpy.context.scene.collection.objects.link(bpy.data.objects.new("room", mesh))


def add_sphere_lights(doc, lighting, kind):
    for name in doc["lightings"][lighting]:
        light = doc["lights"][name]
        if light["type"] != "sphere":
            sys.exit(f"cycles_room.py: light {name}: only sphere lights are supported")
        rad = light["radiance"]
        rad = [rad] * 3 if isinstance(rad, (int, float)) else rad
        if kind == "light":
            # Cycles' own sphere light: a point light of radius r. Its radiance is
            # P / (4 pi * pi r^2) for power P (Cycles: eval_fac = 1/(4 pi) * 1/(pi r^2)).
            r = light["radius"]
            data = bpy.data.lights.new(name, "POINT")
            peak = max(rad)
            data.color = (rad[0] / peak, rad[1] / peak, rad[2] / peak)
            data.energy = peak * 4 * math.pi * math.pi * r * r
            data.shadow_soft_size = r
            obj = bpy.data.objects.new(name, data)
            obj.location = light["center"]
            bpy.context.scene.collection.objects.link(obj)
            continue
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=6, radius=light["radius"],
                                              location=light["center"])
        obj = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        obj.data.materials.append(emission_material(name, rad))


def add_camera(doc, name):
    cam = doc["cameras"][name]
    if cam["model"] != "PINHOLE":
        sys.exit("cycles_room.py: only PINHOLE cameras")
    fx, fy, cx, cy = cam["params"]
    w, h = cam["width"], cam["height"]
    q = Quaternion(cam["qvec"])  # COLMAP cam_from_world (w, x, y, z)
    r_cw = q.to_matrix()
    center = -(r_cw.transposed() @ Vector(cam["tvec"]))
    # COLMAP camera axes (x right, y down, z forward) -> Blender's (x right, y up, -z forward).
    r_wb = r_cw.transposed() @ Matrix(((1, 0, 0), (0, -1, 0), (0, 0, -1)))
    data = bpy.data.cameras.new(name)
    data.sensor_fit = "HORIZONTAL"
    data.sensor_width = 36.0
    data.lens = fx * 36.0 / w
    data.shift_x = -(cx - w / 2) / w
    data.shift_y = (cy - h / 2) / w
    obj = bpy.data.objects.new(name, data)
    obj.matrix_world = Matrix.Translation(center) @ r_wb.to_4x4()
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    if abs(fx - fy) > 1e-3 * fx:
        sys.exit("cycles_room.py: non-square pixels")
    return w, h


def configure(scene, w, h, args):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = int(args["spp"])
    c.seed = int(args["seed"])
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = 64
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = 64
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    c.filter_type = "BOX"
    c.filter_width = 1.0
    c.blur_glossy = 0.0
    scene.world = bpy.data.worlds.new("black")
    scene.world.use_nodes = False
    scene.world.color = (0, 0, 0)
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "FIXED" if int(args["threads"]) > 0 else "AUTO"
    if int(args["threads"]) > 0:
        scene.render.threads = int(args["threads"])
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = args["out"]
