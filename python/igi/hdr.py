"""High dynamic range (igi-hdr): exposure brackets merged into linear radiance maps, and camera raw
files decoded linearly through LibRaw.

Keyword options are igi-hdr's flags with ``_`` for ``-`` and the same defaults, parsed and
checked by the same library code: a bad value raises :class:`igi.InputError` with the line igi-hdr
prints (``--weighting: nope: must be noise or hat``) and nothing is written.

Example::

    import igi
    curve = igi.calib.response(paths, exposure_file="times.txt")
    merged = igi.hdr.merge(paths, exposure_file="times.txt", response=curve, out="radiance.exr")
    radiance, mask = merged.radiance, merged.mask      # linear radiance; 1 = good pixel
    raw = igi.hdr.decode_raw("IMG_0001.CR2")           # linear RGB, 1 = white level
    print(raw.metadata["igi:camera"], raw.metadata["ExposureTime"])
"""

from __future__ import annotations

import os
from typing import Any, NamedTuple, Optional, Sequence, Union

from . import Image, _igi
from ._jobs import ProgressCallback, flag_arguments, run_long
from .calib import Exposures, ResponseCurve, _bracket, _exposure_list

__all__ = ["MergeResult", "decode_raw", "merge"]

PathLike = Union[str, "os.PathLike[str]"]


class MergeResult(NamedTuple):
    """What :func:`merge` returns: the radiance map and its mask, with the counts igi-hdr
    prints."""

    radiance: Image
    """Linear radiance, float32 ``(H, W, C)``, in the response's units per second (relative, not
    absolute); metadata ``igi:response`` and ``igi:weighting`` as in igi-hdr's EXR."""
    mask: Image
    """``(H, W, 1)``: 1 = good, 0 = saturated or black in every exposure (in some channel)."""
    saturated_pixels: int
    """Pixels saturated in every exposure (they hold the bound the shortest exposure gives)."""
    black_pixels: int
    """Pixels black in every exposure (they hold the bound the longest exposure gives)."""


