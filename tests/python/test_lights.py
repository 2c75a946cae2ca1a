"""igi.lights: IES profiles read as the renderer reads them — the table as arrays, values at the
table's angles equal to the table, and the relative intensity of spot directions."""

import os
import pathlib

import numpy as np
import pytest

import igi
from igi import lights


@pytest.fixture(scope="module")
def spot_ies(scenes):
    return lights.read_ies(scenes / "mini" / "lights" / "spot.ies")


def real_ies_files():
    """The real luminaires' files of the shared data (none when it is not there)."""
    shared = os.environ.get("IGI_SHARED_DATA_DIR")
    folder = pathlib.Path(shared) / "real" / "ies" if shared else None
    return sorted(folder.glob("*.IES")) if folder and folder.is_dir() else []


def test_the_table_as_arrays(spot_ies):
    # The file: vertical 0 22.5 45 67.5 90, horizontal 0, candela 100 90 60 20 0.
    np.testing.assert_array_equal(spot_ies.vertical_deg, [0, 22.5, 45, 67.5, 90])
    np.testing.assert_array_equal(spot_ies.horizontal_deg, [0])
    np.testing.assert_array_equal(spot_ies.candela, [[100, 90, 60, 20, 0]])
    assert spot_ies.max_candela == 100
    assert spot_ies.standard == "IESNA:LM-63-2002"
    assert spot_ies.keywords["MANUFAC"] == "igi"
    assert spot_ies.photometric_type == 1


def test_values_at_the_table_angles_equal_the_table(spot_ies):
    v, h = np.meshgrid(spot_ies.vertical_deg, spot_ies.horizontal_deg)
    np.testing.assert_array_equal(spot_ies.intensity(v, h), spot_ies.candela)
    # A one-plane file is rotationally symmetric; between angles the interpolation is linear.
    assert spot_ies.intensity(22.5, 123.0) == 90
    assert spot_ies.intensity(33.75, 0.0) == pytest.approx(75.0, rel=1e-12)


@pytest.mark.parametrize("path", real_ies_files(), ids=lambda p: p.name)
def test_real_files_reproduce_their_tables(path):
    ies = lights.read_ies(path)
    v, h = np.meshgrid(ies.vertical_deg, ies.horizontal_deg)
    assert ies.candela.shape == (len(ies.horizontal_deg), len(ies.vertical_deg))
    # 1e-12 of the peak: at a tabulated angle the bilinear weights are 0 and 1, up to rounding of
    # the angle arithmetic.
    np.testing.assert_allclose(ies.intensity(v, h), ies.candela, rtol=0,
                               atol=1e-12 * ies.max_candela)


def test_relative_intensity_as_the_renderer_weighs_it(spot_ies):
    theta = np.radians(spot_ies.vertical_deg)
    local = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=1)
    np.testing.assert_allclose(spot_ies.relative(local), spot_ies.candela[0] / 100, rtol=1e-12)
    # World directions of a spot pointing down: the same angles from its axis.
    down = local * np.array([1, 1, -1])
    np.testing.assert_allclose(spot_ies.relative(down, axis=[0, 0, -1]),
                               spot_ies.candela[0] / 100, rtol=1e-12)
    # Past 90° from the axis a type C file with angles up to 90° emits nothing.
    assert spot_ies.relative(np.array([[0.0, 0.0, -1.0]]))[0] == 0.0


def test_bad_file_raises_input_error(scenes):
    with pytest.raises(igi.InputError) as raised:
        lights.read_ies(scenes / "broken" / "res" / "broken.ies")
    assert "broken.ies" in str(raised.value)
    with pytest.raises(igi.InputError):
        lights.read_ies(scenes / "nope.ies")
