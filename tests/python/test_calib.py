"""Calibration and HDR from Python equal the executables on real data: igi.calib.response writes
igi-calib's response.json, igi.calib.intrinsics its camera.json, igi.hdr.merge igi-hdr's radiance
map bit for bit, and igi.hdr.decode_raw igi-hdr's linear raw decode; bad input raises
igi.InputError naming the flag or file, with nothing written."""

import inspect
import json
import os
import pathlib
import subprocess
from fractions import Fraction

import numpy as np
import pytest

import igi


def _shared() -> pathlib.Path:
    value = os.environ.get("IGI_SHARED_DATA_DIR")
    if not value:
        pytest.fail("IGI_SHARED_DATA_DIR is not set: run the Python tests through ctest")
    return pathlib.Path(value)


@pytest.fixture(scope="module")
def memorial():
    """Debevec's Memorial Church bracket: 16 8-bit photos, their shutter times in a file."""
    folder = _shared() / "real" / "memorial"
    paths = [str(folder / f"memorial00{i}.png") for i in range(61, 77)]
    if not all(os.path.exists(p) for p in paths):
        pytest.skip(f"the Memorial bracket is not in {folder}")
    return paths, str(folder / "shutter_times.txt")


@pytest.fixture(scope="module")
def calibrated(memorial, bin_dir, tmp_path_factory):
    """igi-calib response's response.json for the Memorial bracket, and the same from Python."""
    paths, times = memorial
    out = tmp_path_factory.mktemp("response") / "response.json"
    subprocess.run([bin_dir / "igi-calib", "--quiet", "response", *paths, "--exposure-file", times,
                    "--out", out], check=True, capture_output=True)
    return out, igi.calib.response(paths, exposure_file=times)


def test_response_equals_igi_calib_response_json(calibrated, tmp_path):
    theirs, curve = calibrated
    document = json.loads(theirs.read_text())
    assert curve.to_dict() == document
    assert curve.method == "debevec" and curve.levels == 256 and curve.channels == ["R", "G", "B"]
    assert curve.g.shape == (3, 256)
    # g at full precision, the file at 1e-7: they differ by the rounding only.
    np.testing.assert_allclose(curve.g, np.array(document["g"]), rtol=0, atol=5.1e-8)
    curve.save(tmp_path / "response.json", plot=tmp_path / "response.svg")
    assert (tmp_path / "response.json").read_bytes() == theirs.read_bytes()
    assert (tmp_path / "response.svg").read_bytes() == theirs.with_suffix(".svg").read_bytes()


def test_response_loads_and_linearises_at_its_levels(calibrated):
    theirs, _ = calibrated
    curve = igi.calib.ResponseCurve.load(theirs)
    assert curve.to_dict() == json.loads(theirs.read_text()) and curve.source == str(theirs)
    assert igi.calib.ResponseCurve.from_dict(curve.to_dict()).to_dict() == curve.to_dict()
    levels = np.arange(256, dtype=np.uint8)
    pixels = np.stack([levels] * 3, axis=-1)  # (256, 3): level k in every channel
    # At a level, g needs no interpolation: the value is the curve's to double rounding.
    np.testing.assert_allclose(curve.ln_exposure(pixels), curve.g.T, rtol=0, atol=1e-12)
    np.testing.assert_allclose(curve.linearize(pixels), np.exp(curve.g.T), rtol=1e-12)
    assert np.all(np.diff(curve.linearize(pixels), axis=0) >= 0)  # non-decreasing


