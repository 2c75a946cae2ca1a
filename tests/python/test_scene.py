"""Scenes from Python: loading, the document as a dict and back, saving elsewhere, the mesh as
arrays, and bad scenes refused with the lines igi-info prints."""

import json
import subprocess

import numpy as np
import pytest

import igi


def test_mini_scene_cameras_lightings_photos_and_mesh(scenes):
    scene = igi.Scene.load(scenes / "mini" / "scene.json")
    assert set(scene.cameras) == {"cam0", "cam1"}
    assert scene.lightings["L1"] == ["spot", "panel"]
    assert scene.materials["box"]["brdf"] == "ward_aniso"
    assert scene.lights["lamp"]["type"] == "point"
    assert [p["camera"] for p in scene.photos] == ["cam0", "cam0"]
    mesh = scene.mesh
    assert mesh["positions"].shape[1] == 3 and mesh["triangles"].shape[1] == 3
    assert mesh["triangles"].max() < len(mesh["positions"])
    assert len(mesh["triangle_region"]) == len(mesh["triangles"])
    assert set(mesh["region_names"]) == {"floor", "ceiling", "walls", "box"}
    cam1 = scene.cameras["cam1"]
    assert cam1.model == "OPENCV" and (cam1.width, cam1.height) == (8, 6)
    np.testing.assert_array_equal(cam1.qvec, [0, 1, 0, 0])  # (w, x, y, z)
    np.testing.assert_allclose(cam1.R @ cam1.center + cam1.tvec, 0, atol=1e-12)


def test_dict_round_trip_and_save_to_another_folder(scenes, tmp_path):
    scene = igi.Scene.load(scenes / "mini" / "scene.json")
    document = scene.to_dict()
    again = igi.Scene.from_dict(document, base_dir=scene.dir)
    assert again.to_dict() == document
    np.testing.assert_array_equal(again.mesh["positions"], scene.mesh["positions"])
    saved = tmp_path / "elsewhere" / "scene.json"
    saved.parent.mkdir()
    original = (scenes / "mini" / "scene.json").read_bytes()
    scene.save(saved)
    assert (scenes / "mini" / "scene.json").read_bytes() == original
    moved = igi.Scene.load(saved)
    np.testing.assert_array_equal(moved.mesh["triangles"], scene.mesh["triangles"])
    assert moved.photos[0]["file"] == scene.photos[0]["file"]  # paths rebased, same files
    assert json.loads(saved.read_text())["geometry"][0]["file"] != document["geometry"][0]["file"]


def test_from_dict_validates_like_load(scenes, tmp_path):
    document = igi.Scene.load(scenes / "mini" / "scene.json").to_dict()
    document["materials"]["walls"]["rho_d"] = 1.5
    with pytest.raises(igi.InputError) as error:
        igi.Scene.from_dict(document, base_dir=scenes / "mini")
    assert "materials.walls.rho_d" in error.value.problems[0]


def test_broken_scenes_raise_the_lines_igi_info_prints(scenes, bin_dir):
    broken = sorted((scenes / "broken").glob("*.json"))
    assert len(broken) > 30
    for path in broken:
        with pytest.raises(igi.InputError) as error:
            igi.Scene.load(path)
        info = subprocess.run([bin_dir / "igi-info", path], capture_output=True, text=True)
        assert info.returncode == 2, path
        first = info.stderr.splitlines()[0].removeprefix("igi-info: error: ")
        assert error.value.problems[0] == first, path
