"""igi: inverse global illumination — Python interface.

Photographs of a real scene under known lights, its geometry and a split of its surfaces into
regions go in; a lighting-independent model of its materials comes out, and renders of it under
new lighting. This package is igi's C++ libraries (the extension module ``igi._igi``) behind a thin
Python layer; the executables (igi-solve, igi-render, ...) do the same work from the shell.

Conventions:

- Images are numpy arrays ``(H, W, C)`` of float32, row 0 at the top, linear RGB where they hold
  radiance. :class:`Image` is such an array with a ``metadata`` dict.
- Cameras follow COLMAP: x right, y down, z forward, ``cam_from_world`` as ``qvec`` (w, x, y, z)
  and ``tvec``, pixel centres at +0.5 (the top-left pixel's centre is (0.5, 0.5)).
- Bad input raises :class:`InputError` (a ``ValueError``) whose ``problems`` lists one line per
  problem, ``FILE: KEY: VALUE: RULE`` — the lines the executables print — and nothing is written.
- igi's log goes to Python's :mod:`logging`, logger ``"igi"``.
"""

from __future__ import annotations

import json
import logging
import os
import tempfile
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _igi, brdf, colmap, lights, mitsuba
from ._igi import Camera, Error, InputError
from ._jobs import ProgressCallback, Summary, bin_dir, flag_arguments, options_help, run_long

__all__ = [
    "Camera",
    "Error",
    "Image",
    "InputError",
    "Renderer",
    "Scene",
    "Summary",
    "brdf",
    "calib",
    "colmap",
    "diagnose",
    "export",
    "hdr",
    "lights",
    "mitsuba",
    "read_image",
    "run",
    "set_log_level",
    "solve",
    "synth",
    "write_image",
]

PathLike = Union[str, "os.PathLike[str]"]

logging.getLogger("igi").addHandler(logging.NullHandler())


def set_log_level(level: int) -> None:
    """Sets the least level (``logging.INFO``, ...) of igi's messages handed to :mod:`logging`."""
    _igi._set_log_level(int(level))


class Image(np.ndarray):
    """A float32 ``(H, W, C)`` array (row 0 at the top) with a ``metadata`` dict.

    ``Image(array, metadata)`` wraps an array without copying it when it is float32 already;
    numpy operations on an Image give Images that keep the metadata.
    """

    metadata: Dict[str, Any]

    def __new__(cls, array: Any, metadata: Optional[Dict[str, Any]] = None) -> "Image":
        obj = np.asarray(array, dtype=np.float32).view(cls)
        obj.metadata = dict(metadata or {})
        return obj

    def __array_finalize__(self, obj: Any) -> None:
        self.metadata = dict(getattr(obj, "metadata", {}) or {})

    @classmethod
    def read(cls, path: PathLike, channels: int = 0) -> "Image":
        """Reads an image file (EXR, HDR, PNG, TIFF, JPEG, ... through OpenImageIO); integer
        files are scaled to [0, 1]. ``channels`` > 0 keeps that many channels."""
        array, metadata = _igi.read_image(os.fspath(path), channels)
        return cls(array, metadata)

    def write(self, path: PathLike, pixel_type: str = "auto", compression: str = "") -> None:
        """Writes the image atomically, with its metadata as attributes. ``pixel_type``: auto
        (float for EXR, uint16 for TIFF, uint8 for PNG/JPEG), half, float, uint8 or uint16."""
        write_image(path, self, self.metadata, pixel_type, compression)


def read_image(path: PathLike, channels: int = 0) -> Image:
    """Reads an image file as an :class:`Image` (see :meth:`Image.read`)."""
    return Image.read(path, channels)


def write_image(path: PathLike, array: Any, metadata: Optional[Dict[str, Any]] = None,
                pixel_type: str = "auto", compression: str = "") -> None:
    """Writes an ``(H, W)`` or ``(H, W, C)`` array atomically; the extension picks the format."""
    if metadata is None:
        metadata = getattr(array, "metadata", {}) or {}
    _igi.write_image(os.fspath(path), np.asarray(array), dict(metadata), pixel_type, compression)


