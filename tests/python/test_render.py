"""Renders from Python equal igi-render's for the same scene, camera, lighting, spp and seed."""

import subprocess

import numpy as np
import pytest

import igi


def test_render_equals_igi_render_bit_for_bit(scenes, bin_dir, tmp_path):
    path = scenes / "render" / "complete.json"
    out = tmp_path / "cam0_L1.exr"
    subprocess.run([bin_dir / "igi-render", path, "--camera", "cam0", "--lighting", "L1",
                    "--spp", "32", "--seed", "7", "--width", "32", "--height", "24", "--out", out],
                   check=True, capture_output=True)
    theirs = igi.read_image(out)
    ours = igi.Renderer(igi.Scene.load(path), "L1").render("cam0", spp=32, seed=7, width=32,
                                                             height=24)
    assert ours.shape == (24, 32, 3)
    assert np.asarray(ours).max() > 0
    np.testing.assert_array_equal(np.asarray(ours), np.asarray(theirs))
    assert ours.metadata["igi:seed"] == 7 and ours.metadata["igi:lighting"] == "L1"


def test_other_seed_other_noise(scenes):
    renderer = igi.Renderer(igi.Scene.load(scenes / "render" / "complete.json"), "L0")
    a = renderer.render("cam0", spp=4, seed=1)
    b = renderer.render("cam0", spp=4, seed=2)
    assert not np.array_equal(np.asarray(a), np.asarray(b))


def test_bad_names_and_incomplete_materials_raise_input_error(scenes):
    scene = igi.Scene.load(scenes / "render" / "complete.json")
    with pytest.raises(igi.InputError, match="no lighting of that name"):
        igi.Renderer(scene, "nope")
    with pytest.raises(igi.InputError, match="no camera of that name"):
        igi.Renderer(scene, "L0").render("nope")
    with pytest.raises(igi.InputError, match="spp"):
        igi.Renderer(scene, "L0").render("cam0", spp=0)
    with pytest.raises(igi.InputError, match="rendering needs every material value"):
        igi.Renderer(igi.Scene.load(scenes / "mini" / "scene.json"), "L0")
