"""Cameras against OpenCV: projection (with OpenCV's distortion model) equals cv2.projectPoints
for the same K, pose and coefficients; rays and projection invert each other."""

import cv2
import numpy as np

import igi


def _points_in_view(camera, n, rng):
    pixels = np.column_stack([rng.uniform(0, camera.width, n), rng.uniform(0, camera.height, n)])
    origin, directions = camera.rays(pixels)
    depths = rng.uniform(0.5, 3.0, n)[:, None]
    return pixels, origin + directions * depths


def test_projection_equals_cv2_project_points(scenes):
    scene = igi.Scene.load(scenes / "mini" / "scene.json")
    rng = np.random.default_rng(3)
    for camera in scene.cameras.values():
        _, points = _points_in_view(camera, 200, rng)
        rvec, _ = cv2.Rodrigues(camera.R)
        distortion = np.array(camera.params[4:8] if camera.model == "OPENCV" else [0, 0, 0, 0],
                              dtype=np.float64)
        theirs, _ = cv2.projectPoints(points, rvec, camera.tvec, camera.K, distortion)
        np.testing.assert_allclose(camera.project(points), theirs.reshape(-1, 2), atol=1e-9)


def test_rays_and_projection_invert_each_other(scenes):
    scene = igi.Scene.load(scenes / "mini" / "scene.json")
    rng = np.random.default_rng(4)
    for camera in scene.cameras.values():
        pixels, points = _points_in_view(camera, 100, rng)
        np.testing.assert_allclose(camera.project(points), pixels, atol=1e-6)


def test_points_behind_the_camera_project_to_nan(scenes):
    camera = igi.Scene.load(scenes / "mini" / "scene.json").cameras["cam0"]
    origin, directions = camera.rays(np.array([[4.0, 3.0]]))
    behind = origin - directions[0]
    assert np.isnan(camera.project(behind[None, :])).all()
