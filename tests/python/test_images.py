"""Images between igi and numpy: files round-trip, metadata travels, bad arrays are refused."""

import numpy as np
import pytest

import igi


def test_exr_round_trip_keeps_values_and_metadata(tmp_path):
    rng = np.random.default_rng(1)
    pixels = rng.random((5, 7, 3), dtype=np.float32) * 100
    path = tmp_path / "a.exr"
    igi.write_image(path, pixels, {"igi:camera": "cam0", "igi:spp": 16, "gain": 1.5})
    image = igi.read_image(path)
    assert isinstance(image, igi.Image)
    assert image.shape == (5, 7, 3) and image.dtype == np.float32
    np.testing.assert_array_equal(np.asarray(image), pixels)
    assert image.metadata["igi:camera"] == "cam0"
    assert image.metadata["igi:spp"] == 16
    assert image.metadata["gain"] == pytest.approx(1.5)


def test_row_zero_is_the_top_row(tmp_path):
    pixels = np.zeros((4, 3, 3), np.float32)
    pixels[0, :, :] = 1.0  # the top row white
    path = tmp_path / "top.png"
    igi.write_image(path, pixels)
    image = igi.read_image(path)
    assert image[0].min() == 1.0 and image[1:].max() == 0.0


def test_png_is_eight_bit_clamped(tmp_path):
    pixels = np.array([[[-1.0, 0.5, 2.0]]], np.float32)
    path = tmp_path / "c.png"
    igi.write_image(path, pixels)
    np.testing.assert_allclose(igi.read_image(path)[0, 0], [0.0, 128 / 255, 1.0], atol=1e-6)


def test_image_keeps_metadata_through_numpy_and_does_not_copy():
    base = np.ones((2, 2, 3), np.float32)
    image = igi.Image(base, {"k": "v"})
    assert np.shares_memory(image, base)
    assert (image * 2).metadata == {"k": "v"}


def test_read_gives_an_array_that_owns_its_pixels(tmp_path):
    path = tmp_path / "o.exr"
    igi.write_image(path, np.full((3, 2, 3), 0.25, np.float32))
    image = igi.read_image(path)
    assert image.flags["C_CONTIGUOUS"] and image.flags["WRITEABLE"]
    image[0, 0, 0] = 7.0  # its own memory, not a view of something freed
    assert image[0, 0, 0] == 7.0


def test_bad_arrays_and_files_raise_input_error(tmp_path):
    with pytest.raises(igi.InputError) as bad_shape:
        igi.write_image(tmp_path / "x.exr", np.zeros((2, 2, 2, 2), np.float32))
    assert "must be (H, W) or (H, W, C)" in bad_shape.value.problems[0]
    with pytest.raises(igi.InputError):
        igi.write_image(tmp_path / "y.exr", np.zeros((2, 2, 6), np.float32))
    with pytest.raises(igi.InputError) as missing:
        igi.read_image(tmp_path / "missing.exr")
    assert "missing.exr" in missing.value.problems[0]
    assert not (tmp_path / "x.exr").exists() and not (tmp_path / "y.exr").exists()
