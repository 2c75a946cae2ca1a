"""Synthetic captures with known truth (igi-synth): a room rendered by igi's path tracer, its
photos, scene.json and truth.json, optionally with effects the photos show and scene.json does
not declare — the data igi's own tests and igi-diagnose's proofs start from."""

from __future__ import annotations

import json
import os
from typing import Any, Optional, Tuple

from . import _igi
from . import Scene, Summary
from ._jobs import ProgressCallback, flag_arguments, options_help, run_long

__all__ = ["synthesize"]


def synthesize(out: "os.PathLike[str] | str", threads: int = 0,
               progress: Optional[ProgressCallback] = None,
               **options: Any) -> Tuple[Scene, Summary]:
    """Writes a synthetic capture into ``out`` (empty or absent, or ``overwrite=True``) and
    returns its scene and a summary: ``photos`` and ``validation`` (file names), ``saturated_pixels``,
    ``seconds`` and ``truth`` (truth.json as a dict: the true materials, lights and effects).
    Deterministic for a ``seed``. ``effect=["vignetting:k1=-0.3", ...]`` hides effects in the
    photos.

    Options (igi-synth's flags, ``-`` written ``_``):
"""
    args = flag_arguments(dict(options, out=os.fspath(out)))
    report = run_long(lambda: _igi._synthesize(args, threads), progress)
    with open(os.path.join(os.fspath(out), "truth.json"), encoding="utf-8") as f:
        report["truth"] = json.load(f)
    return Scene.load(os.path.join(os.fspath(out), "scene.json")), Summary("SynthSummary", report)


synthesize.__doc__ = (synthesize.__doc__ or "") + options_help("igi-synth") + "\n"
