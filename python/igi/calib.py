"""Camera calibration (igi-calib): the response curve of a camera from an exposure bracket, and its
intrinsics from photos of a chessboard or ChArUco board — with the files igi-calib writes,
``response.json`` and ``camera.json`` (docs/file-formats.md), written by the same writers.

Keyword options are igi-calib's flags with ``_`` for ``-`` and the same defaults; they are parsed
and checked by the same library code, so a bad value raises :class:`igi.InputError` with the line
igi-calib prints (``--method: nope: must be debevec or robertson``) and nothing is written.
``--lambda`` is ``lambda_`` (``lambda`` is a Python keyword).

Example::

    import igi
    curve = igi.calib.response(["b0.png", "b1.png", "b2.png"], exposures=["1/250", "1/60", "1/15"])
    curve.save("response.json")                 # equal to igi-calib response --out response.json
    linear = curve.linearize(igi.read_image("b1.png"))   # relative exposure E * t per pixel
    camera = igi.calib.intrinsics(sorted(glob.glob("left*.jpg")), board="9x6", square=0.025)
    print(camera.K, camera.distortion, camera.rms_px)
"""

from __future__ import annotations

import json
import logging
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _igi
from ._jobs import ProgressCallback, flag_arguments, run_long

__all__ = ["CameraIntrinsics", "ResponseCurve", "intrinsics", "response"]

PathLike = Union[str, "os.PathLike[str]"]
Exposures = Union[None, str, Sequence[Union[float, str]]]


def _text(value: Any) -> str:
    """A number or choice as its flag's text (floats in their shortest exact form)."""
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _exposure_list(exposures: Exposures) -> str:
    """``exposures`` as ``--exposures``' text: a comma-separated string as it is, a sequence of
    seconds (numbers or ``"1/250"``) joined with commas, None as empty (not given)."""
    if exposures is None:
        return ""
    if isinstance(exposures, str):
        return exposures
    return ",".join(_text(float(t)) if isinstance(t, (int, float, np.number)) else str(t)
                    for t in exposures)


def _bracket(images: Sequence[Any],
             bits: Optional[int]) -> Tuple[List[Any], List[Dict[str, Any]], int]:
    """A bracket for _igi: file paths as text, or arrays with their metadata (an
    :class:`igi.Image`'s dict, whose ``ExposureTime`` gives its time) and the bits float levels
    were quantised to (0 = not given; integer arrays carry theirs)."""
    images = list(images)
    if all(isinstance(image, (str, os.PathLike)) for image in images):
        return [os.fspath(image) for image in images], [], 0
    metadata = [dict(getattr(image, "metadata", {}) or {}) for image in images]
    return [os.fspath(image) if isinstance(image, (str, os.PathLike)) else np.asarray(image)
            for image in images], metadata, int(bits or 0)