def test_merge_equals_igi_hdr_bit_for_bit(memorial, calibrated, bin_dir, tmp_path):
    paths, times = memorial
    response, curve = calibrated
    out = tmp_path / "theirs.exr"
    subprocess.run([bin_dir / "igi-hdr", *paths, "--exposure-file", times, "--response", response,
                    "--out", out, "--quiet"], check=True, capture_output=True)
    theirs = np.asarray(igi.read_image(out))
    theirs_mask = np.asarray(igi.read_image(tmp_path / "theirs_mask.png"))

    # In memory, with the response as a file; then written band by band as igi-hdr does.
    calls = []
    merged = igi.hdr.merge(paths, exposure_file=times, response=response, threads=2,
                           progress=lambda *call: calls.append(call))
    assert calls and calls[-1][1] == calls[-1][2] == theirs.shape[0]  # every row merged
    np.testing.assert_array_equal(np.asarray(merged.radiance), theirs)
    np.testing.assert_array_equal(np.asarray(merged.mask), theirs_mask)
    assert merged.radiance.metadata == {"igi:response": str(response), "igi:weighting": "noise"}
    ours = tmp_path / "ours.exr"
    written = igi.hdr.merge(paths, exposure_file=times, response=response, out=ours)
    np.testing.assert_array_equal(np.asarray(igi.read_image(ours)), theirs)
    np.testing.assert_array_equal(np.asarray(written.radiance), theirs)
    np.testing.assert_array_equal(np.asarray(igi.read_image(tmp_path / "ours_mask.png")),
                                  theirs_mask)

    # Arrays as igi.read_image gives them, and the curve loaded as an object.
    images = [igi.read_image(p) for p in paths]
    from_arrays = igi.hdr.merge(images, exposure_file=times, bits=8,
                                response=igi.calib.ResponseCurve.load(response))
    np.testing.assert_array_equal(np.asarray(from_arrays.radiance), theirs)
    # The curve at full precision: g within 5e-8 of the file's moves radiance by < 1e-6.
    from_curve = igi.hdr.merge(paths, exposure_file=times, response=curve)
    np.testing.assert_allclose(np.asarray(from_curve.radiance), theirs, rtol=1e-6)


def test_merge_recovering_the_response_equals_igi_hdr(memorial, bin_dir, tmp_path):
    paths, times = memorial
    every_third = paths[::3]
    seconds = [float(Fraction(t)) for t in pathlib.Path(times).read_text().split()][::3]
    out = tmp_path / "recovered.exr"
    subprocess.run([bin_dir / "igi-hdr", *every_third, "--exposures",
                    ",".join(repr(t) for t in seconds), "--weighting", "hat", "--out", out,
                    "--quiet"], check=True, capture_output=True)
    merged = igi.hdr.merge(every_third, exposures=seconds, weighting="hat")
    np.testing.assert_array_equal(np.asarray(merged.radiance), np.asarray(igi.read_image(out)))
    assert merged.radiance.metadata["igi:response"] == "recovered (debevec)"


@pytest.fixture(scope="module")
def colorchart(bin_dir, tmp_path_factory):
    """igi-hdr's radiance map of the one raw frame colorchart.dng (a Canon 550D DNG)."""
    path = _shared() / "real" / "raw" / "colorchart.dng"
    if not path.exists():
        pytest.skip(f"{path} is absent")
    out = tmp_path_factory.mktemp("raw") / "chart.exr"
    subprocess.run([bin_dir / "igi-hdr", path, "--out", out, "--quiet"], check=True,
                   capture_output=True)
    return path, out


def test_decode_raw_equals_igi_hdrs_decode(colorchart):
    path, out = colorchart
    decoded = igi.hdr.decode_raw(path)
    metadata = decoded.metadata
    assert decoded.dtype == np.float32 and decoded.ndim == 3 and decoded.shape[2] == 3
    assert metadata["Make"] == "Canon" and metadata["igi:camera"].startswith("Canon")
    assert metadata["ExposureTime"] > 0
    assert 0 < metadata["igi:black_level"] < metadata["igi:white_level"] < 2 ** 14
    assert metadata["igi:raw_bits"] == 14
    assert 0 <= decoded.min() and decoded.max() <= 1  # 1 = the white level
    # igi-hdr's map of one raw frame is decode / exposure time wherever the frame is usable
    # (elsewhere it holds a bound); the two differ by float rounding of exp(ln v) / t only.
    theirs = np.asarray(igi.read_image(out))
    good = np.asarray(igi.read_image(out.with_name("chart_mask.png")))[..., 0] > 0
    assert good.mean() > 0.9
    ours = np.asarray(decoded, dtype=np.float64) / metadata["ExposureTime"]
    np.testing.assert_allclose(ours[good], theirs[good], rtol=1e-6)
    # And the raw file merged from Python is igi-hdr's map bit for bit.
    merged = igi.hdr.merge([path])
    np.testing.assert_array_equal(np.asarray(merged.radiance), theirs)
    assert merged.radiance.metadata["igi:response"] == "raw (linear)"
    half = igi.hdr.decode_raw(path, raw_white_balance="none", raw_color="raw", half_size=True)
    assert half.shape[0] < decoded.shape[0] and half.metadata["igi:raw_color"] == "raw"


