"""COLMAP sparse models from Python (igi.colmap): TXT and BIN round trips equal to the model,
a model built in Python written and read back, the PLY export, and broken folders refused with the
lines igi's reader gives. Comparisons are exact: TXT carries 17 significant digits and BIN the
bits."""

import os
import shutil
import subprocess

import numpy as np
import pytest

import igi
from igi import colmap


def _unit_quaternion(rng):
    """A (w, x, y, z) unit quaternion equal to itself divided by its norm, as COLMAP keeps one."""
    while True:
        q = rng.normal(size=4)
        for _ in range(8):
            if np.array_equal(q / np.linalg.norm(q), q):
                return q
            q = q / np.linalg.norm(q)


def _model(seed=0):
    """Two cameras of different models, three images (one without 2D points), 2D points with and
    without 3D points, and points with tracks of 0 to 2 elements."""
    rng = np.random.default_rng(seed)
    rec = colmap.Reconstruction()
    rec.cameras[1] = colmap.Camera(1, "PINHOLE", 640, 480, [500.5, 501.25, 320.1, 239.9])
    rec.cameras[7] = colmap.Camera(7, "OPENCV", 4000, 3000, rng.normal(size=8))
    for image_id, name, camera_id in [(1, "a.jpg", 1), (2, "dir/b.JPG", 7), (5, "c.png", 7)]:
        n = 0 if image_id == 5 else 6
        rec.images[image_id] = colmap.Image(image_id, name, camera_id, _unit_quaternion(rng),
                                            rng.normal(size=3), rng.uniform(0, 480, (n, 2)))
    tracks = [[(1, 0), (2, 3)], [(2, 0)], []]
    for row, track in enumerate(tracks):
        for image_id, index in track:
            rec.images[image_id].point3D_ids[index] = 100 + row
    rec.points3D = colmap.Points3D.from_tracks(
        ids=[100, 101, 102], xyz=rng.normal(size=(3, 3)), rgb=[[255, 0, 10], [1, 2, 3], [0, 0, 0]],
        error=[0.5, -1.0, 2.25], tracks=tracks)
    return rec


def test_model_built_in_python_is_written_and_read_back_in_text_and_binary(tmp_path):
    rec = _model()
    rec.validate()
    rec.write_text(tmp_path / "txt")
    rec.write_binary(tmp_path / "bin")
    assert sorted(p.name for p in (tmp_path / "bin").iterdir()) == [
        "cameras.bin", "images.bin", "points3D.bin"]
    for folder in ("txt", "bin"):
        back = colmap.Reconstruction.read(tmp_path / folder)
        assert back == rec, folder
    back = colmap.Reconstruction(tmp_path / "bin")
    assert back.images[2].point3D_ids.tolist() == [101, -1, -1, 100, -1, -1]
    assert back.points3D.ids.dtype == np.int64 and back.points3D.rgb.dtype == np.uint8
    assert back.points3D.track_of(0).tolist() == [[1, 0], [2, 3]]
    assert back.num_observations() == 3
    assert back.find_image_with_name("dir/b.JPG").image_id == 2
    assert back.find_image_with_name("nope.jpg") is None
    assert colmap.CAMERA_MODELS["OPENCV"] == 8 and len(colmap.CAMERA_MODELS) == 11


def test_text_to_binary_to_text_is_identical(tmp_path):
    _model(1).write_text(tmp_path / "txt")
    colmap.Reconstruction.read(tmp_path / "txt").write_binary(tmp_path / "bin")
    colmap.Reconstruction.read(tmp_path / "bin").write_text(tmp_path / "txt2")
    for name in ("cameras.txt", "images.txt", "points3D.txt"):
        assert (tmp_path / "txt" / name).read_bytes() == (tmp_path / "txt2" / name).read_bytes()


def test_pose_helpers_follow_cam_from_world():
    image = _model(2).images[1]
    assert np.allclose(image.R @ image.R.T, np.eye(3), atol=1e-12)
    assert np.allclose(image.R @ image.center + image.tvec, 0, atol=1e-12)
    # A quarter turn about z, (w, x, y, z) order: the world x axis goes to the camera's y axis.
    turn = colmap.Image(9, "t.jpg", 1, qvec=[np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    assert np.allclose(turn.R @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_ply_export_holds_every_point_as_float_and_uchar(tmp_path):
    rec = _model(3)
    rec.export_PLY(tmp_path / "points.ply")
    data = (tmp_path / "points.ply").read_bytes()
    header, body = data.split(b"end_header\n", 1)
    assert header.decode().splitlines() == [
        "ply", "format binary_little_endian 1.0", "element vertex 3", "property float x",
        "property float y", "property float z", "property uchar red", "property uchar green",
        "property uchar blue"]
    assert len(body) == 3 * 15
    records = np.frombuffer(body, dtype=np.dtype(
        [("xyz", "<f4", 3), ("rgb", "u1", 3)]))
    np.testing.assert_array_equal(records["xyz"], rec.points3D.xyz.astype(np.float32))
    np.testing.assert_array_equal(records["rgb"], rec.points3D.rgb)


def test_broken_model_folder_raises_input_error_with_the_problem_line(tmp_path):
    _model(4).write_text(tmp_path)
    images = (tmp_path / "images.txt").read_text().replace(" 7 dir/b.JPG", " 3 dir/b.JPG")
    (tmp_path / "images.txt").write_text(images)
    with pytest.raises(igi.InputError) as error:
        colmap.Reconstruction.read(tmp_path)
    assert any("images.txt: line" in p and "CAMERA_ID 3: image references a missing camera" in p
               for p in error.value.problems), error.value.problems
    (tmp_path / "points3D.txt").unlink()
    with pytest.raises(igi.InputError) as error:
        colmap.Reconstruction.read(tmp_path)
    assert "points3D.txt: missing file" in error.value.problems[0]


def test_invalid_model_built_in_python_writes_nothing(tmp_path):
    rec = _model(5)
    rec.images[2].camera_id = 99
    with pytest.raises(igi.InputError) as error:
        rec.write_binary(tmp_path / "out")
    assert "image references a missing camera" in str(error.value)
    assert not (tmp_path / "out").exists()
    rec = _model(5)
    rec.images[1].xys = np.zeros((2, 3))
    with pytest.raises(igi.InputError, match=r"images\[1\]\.xys"):
        rec.write_text(tmp_path / "out")
    with pytest.raises(igi.InputError, match="must be in"):
        colmap.Points3D(ids=[1], xyz=[[0, 0, 0]], rgb=[[256, 0, 0]], error=[0])
    assert not (tmp_path / "out").exists()


@pytest.mark.skipif(shutil.which("colmap") is None, reason="colmap is not on PATH")
def test_colmap_reads_the_binary_model_written_from_python(tmp_path):
    rec = _model(6)
    rec.write_binary(tmp_path / "bin")
    (tmp_path / "txt").mkdir()
    subprocess.run(["colmap", "model_converter", "--input_path", str(tmp_path / "bin"),
                    "--output_path", str(tmp_path / "txt"), "--output_type", "TXT"],
                   check=True, capture_output=True,
                   env=dict(os.environ, QT_QPA_PLATFORM="offscreen"))
    assert colmap.Reconstruction.read(tmp_path / "txt") == rec