def merge(images: Sequence[Any], exposures: Exposures = None,
          exposure_file: Optional[PathLike] = None,
          response: Union[None, ResponseCurve, PathLike] = None, linear: bool = False,
          weighting: str = "noise", shot_noise: float = 1.0 / 4000,
          read_noise: float = 1.0 / 2000, black: Optional[float] = None,
          saturated: float = 0.98, align: bool = False, camera: Optional[PathLike] = None,
          colour: Optional[PathLike] = None, raw_white_balance: str = "camera",
          raw_color: str = "srgb", half_size: bool = False, band_rows: int = 64,
          whole_images: bool = False, out: Optional[PathLike] = None,
          mask_out: Optional[PathLike] = None, bits: Optional[int] = None, threads: int = 0,
          progress: Optional[ProgressCallback] = None) -> MergeResult:
    """Merges an exposure bracket into a linear radiance map (igi-hdr).

    ``images``: file paths — 8/16-bit images, or camera raw files (DNG, CR2, NEF, ...: decoded
    linearly, no response needed) — or arrays: uint8 / uint16 levels, or float levels in [0, 1]
    as :func:`igi.read_image` gives them, with ``bits``, 8 or 16, the quantisation they came
    from; an :class:`igi.Image`'s ``ExposureTime`` gives its time.

    ``out``: also write the radiance map there (OpenEXR, float) and its mask (``mask_out``, by
    default OUT_mask.png) as igi-hdr does: for files with a known response band by band
    (``band_rows`` rows of every frame in memory) unless ``whole_images``. Either way the values
    equal igi-hdr's for the same inputs bit for bit. Without ``out`` every frame is held whole in
    memory and nothing is written (but ``mask_out``, when given).

    Options (igi-hdr's flags, ``-`` written ``_``):
        exposures: exposure times in seconds, a sequence or one comma-separated string; excludes
            exposure_file. Neither: the files' EXIF or raw metadata, arrays' ``metadata``.
        exposure_file: one exposure time per line.
        response: a :class:`igi.calib.ResponseCurve` or a response.json. None: ``linear``, or a
            Debevec curve recovered from the bracket itself. Raw files take none.
        linear: non-raw input is linear (no response needed).
        weighting: ``noise`` (inverse variance) or ``hat`` (Debevec & Malik).
        shot_noise: variance per unit signal (full scale 1).
        read_noise: read noise standard deviation, full scale 1.
        black: normalised level at or below which a value is black (None: 0.02; raw input 0).
        saturated: normalised level at or above which a value is saturated.
        align: align hand-held brackets (median threshold bitmaps).
        camera: camera.json whose vignetting (igi-calib vignetting) is divided out.
        colour: colour.json (igi-calib colour): camera RGB -> linear sRGB.
        raw_white_balance: ``camera`` or ``none``.
        raw_color: ``srgb`` (linear) or ``raw`` (camera RGB).
        half_size: raw: 2x2 binning, no demosaicing.
        band_rows: rows of every frame held in memory when merging band by band.
        whole_images: load every frame whole instead of merging band by band.

    ``threads``: workers (0 = all cores). The GIL is released while the merge runs;
    ``progress(label, done, total)`` sees its rows and Ctrl-C stops it (nothing written).
    """
    paths_or_arrays, metadata, bits_ = _bracket(images, bits)
    curve = response._native if isinstance(response, ResponseCurve) else None
    args = flag_arguments({
        "exposures": _exposure_list(exposures) or None, "exposure_file": exposure_file,
        "response": None if curve is not None else response, "linear": linear,
        "weighting": weighting, "shot_noise": shot_noise, "read_noise": read_noise,
        "black": black, "saturated": saturated, "align": align, "camera": camera,
        "colour": colour, "raw_white_balance": raw_white_balance, "raw_color": raw_color,
        "half_size": half_size, "band_rows": band_rows, "whole_images": whole_images,
        "out": out, "mask_out": mask_out})
    radiance, radiance_metadata, mask, counts = run_long(
        lambda: _igi._merge(paths_or_arrays, metadata, bits_, curve, args, int(threads)),
        progress)
    return MergeResult(Image(radiance, radiance_metadata), Image(mask),
                       int(counts["saturated_pixels"]), int(counts["black_pixels"]))


def decode_raw(path: PathLike, raw_white_balance: str = "camera", raw_color: str = "srgb",
               half_size: bool = False) -> Image:
    """Decodes a camera raw file (DNG, CR2, NEF, ARW, KDC, ...) linearly through LibRaw, as igi-hdr
    and igi-calib do: the black level subtracted, scaled so that the white level is 1 and clipped
    there, no gamma, no auto-brightening; LibRaw's AHD demosaicing (or 2x2 binning with
    ``half_size``). Returns linear RGB, float32 ``(H, W, 3)`` — linear in scene radiance.

    Metadata: ``ExposureTime`` (s), ``Exif:ISOSpeedRatings``, ``FNumber``, ``Make``, ``Model``
    where the file gives them, and ``igi:camera`` ("Make Model"), ``igi:black_level`` and
    ``igi:white_level`` (raw counts, as the file states them), ``igi:raw_bits``,
    ``igi:raw_white_balance``, ``igi:raw_color``, ``igi:units``.

    Options (igi-hdr's flags): raw_white_balance ``camera`` (the camera's multipliers) or
    ``none``; raw_color ``srgb`` (linear sRGB, LibRaw's matrix) or ``raw`` (camera RGB);
    half_size. A file LibRaw cannot decode raises :class:`igi.InputError`.
    """
    array, metadata, info = run_long(
        lambda: _igi._decode_raw(os.fspath(path), raw_white_balance, raw_color, bool(half_size)))
    metadata.update({
        "igi:camera": info["camera"],
        "igi:black_level": info["black_level"],
        "igi:white_level": info["white_level"],
        "igi:raw_bits": info["raw_bits"],
        "igi:raw_white_balance": raw_white_balance,
        "igi:raw_color": raw_color,
        "igi:units": "linear, 1 = white level",
    })
    return Image(array, metadata)
