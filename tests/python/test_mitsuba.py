"""igi.mitsuba: the load_dict dictionary of a scene's lighting — sensors whose rays are the
cameras', one shape and BSDF per region, the lights' emitters — and every element, property and
value of igi-export's Mitsuba XML in it."""

import importlib.util
import json
import math
import os
import subprocess
import types
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import igi
from igi import mitsuba


@pytest.fixture(scope="module")
def scene(scenes):
    return igi.Scene.load(scenes / "render" / "complete.json")


@pytest.fixture(scope="module")
def dicts(scene, tmp_path_factory):
    out = tmp_path_factory.mktemp("mitsuba_dict")
    return {lighting: mitsuba.scene_dict(scene, lighting, out) for lighting in scene.lightings}


def mitsuba_ray(sensor, u, v):
    """The world direction of film position (u, v) in pixels by Mitsuba's perspective sensor
    (fov along x, principal point at the centre): in camera space (x left, y up, z forward)
    x/z = tan(fov/2)·(1 − 2u/W), y/z = tan(fov/2)·(1 − 2v/H)·H/W; to_world turns it."""
    w, h = sensor["film"]["width"], sensor["film"]["height"]
    t = math.tan(math.radians(sensor["fov"]) / 2)
    d_cam = np.array([t * (1 - 2 * u / w), t * (1 - 2 * v / h) * h / w, 1.0])
    m = np.array(sensor["to_world"]["matrix"])
    d = m[:3, :3] @ d_cam
    return m[:3, 3], d / np.linalg.norm(d)


def test_structure_and_sensors(scene, dicts):
    d = dicts["L0"]
    assert d["type"] == "scene"
    assert d["integrator"] == {"type": "path", "max_depth": -1}
    sensors = {k: v for k, v in d.items() if isinstance(v, dict) and v.get("type") == "perspective"}
    assert sorted(sensors) == sorted(scene.cameras)
    for name, camera in scene.cameras.items():
        s = sensors[name]
        assert s["fov_axis"] == "x"
        fx = camera.K[0, 0]
        assert s["fov"] == pytest.approx(math.degrees(2 * math.atan(camera.width / (2 * fx))),
                                         rel=1e-12)
        assert (s["film"]["width"], s["film"]["height"]) == (camera.width, camera.height)
        assert s["to_world"]["type"] == "transform"
        m = np.array(s["to_world"]["matrix"])
        np.testing.assert_allclose(m[3], [0, 0, 0, 1])
        np.testing.assert_allclose(m[:3, 3], camera.center, atol=1e-12)
    # cam0 is a pinhole with its principal point at the centre: every pixel's ray is the
    # camera's. (cam1's distortion is dropped by the export: only its central ray agrees.)
    cam0 = scene.cameras["cam0"]
    pixels = np.array([[0.5, 0.5], [7.5, 0.5], [4.0, 3.0], [2.25, 5.5], [7.5, 5.5]])
    origin, directions = cam0.rays(pixels)
    for (u, v), want in zip(pixels, directions):
        o, got = mitsuba_ray(sensors["cam0"], u, v)
        np.testing.assert_allclose(o, origin, atol=1e-12)
        np.testing.assert_allclose(got, want, atol=1e-12)
    cam1 = scene.cameras["cam1"]
    origin, directions = cam1.rays(np.array([[4.0, 3.0]]))
    np.testing.assert_allclose(mitsuba_ray(sensors["cam1"], 4.0, 3.0)[1], directions[0],
                               atol=1e-12)


