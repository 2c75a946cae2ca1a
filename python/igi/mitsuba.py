"""A bridge to Mitsuba 3: a scene's lighting as a ``mitsuba.load_dict`` dictionary.

:func:`scene_dict` builds the dictionary from the same description of Mitsuba objects as
``igi-export --format mitsuba`` builds its ``scene_<L>.xml`` (solver/export/export_mitsuba.h
documents the mapping and its approximations), so every object, property and value of the XML
is in the dict. It is plain data — it needs no mitsuba to build or to save as JSON:

- ``{"type": "scene", "integrator": {...}, ID: {"type": PLUGIN, PROPERTY: VALUE, ...}, ...}``,
  one entry per camera (a ``perspective`` sensor), per region (its ``bsdf.<region>`` BSDF and
  its ``obj`` shape) and per light of the lighting, keyed by the XML's ids;
- rgb values as ``{"type": "rgb", "value": [r, g, b]}``, points and vectors as ``[x, y, z]``;
- ``to_world`` as ``{"type": "transform", "matrix": M}``, M the 4x4 row-major matrix of
  Mitsuba's ``look_at`` of the XML — :func:`to_mitsuba` turns these into
  ``mitsuba.ScalarTransform4f``;
- a shape's BSDF as ``"bsdf": {"type": "ref", "id": "bsdf.<region>"}``;
- mesh and texture filenames absolute, in the folder given (written there).

With Mitsuba 3 installed::

    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    d = igi.mitsuba.scene_dict(scene, "L0", "mitsuba_meshes")
    image = mi.render(mi.load_dict(igi.mitsuba.to_mitsuba(d)), sensor=0)
"""

from __future__ import annotations

import copy
import json
import os
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Union

from . import _igi

if TYPE_CHECKING:
    from . import Scene

__all__ = ["SceneDict", "scene_dict", "to_mitsuba"]


class SceneDict(dict):  # type: ignore[type-arg]
    """A ``load_dict`` dictionary (a plain dict) that also carries what the conversion did:
    ``files`` (written, relative to the output folder) and ``approximations`` (dicts of
    ``item``, ``description`` and ``relative_error``, as igi-export's export_report.json)."""

    files: List[str]
    approximations: List[Dict[str, Any]]


def scene_dict(scene: "Scene", lighting: str, out_dir: Union[str, "os.PathLike[str]"],
               spp: int = 256) -> SceneDict:
    """The Mitsuba 3 scene of lighting ``lighting`` of ``scene`` (loaded with its geometry and
    every material value) as a ``load_dict`` dictionary. The meshes and textures it names are
    written into ``out_dir`` (created when absent; files of the same names are replaced, each
    atomically). ``spp``: the sensors' samples per pixel. Raises :class:`igi.InputError` for an
    unknown lighting, an incomplete material or a bad ``spp``."""
    text, report = _igi._mitsuba_scene_dict(scene._native, lighting, os.fspath(out_dir), spp)
    out = SceneDict(json.loads(text))
    info = json.loads(report)
    out.files = list(info["files"])
    out.approximations = list(info["approximations"])
    return out


def _is_transform(value: Any) -> bool:
    return isinstance(value, dict) and value.get("type") == "transform" and "matrix" in value


def to_mitsuba(d: Dict[str, Any], mi: Optional[Any] = None) -> Dict[str, Any]:
    """A copy of ``d`` (a :func:`scene_dict`) ready for ``mitsuba.load_dict``: every
    ``{"type": "transform", "matrix": M}`` becomes ``mi.ScalarTransform4f(mi.ScalarMatrix4f(M))``.
    ``mi``: the mitsuba module (imported when None; set a variant first). Raises ImportError
    when mitsuba is not importable."""
    if mi is None:
        import mitsuba as mi  # noqa: F811  (optional dependency, imported on use)

    def convert(value: Any) -> Any:
        if _is_transform(value):
            return mi.ScalarTransform4f(mi.ScalarMatrix4f(value["matrix"]))
        if isinstance(value, dict):
            return {key: convert(item) for key, item in value.items()}
        return copy.deepcopy(value)

    return convert(dict(d))
