"""Fixtures of the Python package's tests: where the sources, executables and shared data are
(set by ctest; tests/python/CMakeLists.txt)."""

import os
import pathlib

import pytest


def _env_path(name: str) -> pathlib.Path:
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set: run the Python tests through ctest")
    return pathlib.Path(value)


@pytest.fixture(scope="session")
def source_dir() -> pathlib.Path:
    return _env_path("IGI_SOURCE_DIR")


@pytest.fixture(scope="session")
def bin_dir() -> pathlib.Path:
    return _env_path("IGI_BIN")


@pytest.fixture(scope="session")
def scenes(source_dir: pathlib.Path) -> pathlib.Path:
    return source_dir / "tests" / "data" / "scenes"