def test_one_shape_per_region_with_its_material(scene, dicts):
    d = dicts["L0"]
    materials = scene.materials
    shapes = [k for k, v in d.items() if isinstance(v, dict) and v.get("type") == "obj"]
    assert sorted(shapes) == sorted(materials)
    for region, m in materials.items():
        shape = d[region]
        assert os.path.isabs(shape["filename"]) and os.path.isfile(shape["filename"])
        assert shape["bsdf"] == {"type": "ref", "id": "bsdf." + region}
        twosided = d["bsdf." + region]
        assert twosided["type"] == "twosided"
        inner = twosided["bsdf"]
        if m["brdf"] == "lambert":
            rho_d = np.broadcast_to(np.asarray(m["rho_d"], float), 3)
            assert inner == {"type": "diffuse",
                             "reflectance": {"type": "rgb", "value": rho_d.tolist()}}
            continue
        # A lobe: roughplastic, Beckmann for Ward's lobes, int_ior from mean ρs (its F0).
        assert inner["type"] == "roughplastic" and inner["distribution"] == "beckmann"
        eta = inner["int_ior"]
        f0 = np.mean(np.broadcast_to(np.asarray(m["rho_s"], float), 3))
        assert ((eta - 1) / (eta + 1)) ** 2 == pytest.approx(f0, rel=1e-12)
        assert 0 < inner["alpha"] < 0.5
        if "rho_d_map" in m:
            texture = inner["diffuse_reflectance"]
            assert texture["type"] == "bitmap" and texture["raw"] is True
            assert os.path.isfile(texture["filename"])
        else:
            assert inner["diffuse_reflectance"]["value"] == list(m["rho_d"])


def test_emitters_match_the_lights(scene, dicts):
    lights = scene.lights
    lamp = dicts["L0"]["lamp"]
    assert lamp == {"type": "point", "position": lights["lamp"]["position"],
                    "intensity": {"type": "rgb", "value": lights["lamp"]["intensity"]}}
    spot = dicts["L1"]["spot"]
    assert spot["type"] == "spot"
    assert spot["intensity"]["value"] == lights["spot"]["intensity"]
    m = np.array(spot["to_world"]["matrix"])
    axis = np.array(lights["spot"]["direction"], float)
    np.testing.assert_allclose(m[:3, 2], axis / np.linalg.norm(axis), atol=1e-12)
    np.testing.assert_allclose(m[:3, 3], lights["spot"]["position"], atol=1e-12)
    panel = dicts["L1"]["panel"]
    assert panel["type"] == "obj" and os.path.isfile(panel["filename"])
    assert panel["emitter"] == {"type": "area",
                                "radiance": {"type": "rgb", "value": lights["panel"]["radiance"]}}
    d2 = dicts["L2"]
    sun = np.array(lights["sun"]["direction"], float)
    np.testing.assert_allclose(d2["sun"]["direction"], sun / np.linalg.norm(sun), atol=1e-12)
    assert d2["sun"]["irradiance"]["value"] == lights["sun"]["irradiance"]
    assert d2["bulb"]["type"] == "sphere" and d2["bulb"]["radius"] == lights["bulb"]["radius"]
    assert d2["bulb"]["center"] == lights["bulb"]["center"]
    assert d2["bulb"]["emitter"]["radiance"]["value"] == lights["bulb"]["radiance"]
    cone = lights["spot2"]["profile"]["cone"]
    assert (d2["spot2"]["beam_width"], d2["spot2"]["cutoff_angle"]) == (cone["inner_deg"],
                                                                        cone["outer_deg"])
    # Each lighting holds only its own lights.
    assert "lamp" not in d2 and "spot" not in dicts["L0"]
    assert not [k for k, v in dicts["dark"].items()
                if isinstance(v, dict) and v.get("type") in ("point", "spot", "directional")]
    assert dicts["L1"].approximations and "meshes/light.panel.obj" in dicts["L1"].files