class Scene:
    """A calibrated scene (scene.json): geometry with regions, materials, lights and lightings,
    cameras and photos. Load one with :meth:`load` or :meth:`from_dict`; the scene is immutable,
    edit its :meth:`to_dict` and make a new one."""

    def __init__(self, native: "_igi._Scene") -> None:
        self._native = native

    @classmethod
    def load(cls, path: PathLike, load_geometry: bool = True, check_images: bool = True,
             require_complete_materials: bool = False) -> "Scene":
        """Reads and validates scene.json. Raises :class:`InputError` listing every problem
        (as ``igi-info`` prints them)."""
        return cls(_igi._Scene.load(os.fspath(path), load_geometry, check_images,
                                    require_complete_materials))

    @classmethod
    def from_dict(cls, document: Dict[str, Any], base_dir: PathLike = ".",
                  load_geometry: bool = True, check_images: bool = True,
                  require_complete_materials: bool = False) -> "Scene":
        """A scene from a scene.json document held as a dict; relative paths in it are taken
        from ``base_dir``. Validated as :meth:`load` validates a file."""
        path = os.path.join(os.fspath(base_dir), "scene.json")
        return cls(_igi._Scene.from_json(json.dumps(document), path, load_geometry,
                                         check_images, require_complete_materials))

    def to_dict(self) -> Dict[str, Any]:
        """The scene.json document, as read (paths relative to :attr:`dir`)."""
        return json.loads(self._native.document_json())

    def save(self, path: PathLike) -> None:
        """Writes the document to ``path`` (atomically), its relative paths rewritten for the new
        folder; validated first, nothing written when it breaks a rule."""
        _igi._save_scene(self._native.document_json(), os.fspath(self.dir), os.fspath(path))

    @property
    def file(self) -> str:
        """The scene.json read (absolute)."""
        return os.fspath(self._native.file)

    @property
    def dir(self) -> str:
        """Its folder: relative paths in the document are taken from it."""
        return os.fspath(self._native.dir)

    @property
    def materials(self) -> Dict[str, Dict[str, Any]]:
        """Materials by region name, as the document states them (absent values are unknowns)."""
        return dict(self.to_dict().get("materials", {}))

    @property
    def lights(self) -> Dict[str, Dict[str, Any]]:
        """Lights by name, as the document states them."""
        return dict(self.to_dict().get("lights", {}))

    @property
    def lightings(self) -> Dict[str, List[str]]:
        """Lightings by name: the names of their lights."""
        return self._native.lightings

    @property
    def cameras(self) -> Dict[str, Camera]:
        """Cameras by name (from the document or its COLMAP model)."""
        return self._native.cameras

    @property
    def photos(self) -> List[Dict[str, Any]]:
        """Photos: ``file`` (absolute), ``mask``, ``camera``, ``lighting``, ``exposure_scale``."""
        return self._native.photos

    @property
    def mesh(self) -> Dict[str, Any]:
        """All geometry as arrays: ``positions`` (V, 3), ``normals`` (V, 3), ``uvs`` (V, 2 or 0),
        ``triangles`` (T, 3) vertex indices, ``triangle_region`` (T,) indices into
        ``region_names``."""
        return self._native.mesh

    def __repr__(self) -> str:
        return f"<igi.Scene {self.file}: {len(self.cameras)} cameras, {len(self.photos)} photos>"


class Renderer:
    """The path tracer for one lighting of a scene: ``Renderer(scene, "L0").render("cam0")``.

    Renders are linear radiance (the scene's units), the same for the same seed as igi-render's.
    The GIL is released while a render runs."""

    def __init__(self, scene: Scene, lighting: str) -> None:
        self.scene = scene
        self.lighting = lighting
        self._native = _igi._Renderer(scene._native, lighting)

    def render(self, camera: str, spp: int = 64, seed: int = 0, width: int = 0, height: int = 0,
               max_bounces: int = 64, threads: int = 0,
               progress: Optional[ProgressCallback] = None) -> Image:
        """Renders camera ``camera`` (a name of ``scene.cameras``): ``spp`` paths per pixel,
        ``width``/``height`` 0 for the camera's size (another size keeps the field of view).
        The Image's metadata holds the scene, camera, lighting, spp, seed and timing.
        ``progress(label, done, total)`` is called as rows finish; Ctrl-C stops the render."""
        array, info = run_long(
            lambda: self._native.render(camera, spp, seed, width, height, max_bounces, threads),
            progress)
        metadata = {
            "igi:scene": self.scene.file,
            "igi:camera": camera,
            "igi:lighting": self.lighting,
            "igi:spp": spp,
            "igi:seed": seed,
            "igi:units": "radiance W/(sr m^2), linear",
        }
        image = Image(array, metadata)
        image.metadata["render_seconds"] = info["seconds"]
        image.metadata["rays"] = info["rays"]
        return image


