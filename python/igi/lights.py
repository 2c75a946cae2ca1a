"""Light emission profiles: IESNA LM-63 photometric files as igi reads them (recon/ies_profile.h).

A spot light of scene.json with ``"profile": {"ies": FILE}`` emits its ``"intensity"`` times the
profile's relative intensity, ``candela(θ, φ) / max_candela``, with θ the angle from the spot's
axis (the file's vertical angle, 0 at nadir) and φ the azimuth about it (the file's horizontal
angle). :meth:`IesProfile.relative` computes that weight with the renderer's own code::

    ies = igi.lights.read_ies("lights/spot.ies")
    ies.vertical_deg, ies.horizontal_deg, ies.candela    # the file's table, (H, V) candela
    ies.intensity(30.0, 0.0)                             # cd, interpolated, numpy broadcasting
    ies.relative(directions, axis=[0, 0, -1])            # (N,) weights of world directions
"""

from __future__ import annotations

import os
from typing import Union

from ._igi import IesProfile

__all__ = ["IesProfile", "read_ies"]


def read_ies(path: Union[str, "os.PathLike[str]"]) -> IesProfile:
    """Reads and validates an IES LM-63 file (1986 to 2019 forms); raises
    :class:`igi.InputError` naming the file, line, field and value on bad input."""
    return IesProfile.read(os.fspath(path))