def test_intrinsics_equals_igi_calib_camera_json(bin_dir, tmp_path):
    folder = _shared() / "real" / "chessboard_left"
    views = sorted(str(p) for p in folder.glob("left*.jpg"))
    if len(views) < 3:
        pytest.skip(f"the chessboard views are not in {folder}")
    out = tmp_path / "theirs.json"
    subprocess.run([bin_dir / "igi-calib", "--quiet", "intrinsics", *views, "--board", "9x6",
                    "--square", "0.025", "--fix-aspect-ratio", "--out", out], check=True,
                   capture_output=True)
    camera = igi.calib.intrinsics(views, board="9x6", square=0.025, fix_aspect_ratio=True)
    assert camera.to_dict() == json.loads(out.read_text())
    camera.save(tmp_path / "ours.json")
    assert (tmp_path / "ours.json").read_bytes() == out.read_bytes()
    assert igi.calib.CameraIntrinsics.load(out).to_dict() == camera.to_dict()
    fx, fy, cx, cy = camera.params[:4]
    np.testing.assert_array_equal(camera.K, [[fx, 0, cx], [0, fy, cy], [0, 0, 1]])
    np.testing.assert_array_equal(camera.distortion, camera.params[4:])
    assert (camera.model, camera.width, camera.height) == ("OPENCV", 640, 480)
    assert len(camera.views) == len(views) and not camera.rejected_views
    # OpenCV's own calibration of these views (left_intrinsics.yml): fx = fy = 535.92, RMS 0.393;
    # igi's corner refinement differs slightly, so 1 % and 0.05 px.
    assert fx == fy and abs(fx / 535.92 - 1) < 0.01 and abs(camera.rms_px - 0.393) < 0.05


def test_bad_input_raises_input_error_and_writes_nothing(memorial, tmp_path):
    paths, times = memorial
    out = tmp_path / "radiance.exr"
    missing = str(tmp_path / "missing.png")
    with pytest.raises(igi.InputError, match="missing.png"):
        igi.hdr.merge([paths[0], missing], exposures=[1, 2], linear=True, out=out)
    with pytest.raises(igi.InputError, match="missing.png"):
        igi.calib.response([paths[0], missing], exposures="1,2")
    with pytest.raises(igi.InputError, match="--weighting: nope: must be noise or hat"):
        igi.hdr.merge(paths, exposure_file=times, weighting="nope", out=out)
    with pytest.raises(igi.InputError, match="--method: nope: must be debevec or robertson"):
        igi.calib.response(paths, exposure_file=times, method="nope")
    with pytest.raises(igi.InputError, match="--lambda: -1"):
        igi.calib.response(paths, exposure_file=times, lambda_=-1)
    with pytest.raises(igi.InputError, match="--black/--saturated"):
        igi.hdr.merge(paths, exposure_file=times, black=0.99, out=out)
    with pytest.raises(igi.InputError, match="excludes --exposure-file"):
        igi.hdr.merge(paths, exposures=[1] * 16, exposure_file=times, out=out)
    with pytest.raises(igi.InputError, match="--out: .png: radiance maps are written as OpenEXR"):
        igi.hdr.merge(paths, exposure_file=times, out=tmp_path / "radiance.png")
    with pytest.raises(igi.InputError, match="--board: 9by6: must be COLSxROWS"):
        igi.calib.intrinsics(paths, board="9by6", square=0.025)
    with pytest.raises(igi.InputError, match="--raw-color: xyz: must be srgb or raw"):
        igi.hdr.decode_raw(missing, raw_color="xyz")
    with pytest.raises(igi.InputError, match="missing.png: raw"):
        igi.hdr.decode_raw(missing)
    assert list(tmp_path.iterdir()) == []


def test_keyword_defaults_are_the_libraries_defaults():
    defaults = igi._igi._calib_defaults()
    for function, program in ((igi.calib.response, "response"),
                              (igi.calib.intrinsics, "intrinsics"), (igi.hdr.merge, "merge")):
        parameters = inspect.signature(function).parameters
        for name, value in defaults[program].items():
            assert parameters[name].default == value, (function.__name__, name)