def _output_dir(out: Optional[PathLike], prefix: str) -> Tuple[str, Any]:
    """The job's output folder, or a temporary one that lives as long as the returned holder."""
    if out is not None:
        return os.fspath(out), None
    holder = tempfile.TemporaryDirectory(prefix=prefix)
    return holder.name, holder


def _load_result(out: str, holder: Any) -> Scene:
    scene = Scene.load(os.path.join(out, "scene.json"))
    scene._output_holder = holder  # a temporary output folder lives as long as the scene
    return scene


def solve(scene: Scene, out: Optional[PathLike] = None, threads: int = 0,
          progress: Optional[ProgressCallback] = None, **options: Any) -> Tuple[Scene, Summary]:
    """Solves the scene's unknown material values (igi-solve): returns the solved scene and the
    summary, whose :meth:`Summary.to_dict` equals ``OUT/report.json``.

    ``out``: the output folder (scene.json, albedo/, report.json, report.html); None writes to a
    temporary folder kept as long as the returned scene. ``threads``: workers (0 = all cores).
    ``progress(label, done, total)``: called as the stages advance; Ctrl-C stops the solve and
    nothing is written. A region no photo sees is reported in the summary (``regions``, status
    ``unobserved``), where igi-solve exits 3.

    Options (igi-solve's flags, ``-`` written ``_``):
"""
    folder, holder = _output_dir(out, "igi-solve-")
    args = flag_arguments(options)
    report = run_long(lambda: _igi._solve(scene._native, folder, args, threads), progress)
    return _load_result(folder, holder), Summary("SolveSummary", json.loads(report))


def diagnose(scene: Scene, out: Optional[PathLike] = None, threads: int = 0,
             progress: Optional[ProgressCallback] = None,
             **options: Any) -> Tuple[Scene, Summary]:
    """Finds where the simulation and the photos differ, names the physics left out, models it
    and keeps it where held-out pixels improve (igi-diagnose): returns the improved scene and the
    summary, whose :meth:`Summary.to_dict` equals ``OUT/diagnosis.json`` (``steps``: each effect
    tried, kept or not, with its verdict).

    ``out``, ``threads`` and ``progress`` as for :func:`solve`.

    Options (igi-diagnose's flags, ``-`` written ``_``):
"""
    folder, holder = _output_dir(out, "igi-diagnose-")
    args = flag_arguments(options)
    report = run_long(lambda: _igi._diagnose(scene._native, folder, args, threads), progress)
    return _load_result(folder, holder), Summary("DiagnosisSummary", json.loads(report))


def export(scene: Scene, out: PathLike, format: str, **options: Any) -> Summary:
    """Writes a solved scene (every material value known) for another renderer (igi-export):
    ``format`` radiance, mitsuba or gltf, into ``out`` (absent or empty). Returns the summary,
    whose :meth:`Summary.to_dict` equals ``OUT/export_report.json`` (every approximation made,
    with its fitted error).

    Options (igi-export's flags, ``-`` written ``_``):
"""
    args = flag_arguments(dict(options, format=format))
    report = run_long(lambda: _igi._export(scene._native, os.fspath(out), args))
    return Summary("ExportSummary", json.loads(report))


def run(out: PathLike, photos: Optional[PathLike] = None, threads: int = 0,
        progress: Optional[ProgressCallback] = None, **options: Any) -> Summary:
    """The whole chain (igi-run): response, HDR merge, registration, solve, diagnosis and report
    from a folder of photos (``photos``, the layout of ``igi-run --help``), or ``demo=True`` for a
    synthetic capture. Each stage resumes from ``out``. Returns the summary: ``stages`` (stage,
    status, seconds, cpu_seconds), ``report``, ``solved_scene`` and, for a demo, ``demo_summary``
    (``OUT/demo_summary.json``). ``scene`` may be a path or a :class:`Scene`.

    Options (igi-run's flags, ``-`` written ``_``; ``bin_dir`` defaults to the executables beside
    this package):
"""
    if isinstance(options.get("scene"), Scene):
        options["scene"] = options["scene"].file
    options.setdefault("bin_dir", bin_dir())
    args = flag_arguments(options)
    report = run_long(
        lambda: _igi._run(os.fspath(photos) if photos is not None else "", os.fspath(out), args,
                          threads), progress)
    return Summary("RunSummary", json.loads(report))


for _job, _program in ((solve, "igi-solve"), (diagnose, "igi-diagnose"), (export, "igi-export"),
                       (run, "igi-run")):
    _job.__doc__ = (_job.__doc__ or "") + options_help(_program) + "\n"

# Submodules that use Scene, Image and Summary from here.
from . import calib, hdr, synth  # noqa: E402
