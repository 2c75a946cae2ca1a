"""The machinery shared by igi's long jobs (solve, diagnose, export, synthesize, run, render):
keyword options turned into the executables' flags, the job run on a worker thread so that Ctrl-C
and a progress callback reach it, and the summaries."""

from __future__ import annotations

import copy
import os
import shutil
import threading
from typing import Any, Callable, Dict, List, Optional, Sequence

from . import _igi

ProgressCallback = Callable[[str, int, int], None]

# Options whose value is one comma-separated list on the command line; any other list or tuple is
# the flag repeated (--effect a --effect b).
_COMMA_LISTS = {"lamp_position", "unknowns", "photo_lightings", "validation_lightings"}


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return str(value)


def flag_arguments(options: Dict[str, Any]) -> List[str]:
    """Keyword options as an executable's flags: ``pixel_stride=2`` is ``--pixel-stride=2``;
    ``True``/``False`` are ``true``/``false``; a list is the flag repeated, or one comma-separated
    value for the options that take a list (``unknowns``, ``photo_lightings``, ...); ``None`` leaves
    the option at its default."""
    args: List[str] = []
    for key, value in options.items():
        if value is None:
            continue
        flag = "--" + key.replace("_", "-")
        if isinstance(value, (list, tuple)):
            if key in _COMMA_LISTS:
                args.append(flag + "=" + ",".join(_text(v) for v in value))
            else:
                args.extend(flag + "=" + _text(v) for v in value)
        else:
            args.append(flag + "=" + _text(value))
    return args


def options_help(program: str) -> str:
    """The keyword options of a job, as its executable's flags describe them."""
    lines = []
    for flag, default, description in _igi._options(program):
        name = flag[2:].replace("-", "_")
        lines.append(f"    {name}" + (f" (default {default})" if default else "") +
                     f": {description}")
    return "\n".join(lines)


def run_long(function: Callable[[], Any], progress: Optional[ProgressCallback] = None) -> Any:
    """Runs ``function`` (a call into igi's libraries that releases the GIL) on a worker thread
    while this thread waits, so that Ctrl-C reaches Python: it asks the job to stop at its next
    unit of work (nothing partial is written) and raises KeyboardInterrupt once it has. While it
    runs, ``progress(label, done, total)`` is called about ten times a second per stage; an
    exception the callback raises stops the job and is raised here."""
    result: Dict[str, Any] = {}

    def target() -> None:
        try:
            result["value"] = function()
        except BaseException as error:  # handed to the waiting thread
            result["error"] = error

    _igi._clear_cancel()
    _igi._set_progress(progress)
    worker = threading.Thread(target=target, name="igi-job", daemon=True)
    interrupted = False
    try:
        worker.start()
        while worker.is_alive():
            try:
                worker.join(0.1)
            except KeyboardInterrupt:
                interrupted = True
                _igi._request_cancel()
    finally:
        if worker.is_alive():
            worker.join()
        _igi._set_progress(None)
        _igi._clear_cancel()
    callback_error = _igi._take_progress_error()
    if callback_error is not None:
        raise callback_error
    if interrupted:
        raise KeyboardInterrupt
    if "error" in result:
        raise result["error"]
    return result.get("value")


class Summary:
    """A job's report. :meth:`to_dict` is the JSON report the executable writes (report.json,
    diagnosis.json, export_report.json); its top-level keys read as attributes
    (``summary.regions``)."""

    def __init__(self, kind: str, report: Dict[str, Any]) -> None:
        self._kind = kind
        self._report = report

    def to_dict(self) -> Dict[str, Any]:
        """The report as a dict (a copy)."""
        return copy.deepcopy(self._report)

    def keys(self) -> Sequence[str]:
        """The report's top-level keys."""
        return list(self._report.keys())

    def __getattr__(self, name: str) -> Any:
        report = self.__dict__.get("_report", {})
        if name in report:
            return report[name]
        raise AttributeError(f"{self.__dict__.get('_kind', 'Summary')} has no {name!r}")

    def __repr__(self) -> str:
        return f"<igi.{self._kind}: {', '.join(list(self._report.keys())[:8])}, ...>"


def bin_dir() -> str:
    """The folder of igi's executables (igi-run runs them): beside the package in a build tree
    (build/python/igi -> build/bin) or an installed prefix (PREFIX/lib/python3/dist-packages/igi ->
    PREFIX/bin), else the one on PATH."""
    here = os.path.dirname(os.path.abspath(__file__))
    for candidate in (os.path.join(here, "..", "..", "bin"),
                      os.path.join(here, "..", "..", "..", "..", "bin")):
        if os.path.isfile(os.path.join(candidate, "igi-solve")):
            return os.path.normpath(candidate)
    found = shutil.which("igi-solve")
    if found:
        return os.path.dirname(found)
    raise _igi.Error("igi's executables (igi-solve, ...) are neither beside the package nor on "
                     "PATH: pass bin_dir")