class ResponseCurve:
    """A camera response curve (Debevec & Malik's form): per channel and pixel level z,
    ``g[c, z] = ln(E * t)``, the log of the exposure that gives that level, up to one additive
    constant. Values are normalised levels in [0, 1] (level / (levels - 1)); between levels g is
    linear. Make one with :func:`response`, :meth:`load` or :meth:`from_dict`.

    :meth:`to_dict` is response.json as igi-calib writes it; :meth:`save` writes it. ``g`` holds
    the curve at full precision, the file at 1e-7 (so a saved and reloaded curve differs from it
    by at most 5e-8 in ln exposure)."""

    def __init__(self, native: "_igi._ResponseCurve") -> None:
        self._native = native

    @classmethod
    def load(cls, path: PathLike) -> "ResponseCurve":
        """Reads response.json (strict: a wrong key, count or a decreasing g is an
        :class:`igi.InputError` naming the file and key)."""
        return cls(_igi._ResponseCurve.load(os.fspath(path)))

    @classmethod
    def from_dict(cls, document: Dict[str, Any]) -> "ResponseCurve":
        """A curve from a response.json document held as a dict (checked as :meth:`load`)."""
        return cls(_igi._ResponseCurve.from_json(json.dumps(document), "response"))

    def to_dict(self) -> Dict[str, Any]:
        """response.json as igi-calib writes it: ``format``, ``version``, ``method``, ``levels``,
        ``channels``, ``g`` (rounded to 1e-7) and ``info`` (how it was recovered)."""
        return json.loads(self._native.document())

    def save(self, path: PathLike, plot: Optional[PathLike] = None) -> None:
        """Writes response.json to ``path`` atomically (igi-calib's writer); ``plot``: also an SVG
        plot of the curves there (igi-calib's ``--plot``)."""
        self._native.save(os.fspath(path), os.fspath(plot) if plot is not None else "")

    @property
    def method(self) -> str:
        """How the curve was made: ``debevec``, ``robertson``, ``linear``, or another writer's
        text."""
        return self._native.method

    @property
    def levels(self) -> int:
        """The number of pixel levels (256 for 8-bit input, 1024 by default for 16-bit)."""
        return self._native.levels

    @property
    def channels(self) -> List[str]:
        """Channel names (``["R", "G", "B"]``)."""
        return self._native.channels

    @property
    def g(self) -> npt.NDArray[np.float64]:
        """The curve, ``(channels, levels)`` float64: ln exposure of each level (a copy)."""
        return self._native.g

    @property
    def info(self) -> Dict[str, Any]:
        """response.json's ``info``: images, exposures_s, samples, lambda, black, residuals, ...
        (empty when the file has none)."""
        return dict(self.to_dict().get("info", {}))

    @property
    def source(self) -> str:
        """The file the curve was read from; empty when it was made in memory."""
        return self._native.source

    def ln_exposure(self, values: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """g(v) for every value of ``values``, an array ``(..., C)`` of normalised levels with one
        value per channel of the curve (any shape for a one-channel curve); uint8 and uint16
        arrays are levels, scaled to [0, 1] first. Interpolated between levels as igi-hdr does."""
        array = np.asarray(values)
        if array.dtype == np.uint8:
            array = array / 255.0
        elif array.dtype == np.uint16:
            array = array / 65535.0
        return self._native.ln_exposure(array)

    def linearize(self, values: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The relative exposure ``E * t = exp(g(v))`` of pixel values (see :meth:`ln_exposure`):
        linear in the light that reached the pixel, in the curve's arbitrary units. Divide by the
        exposure time for relative radiance."""
        return np.exp(self.ln_exposure(values))

    def __repr__(self) -> str:
        return (f"<igi.calib.ResponseCurve {self.method}: {len(self.channels)} channels, "
                f"{self.levels} levels>")


def response(images: Sequence[Any], exposures: Exposures = None,
             exposure_file: Optional[PathLike] = None, method: str = "debevec",
             lambda_: Union[str, float] = "auto", samples: int = 0, levels: int = 0,
             black: Union[str, float] = "auto", saturated: float = 0.98,
             max_iterations: int = 50, robertson_smoothing: float = 0.0,
             bits: Optional[int] = None,
             progress: Optional[ProgressCallback] = None) -> ResponseCurve:
    """Recovers the camera's response curve from an exposure bracket (igi-calib response).

    ``images``: the bracket, as file paths (8- or 16-bit PNG, TIFF, JPEG, ...) or as arrays
    (uint8 / uint16 levels, or float levels in [0, 1] — as :func:`igi.read_image` gives them —
    with ``bits``, 8 or 16, the quantisation they came from). Its
    :meth:`ResponseCurve.to_dict` equals the response.json igi-calib writes for the same files and
    flags (``info["images"]`` lists the paths as given; arrays are named ``images[i]``).

    Options (igi-calib response's flags, ``-`` written ``_``):
        exposures: exposure times in seconds, a sequence (``[0.004, "1/60"]``) or one
            comma-separated string; excludes exposure_file. Neither: the images' EXIF
            (ExposureTime), for arrays their ``metadata``.
        exposure_file: a file with one exposure time per line (``#`` comments).
        method: ``debevec`` (Debevec & Malik's least squares) or ``robertson``.
        lambda_: Debevec's smoothness weight, or ``"auto"``: per channel the smallest whose curve
            is reproducible to 0.15 % (split-half test).
        samples: Debevec's sample pixels (0 = auto).
        levels: levels of the curve (0 = 256 for 8-bit input, 1024 for 16-bit).
        black: normalised level at or below which a value is unusable, or ``"auto"``: each
            channel's black floor, at least 0.02.
        saturated: normalised level at or above which a value is unusable.
        max_iterations: Robertson's iterations.
        robertson_smoothing: Robertson's second-difference penalty on ln I (0 = none).

    ``progress(label, done, total)`` as for :func:`igi.solve`; Ctrl-C returns once the library
    call does and raises KeyboardInterrupt. Bad input raises :class:`igi.InputError`.
    """
    paths_or_arrays, metadata, bits_ = _bracket(images, bits)
    args = flag_arguments({
        "exposures": _exposure_list(exposures) or None, "exposure_file": exposure_file,
        "method": method, "lambda": _text(lambda_), "samples": samples, "levels": levels,
        "black": _text(black), "saturated": saturated, "max_iterations": max_iterations,
        "robertson_smoothing": robertson_smoothing})
    return ResponseCurve(
        run_long(lambda: _igi._response(paths_or_arrays, metadata, bits_, args), progress))


class CameraIntrinsics:
    """A camera's intrinsics as igi-calib intrinsics measures them (camera.json): the COLMAP
    ``model`` (PINHOLE, OPENCV or FULL_OPENCV), ``width`` x ``height`` pixels, ``params`` in
    COLMAP's order, the RMS reprojection error and the views used and rejected.

    Pixel convention: COLMAP's, the centre of the top-left pixel at (0.5, 0.5) — so ``K``'s
    principal point is OpenCV's plus 0.5 (subtract 0.5 for ``cv2.undistort`` and the like).
    :meth:`to_dict` is camera.json as igi-calib writes it; :meth:`save` writes it."""

    def __init__(self, native: "_igi._CameraFile") -> None:
        self._native = native
        self._document: Dict[str, Any] = json.loads(native.document())

    @classmethod
    def load(cls, path: PathLike) -> "CameraIntrinsics":
        """Reads and validates a camera.json (one holding only vignetting has no ``params``)."""
        return cls(_igi._CameraFile.load(os.fspath(path)))

    def to_dict(self) -> Dict[str, Any]:
        """camera.json as igi-calib writes it (a copy)."""
        return json.loads(json.dumps(self._document))

    def save(self, path: PathLike) -> None:
        """Validates and writes camera.json atomically (igi-calib's writer)."""
        self._native.save(os.fspath(path))

    @property
    def model(self) -> str:
        """COLMAP's camera model name (``OPENCV``)."""
        return str(self._document.get("model", ""))

    @property
    def width(self) -> int:
        """Image width in pixels."""
        return int(self._document["width"])

    @property
    def height(self) -> int:
        """Image height in pixels."""
        return int(self._document["height"])

    @property
    def params(self) -> npt.NDArray[np.float64]:
        """The parameters in COLMAP's order for :attr:`model` (OPENCV: fx, fy, cx, cy, k1, k2,
        p1, p2), pixels."""
        return np.array(self._document.get("params", []), dtype=np.float64)

    @property
    def K(self) -> npt.NDArray[np.float64]:
        """The 3x3 camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (COLMAP's pixel centres)."""
        p = self.params
        if p.size == 0:
            raise _igi.InputError("camera.json holds no intrinsics (vignetting only)")
        one_focal = self.model in ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL")
        fx, fy, cx, cy = (p[0], p[0], p[1], p[2]) if one_focal else (p[0], p[1], p[2], p[3])
        return np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])

    @property
    def distortion(self) -> npt.NDArray[np.float64]:
        """The distortion coefficients in OpenCV's order (k1, k2, p1, p2[, k3, k4, k5, k6]);
        empty for a pinhole."""
        p = self.params
        if self.model == "SIMPLE_RADIAL":
            return np.array([p[3], 0.0, 0.0, 0.0])
        if self.model == "RADIAL":
            return np.array([p[3], p[4], 0.0, 0.0])
        return p[4:].copy() if self.model in ("OPENCV", "FULL_OPENCV") else np.zeros(0)

    @property
    def rms_px(self) -> float:
        """RMS reprojection error over every used view, pixels (-1 = unknown)."""
        return float(self._document.get("rms_px", -1.0))

    @property
    def views(self) -> List[str]:
        """The photos used (file names)."""
        return list(self._document.get("views", []))

    @property
    def per_view_rms_px(self) -> List[float]:
        """RMS reprojection error of each used view, pixels."""
        return list(self._document.get("per_view_rms_px", []))

    @property
    def rejected_views(self) -> List[Dict[str, str]]:
        """Photos where the board was not found: ``{"file", "reason"}`` each."""
        return [dict(v) for v in self._document.get("rejected_views", [])]

    def __repr__(self) -> str:
        return (f"<igi.calib.CameraIntrinsics {self.model} {self.width}x{self.height}, "
                f"RMS {self.rms_px:.4f} px over {len(self.views)} views>")


def intrinsics(images: Sequence[PathLike], board: str, square: float,
               board_type: str = "chessboard", dictionary: str = "DICT_4X4_50",
               marker: float = 0.0, model: str = "OPENCV", fix_aspect_ratio: bool = False,
               zero_tangent_dist: bool = False, fix_principal_point: bool = False,
               subpix_window: int = 11,
               progress: Optional[ProgressCallback] = None) -> CameraIntrinsics:
    """Calibrates focal length, principal point and distortion from photos of a planar board
    (igi-calib intrinsics: OpenCV's corner detection and calibrateCamera, Zhang's method). Its
    :meth:`CameraIntrinsics.to_dict` equals the camera.json igi-calib writes for the same files
    and flags.

    Views where the board is not found are left out and listed in
    :attr:`CameraIntrinsics.rejected_views` (igi-calib writes camera.json and exits 3; here a
    warning goes to the ``igi`` logger). Fewer than 3 views with the board raise
    :class:`igi.Error`; bad options and unreadable photos raise :class:`igi.InputError`.

    Options (igi-calib intrinsics' flags, ``-`` written ``_``):
        board: chessboard: inner corners ``"COLSxROWS"`` (``"9x6"``); charuco: squares X x Y.
        square: side of one square in metres.
        board_type: ``chessboard`` or ``charuco``.
        dictionary: charuco: OpenCV ArUco dictionary.
        marker: charuco: side of a marker in metres.
        model: ``PINHOLE``, ``OPENCV`` or ``FULL_OPENCV``.
        fix_aspect_ratio: constrain fx = fy.
        zero_tangent_dist: constrain p1 = p2 = 0.
        fix_principal_point: keep the principal point at the image centre.
        subpix_window: half window of the sub-pixel corner refinement, pixels.
    """
    paths = [os.fspath(image) for image in images]
    args = flag_arguments({
        "board": board, "square": square, "board_type": board_type, "dictionary": dictionary,
        "marker": marker, "model": model, "fix_aspect_ratio": fix_aspect_ratio,
        "zero_tangent_dist": zero_tangent_dist, "fix_principal_point": fix_principal_point,
        "subpix_window": subpix_window})
    camera = CameraIntrinsics(run_long(lambda: _igi._intrinsics(paths, args), progress))
    for view in camera.rejected_views:
        logging.getLogger("igi").warning("%s: %s; view rejected", view["file"], view["reason"])
    return camera