def check_element(element, value, path):
    """Every property of an XML element is in its dict `value`, with the same value."""
    assert value["type"] == element.get("type"), path
    for child in element:
        if child.tag == "ref":
            assert {"type": "ref", "id": child.get("id")} in value.values(), path
            continue
        key = child.get("name") or child.tag
        where = f"{path}.{key}"
        assert key in value, where
        got = value[key]
        if child.tag in ("bsdf", "texture", "emitter", "sampler", "film", "rfilter"):
            check_element(child, got, where)
        elif child.tag == "transform":
            lookat = child.find("lookat")
            origin = [float(x) for x in lookat.get("origin").split(",")]
            target = np.array([float(x) for x in lookat.get("target").split(",")])
            m = np.array(got["matrix"])
            # 1e-8: the XML's numbers have 9 significant digits.
            np.testing.assert_allclose(m[:3, 3], origin, atol=1e-8, err_msg=where)
            direction = (target - origin) / np.linalg.norm(target - origin)
            np.testing.assert_allclose(m[:3, 2], direction, atol=1e-8, err_msg=where)
        elif child.tag == "rgb":
            values = [float(x) for x in child.get("value").split(",")]
            np.testing.assert_allclose(got["value"], values, rtol=1e-8, err_msg=where)
        elif child.tag in ("point", "vector"):
            values = [float(child.get(axis)) for axis in "xyz"]
            np.testing.assert_allclose(got, values, rtol=1e-8, atol=1e-12, err_msg=where)
        elif child.tag == "float":
            assert got == pytest.approx(float(child.get("value")), rel=1e-8, abs=1e-12), where
        elif child.tag == "integer":
            assert got == int(child.get("value")), where
        elif child.tag == "boolean":
            assert got == (child.get("value") == "true"), where
        elif child.tag == "string" and key == "filename":
            assert os.path.isabs(got) and got.endswith("/" + child.get("value")), where
        elif child.tag == "string":
            assert got == child.get("value"), where
        else:
            pytest.fail(f"{where}: unexpected element <{child.tag}>")


def test_every_key_of_the_xml_export_is_in_the_dict(scene, dicts, bin_dir, tmp_path):
    out = tmp_path / "xml"
    subprocess.run([bin_dir / "igi-export", scene.file, "--format", "mitsuba", "--out", out,
                    "--quiet"], check=True, capture_output=True)
    for lighting, d in dicts.items():
        root = ET.parse(out / f"scene_{lighting}.xml").getroot()
        assert root.tag == "scene"
        keys = []
        for element in root:
            key = element.get("id") or element.tag
            keys.append(key)
            assert key in d, (lighting, key)
            check_element(element, d[key], f"{lighting}:{key}")
        # And nothing else: the dict is the XML's objects and its own "type".
        assert sorted(keys + ["type"]) == sorted(d), lighting


def test_the_dict_is_plain_json_data(dicts):
    d = dicts["L1"]
    assert json.loads(json.dumps(d)) == d


def test_to_mitsuba_turns_transforms_into_mitsuba_ones(dicts):
    d = dicts["L1"]
    fake = types.SimpleNamespace(ScalarMatrix4f=lambda rows: ("matrix", rows),
                                 ScalarTransform4f=lambda m: ("transform", m))
    converted = mitsuba.to_mitsuba(d, mi=fake)
    assert converted["cam0"]["to_world"] == ("transform",
                                              ("matrix", d["cam0"]["to_world"]["matrix"]))
    assert converted["spot"]["to_world"][0] == "transform"
    assert converted["cam0"]["film"] == d["cam0"]["film"]
    assert d["cam0"]["to_world"]["type"] == "transform"  # the input is left as it was
    if importlib.util.find_spec("mitsuba") is None:
        with pytest.raises(ImportError):
            mitsuba.to_mitsuba(d)


def test_bad_requests_raise_input_error(scene, scenes, tmp_path):
    with pytest.raises(igi.InputError, match="no lighting of that name"):
        mitsuba.scene_dict(scene, "nope", tmp_path)
    with pytest.raises(igi.InputError, match="spp"):
        mitsuba.scene_dict(scene, "L0", tmp_path, spp=0)
    incomplete = igi.Scene.load(scenes / "mini" / "scene.json")
    with pytest.raises(igi.InputError, match="box"):
        mitsuba.scene_dict(incomplete, "L0", tmp_path / "incomplete")
    assert not (tmp_path / "incomplete").exists()
