"""igi's reflectance models on numpy arrays, to compare with other renderers.

The functions evaluate and sample exactly what igi's renderer and solver use
(solver/render/brdf.h and microfacet.h), looping in C++ with the GIL released.

Materials are dicts shaped like a ``materials`` entry of scene.json and are read by the scene
loader's rules, so every model igi has is available (:data:`MODELS`: lambert, the Ward models,
their ``*_fresnel`` forms, ggx, beckmann and the anisotropic forms) with either diffuse term
(``"diffuse"``: lambert, oren_nayar with ``"sigma"``, coated)::

    {"brdf": "ward", "rho_d": [0.5, 0.4, 0.3], "rho_s": 0.04, "alpha": 0.1}
    {"brdf": "ggx_aniso", "rho_d": 0.2, "rho_s": 0.9, "alpha_x": 0.05, "alpha_y": 0.3}

Every value the model needs must be there; a bad or missing value raises :class:`igi.InputError`
whose message names the key (``material: rho_s: 1.5: must be in [0, 1]``). ``rho_d_map``
(a texture) is refused: give ``rho_d``. ``emitter`` and ``black`` have no BRDF.

Directions are unit vectors, arrays ``(N, 3)`` or one ``(3,)`` vector standing for every row,
both leaving the surface: ``wi`` toward the light, ``wo`` toward the viewer. Without ``normal``
they are in the local shading frame: z the normal, x the tangent (the direction of ``alpha_x``),
y = z × x; a material's ``"tangent"`` is then not needed and not read. With ``normal`` (and
optionally ``tangent``) they are world directions, and each row's frame is built from its normal
and tangent as the renderer builds it (the tangent made orthogonal to the normal; the material's
``"tangent"`` when no ``tangent`` is given; any tangent for an isotropic model).

Values are the BRDF f(wi, wo) in 1/sr, RGB, **without** the cosine factor (multiply by
``wi[..., 2]`` in the local frame for f·cosθi). f is one-sided: 0 when wi or wo is at or below the
surface. All models are reciprocal: f(wi, wo) = f(wo, wi).
"""

from __future__ import annotations

import json
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _igi
from ._igi import InputError

__all__ = ["MODELS", "albedo", "evaluate", "pdf", "sample"]

MODELS: Tuple[str, ...] = tuple(_igi._brdf_models())
"""The reflectance models' names (scene.json ``"brdf"`` values that have a BRDF)."""


def _input_error(line: str) -> InputError:
    error = InputError(line)
    error.problems = [line]
    return error


def _material_json(material: Dict[str, Any]) -> str:
    """The material as JSON text; numpy arrays and numbers become JSON lists and numbers."""

    def plain(value: Any) -> Any:
        if isinstance(value, np.ndarray):
            return value.tolist()
        if isinstance(value, np.generic):
            return value.item()
        raise _input_error(f"material: {value!r}: must be JSON data (numbers, strings, lists)")

    return json.dumps(material, default=plain)


def _rows(**vectors: Any) -> Tuple[Dict[str, Optional[np.ndarray]], bool]:
    """Each given vector array as a C-contiguous float64 ``(N, 3)`` array, all broadcast to one N;
    and whether every one was a single ``(3,)`` vector. None stays None."""
    arrays = {}
    for name, value in vectors.items():
        if value is None:
            continue
        array = np.asarray(value, dtype=np.float64)
        if array.ndim not in (1, 2) or array.shape[-1] != 3:
            raise _input_error(f"{name}: shape {array.shape}: must be (3,) or (N, 3)")
        arrays[name] = array
    single = all(a.ndim == 1 for a in arrays.values())
    try:
        broadcast = np.broadcast_arrays(*(np.atleast_2d(a) for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{k} {a.shape}" for k, a in arrays.items())
        raise _input_error(f"directions: {shapes}: must have the same number of rows N") from None
    out: Dict[str, Optional[np.ndarray]] = {name: None for name in vectors}
    out.update({name: np.ascontiguousarray(a) for name, a in zip(arrays, broadcast)})
    return out, single


def evaluate(material: Dict[str, Any], wi: Any, wo: Any, normal: Any = None,
             tangent: Any = None) -> np.ndarray:
    """The BRDF f(wi, wo) (1/sr, RGB, without the cosine): ``(N, 3)`` float64, or ``(3,)`` when
    every direction given is one ``(3,)`` vector. See the module's help for the frames."""
    rows, single = _rows(wi=wi, wo=wo, normal=normal, tangent=tangent)
    f = _igi._brdf_eval(_material_json(material), rows["wi"], rows["wo"], rows["normal"],
                        rows["tangent"])
    return f[0] if single else f


def pdf(material: Dict[str, Any], wi: Any, wo: Any, normal: Any = None,
        tangent: Any = None) -> np.ndarray:
    """The density (per steradian, over the whole sphere) with which :func:`sample` draws wi
    given wo: ``(N,)`` float64 (a float for single vectors). 0 when wo is at or below the
    surface; below the surface it is the density of the draws that land there."""
    rows, single = _rows(wi=wi, wo=wo, normal=normal, tangent=tangent)
    p = _igi._brdf_pdf(_material_json(material), rows["wi"], rows["wo"], rows["normal"],
                       rows["tangent"])
    return float(p[0]) if single else p


def sample(material: Dict[str, Any], wo: Any, u: Any, normal: Any = None,
           tangent: Any = None) -> Dict[str, np.ndarray]:
    """Draws wi for each wo as the renderer does, from uniform numbers ``u`` ``(N, 3)`` in [0, 1)
    (the first picks the lobe, the other two the direction). Returns a dict of arrays:

    - ``wi`` ``(N, 3)``: the drawn direction, in the frame wo was given in;
    - ``f`` ``(N, 3)``: f(wi, wo);
    - ``pdf`` ``(N,)``: :func:`pdf` at wi;
    - ``weight`` ``(N, 3)``: f·cosθi/pdf, 0 for an invalid draw;
    - ``lobe`` ``(N,)`` int8: 0 none (failed), 1 diffuse, 2 specular;
    - ``valid`` ``(N,)`` bool: pdf > 0 and wi above the surface.
    """
    rows, _ = _rows(wo=wo, u=u, normal=normal, tangent=tangent)
    return _igi._brdf_sample(_material_json(material), rows["wo"], rows["u"], rows["normal"],
                             rows["tangent"])


def albedo(material: Dict[str, Any], wo: Any, samples: int = 4096, seed: int = 0,
           normal: Any = None, tangent: Any = None) -> np.ndarray:
    """The directional albedo ∫ f(wi, wo) cosθi dwi toward each wo, RGB, estimated by
    importance sampling: the mean of :func:`sample`'s weights over ``samples`` draws from
    ``numpy.random.default_rng(seed)``. ``(N, 3)``, or ``(3,)`` for one vector. Its standard error
    falls as 1/√samples."""
    if samples < 1:
        raise _input_error(f"samples: {samples}: must be >= 1")
    rows, single = _rows(wo=wo, normal=normal, tangent=tangent)
    wo_rows = rows["wo"]
    assert wo_rows is not None
    n = wo_rows.shape[0]
    rng = np.random.default_rng(seed)
    repeat = lambda a: None if a is None else np.repeat(a, samples, axis=0)  # noqa: E731
    drawn = sample(material, repeat(wo_rows), rng.random((n * samples, 3)),
                   repeat(rows["normal"]), repeat(rows["tangent"]))
    mean = drawn["weight"].reshape(n, samples, 3).mean(axis=1)
    return mean[0] if single else mean
