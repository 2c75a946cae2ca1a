"""COLMAP sparse models: cameras, images and 3D points, read from and written to COLMAP 3.8's TXT
and BIN files, and the points exported as COLMAP's PLY.

Names follow pycolmap where it has them (:class:`Reconstruction`, ``cameras``, ``images``,
``points3D``, ``write_text``, ``write_binary``, ``export_PLY``, ``find_image_with_name``) and
COLMAP's ``scripts/python/read_write_model.py`` for the record fields (``qvec``, ``tvec``, ``xys``,
``point3D_ids``). The frames are COLMAP's:

- An image's pose is ``cam_from_world``: ``x_cam = R(qvec) @ x_world + tvec``.
- ``qvec`` is the rotation as a unit quaternion in the order **(w, x, y, z)**, as COLMAP's files
  store it. pycolmap's ``Rotation3d.quat`` is (x, y, z, w): reorder when passing poses between
  the two.
- Camera x right, y down, z forward; the centre of the top-left pixel is (0.5, 0.5).
- Camera ``params`` are in COLMAP's order for the model (PINHOLE: fx, fy, cx, cy), in pixels.

A model is validated (known camera models, parameter counts, unit quaternions, unique non-empty
image names, every id it refers to present) when it is read and before anything is written;
problems raise :class:`igi.InputError` with one line per problem in :attr:`~igi.InputError.problems`
(``FILE: line N: VALUE: RULE`` for a file read), and nothing is written. Each file is written
atomically.

Example::

    from igi import colmap
    rec = colmap.Reconstruction.read("sparse/0")      # TXT or BIN
    image = rec.find_image_with_name("IMG_0001.JPG")
    print(image.qvec, image.center, rec.cameras[image.camera_id].params)
    rec.write_binary("sparse_bin")
    rec.export_PLY("points.ply")
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _igi

__all__ = ["CAMERA_MODELS", "Camera", "Image", "Points3D", "Reconstruction"]

PathLike = Union[str, "os.PathLike[str]"]

CAMERA_MODELS: Dict[str, int] = dict(_igi._colmap_camera_models())
"""COLMAP 3.8's camera models in id order (SIMPLE_PINHOLE = 0 ... THIN_PRISM_FISHEYE = 10): the
number of ``params`` each takes."""


def _doubles(value: Any, shape: Tuple[int, ...]) -> npt.NDArray[np.float64]:
    """``value`` as a float64 array reshaped to ``shape`` (-1 for any length)."""
    return np.array(value, dtype=np.float64).reshape(shape)


class Camera:
    """A camera: COLMAP model name, image size in pixels and parameters in COLMAP's order for
    the model (focal lengths and principal point in pixels, top-left pixel centre at 0.5)."""

    def __init__(self, camera_id: int, model: str, width: int, height: int,
                 params: npt.ArrayLike) -> None:
        self.camera_id = int(camera_id)
        self.model = str(model)
        self.width = int(width)
        self.height = int(height)
        self.params: npt.NDArray[np.float64] = _doubles(params, (-1,))

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Camera) and self.camera_id == other.camera_id
                and self.model == other.model and self.width == other.width
                and self.height == other.height and np.array_equal(self.params, other.params))

    def __repr__(self) -> str:
        return (f"Camera(camera_id={self.camera_id}, model={self.model!r}, width={self.width}, "
                f"height={self.height}, params={self.params.tolist()})")


class Image:
    """A posed photo: ``qvec`` and ``tvec`` of ``cam_from_world``, the id of its camera, its
    file name relative to the image folder, and its 2D points: ``xys`` (N, 2) pixels and
    ``point3D_ids`` (N,) int64, -1 where a 2D point has no 3D point (``point3D_ids`` defaults to
    all -1).

    ``qvec`` is (w, x, y, z) as COLMAP's files store it, not (x, y, z, w) as pycolmap's
    ``Rotation3d.quat``. Arguments are ``Image(image_id, name, camera_id, qvec, tvec, xys,
    point3D_ids)``; the pose defaults to the identity."""

    def __init__(self, image_id: int, name: str, camera_id: int,
                 qvec: npt.ArrayLike = (1.0, 0.0, 0.0, 0.0),
                 tvec: npt.ArrayLike = (0.0, 0.0, 0.0),
                 xys: Optional[npt.ArrayLike] = None,
                 point3D_ids: Optional[npt.ArrayLike] = None) -> None:
        self.image_id = int(image_id)
        self.name = str(name)
        self.camera_id = int(camera_id)
        self.qvec: npt.NDArray[np.float64] = _doubles(qvec, (4,))
        self.tvec: npt.NDArray[np.float64] = _doubles(tvec, (3,))
        self.xys: npt.NDArray[np.float64] = _doubles([] if xys is None else xys, (-1, 2))
        if point3D_ids is None:
            point3D_ids = np.full(len(self.xys), -1, dtype=np.int64)
        self.point3D_ids: npt.NDArray[np.int64] = np.array(point3D_ids, dtype=np.int64).reshape(-1)

    @property
    def R(self) -> npt.NDArray[np.float64]:
        """cam_from_world's rotation matrix (3, 3) from ``qvec``: ``x_cam = R @ x_world + tvec``."""
        w, x, y, z = self.qvec / np.linalg.norm(self.qvec)
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ])

    @property
    def center(self) -> npt.NDArray[np.float64]:
        """The camera centre in the world frame, ``-R.T @ tvec`` (pycolmap's
        ``projection_center()``)."""
        return -self.R.T @ self.tvec

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Image) and self.image_id == other.image_id
                and self.name == other.name and self.camera_id == other.camera_id
                and np.array_equal(self.qvec, other.qvec)
                and np.array_equal(self.tvec, other.tvec)
                and np.array_equal(self.xys, other.xys)
                and np.array_equal(self.point3D_ids, other.point3D_ids))

    def __repr__(self) -> str:
        return (f"Image(image_id={self.image_id}, name={self.name!r}, "
                f"camera_id={self.camera_id}, qvec={self.qvec.tolist()}, "
                f"tvec={self.tvec.tolist()}, {len(self.xys)} points2D)")


class Points3D:
    """The 3D points as arrays, one row per point in id order:

    - ``ids`` (P,) int64 (COLMAP's point ids, below 2**63),
    - ``xyz`` (P, 3) float64 world coordinates,
    - ``rgb`` (P, 3) uint8 colour,
    - ``error`` (P,) float64 mean reprojection error in pixels (-1: unknown),
    - tracks in compressed rows: point ``i`` is seen at the rows
      ``track[track_offsets[i]:track_offsets[i + 1]]`` of ``track`` (T, 2) uint32, each
      ``(image_id, point2D_idx)``; ``track_offsets`` is (P + 1,) int64.

    Build one from per-point tracks with :meth:`from_tracks`.
    """

    def __init__(self, ids: npt.ArrayLike = (), xyz: npt.ArrayLike = (),
                 rgb: npt.ArrayLike = (), error: npt.ArrayLike = (),
                 track_offsets: Optional[npt.ArrayLike] = None,
                 track: npt.ArrayLike = ()) -> None:
        self.ids: npt.NDArray[np.int64] = np.array(ids, dtype=np.int64).reshape(-1)
        self.xyz: npt.NDArray[np.float64] = _doubles(xyz, (-1, 3))
        self.rgb: npt.NDArray[np.uint8] = _checked_uint8(rgb).reshape(-1, 3)
        self.error: npt.NDArray[np.float64] = _doubles(error, (-1,))
        if track_offsets is None:
            track_offsets = np.zeros(len(self.ids) + 1, dtype=np.int64)
        self.track_offsets: npt.NDArray[np.int64] = np.array(track_offsets,
                                                             dtype=np.int64).reshape(-1)
        self.track: npt.NDArray[np.uint32] = np.array(track, dtype=np.uint32).reshape(-1, 2)

    @classmethod
    def from_tracks(cls, ids: npt.ArrayLike, xyz: npt.ArrayLike, rgb: npt.ArrayLike,
                    error: npt.ArrayLike, tracks: List[npt.ArrayLike]) -> "Points3D":
        """Points from one track per point, each a sequence of ``(image_id, point2D_idx)``."""
        rows = [np.array(t, dtype=np.uint32).reshape(-1, 2) for t in tracks]
        offsets = np.zeros(len(rows) + 1, dtype=np.int64)
        offsets[1:] = np.cumsum([len(r) for r in rows])
        track = np.concatenate(rows) if rows else np.zeros((0, 2), dtype=np.uint32)
        return cls(ids, xyz, rgb, error, offsets, track)

    def track_of(self, index: int) -> npt.NDArray[np.uint32]:
        """The track (L, 2) of the point in row ``index`` (not its id): ``(image_id,
        point2D_idx)`` rows."""
        return self.track[self.track_offsets[index]:self.track_offsets[index + 1]]

    def tracks(self) -> List[npt.NDArray[np.uint32]]:
        """Every point's track, in row order (see :meth:`track_of`)."""
        return [self.track_of(i) for i in range(len(self))]

    def index_of(self, point3D_ids: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """The rows of the points with these ids, -1 for an id not present (as for a 2D point
        without a 3D point): with ``rows = index_of(image.point3D_ids)``, the image's 3D points
        are ``xyz[rows[rows >= 0]]``."""
        wanted = np.asarray(point3D_ids, dtype=np.int64)
        if len(self.ids) == 0:
            return np.full(wanted.shape, -1, dtype=np.int64)
        order = np.argsort(self.ids, kind="stable")
        rows = order[np.minimum(np.searchsorted(self.ids, wanted, sorter=order), len(order) - 1)]
        return np.where(self.ids[rows] == wanted, rows, -1).astype(np.int64)

    def __len__(self) -> int:
        return len(self.ids)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Points3D) and all(
            np.array_equal(getattr(self, name), getattr(other, name))
            for name in ("ids", "xyz", "rgb", "error", "track_offsets", "track"))

    def __repr__(self) -> str:
        return f"Points3D({len(self)} points, {len(self.track)} observations)"


def _checked_uint8(value: Any) -> npt.NDArray[np.uint8]:
    """Colours as uint8, refusing values outside [0, 255] (:class:`igi.InputError`) rather than
    wrapping them."""
    array = np.asarray(value)
    if array.dtype != np.uint8 and array.size and (array.min() < 0 or array.max() > 255):
        line = f"points3D.rgb: {array.min()}..{array.max()}: must be in [0, 255]"
        error = _igi.InputError(line)
        error.problems = [line]
        raise error
    return array.astype(np.uint8)


class Reconstruction:
    """A COLMAP sparse model: ``cameras`` and ``images`` as dicts by id, ``points3D`` as
    :class:`Points3D` arrays. Edit them freely; the model is validated when written.

    ``Reconstruction(path)`` reads a model folder, as ``Reconstruction.read(path)``;
    ``Reconstruction()`` is an empty model to fill in.
    """

    def __init__(self, path: Optional[PathLike] = None) -> None:
        self.cameras: Dict[int, Camera] = {}
        self.images: Dict[int, Image] = {}
        self.points3D: Points3D = Points3D()
        if path is not None:
            self._set(_igi._ColmapModel.read(os.fspath(path)))

    @classmethod
    def read(cls, path: PathLike) -> "Reconstruction":
        """Reads the model in folder ``path``: BIN when cameras.bin, images.bin and points3D.bin
        all exist (as COLMAP decides), else TXT. Raises :class:`igi.InputError` listing every
        problem (file, line or record and byte, value, rule)."""
        return cls(path)

    def write_text(self, path: PathLike) -> None:
        """Writes cameras.txt, images.txt and points3D.txt into folder ``path`` (created if
        needed), with COLMAP's headers and 17 significant digits, so reading gives the same
        model back."""
        self._native().write_text(os.fspath(path))

    def write_binary(self, path: PathLike) -> None:
        """Writes cameras.bin, images.bin and points3D.bin into folder ``path`` (created if
        needed) in COLMAP 3.8's little-endian layout; reading gives the same model back bit for
        bit. Records are in id order."""
        self._native().write_binary(os.fspath(path))

    def export_PLY(self, path: PathLike) -> None:
        """Writes the 3D points to the file ``path`` as COLMAP's ``model_converter --output_type
        PLY`` does (named as pycolmap's ``Reconstruction.export_PLY``): binary little-endian PLY,
        float32 x, y, z and uint8 red, green, blue per point, in id order. Raises
        :class:`igi.InputError` for a coordinate beyond float32's range."""
        self._native().export_ply(os.fspath(path))

    def find_image_with_name(self, name: str) -> Optional[Image]:
        """The image with this file name, or None."""
        return next((image for image in self.images.values() if image.name == name), None)

    def num_observations(self) -> int:
        """The number of 2D points with a 3D point, over all images."""
        return int(sum(int(np.count_nonzero(image.point3D_ids >= 0))
                       for image in self.images.values()))

    def validate(self) -> None:
        """Checks the model by the rules writing applies, without writing; raises
        :class:`igi.InputError` listing the problems (named after cameras.txt, images.txt and
        points3D.txt)."""
        self._native().validate()

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Reconstruction) and self.cameras == other.cameras
                and self.images == other.images and self.points3D == other.points3D)

    def __repr__(self) -> str:
        return (f"<igi.colmap.Reconstruction: {len(self.cameras)} cameras, "
                f"{len(self.images)} images, {len(self.points3D)} points3D>")

    def _set(self, native: "_igi._ColmapModel") -> None:
        """Fills the model from the extension's records."""
        self.cameras = {key: Camera(*fields) for key, *fields in native.cameras()}
        self.images = {}
        for key, image_id, qvec, tvec, camera_id, name, xys, ids in native.images():
            self.images[key] = Image(image_id, name, camera_id, qvec, tvec, xys, ids)
        self.points3D = Points3D(*native.points3D())

    def _native(self) -> "_igi._ColmapModel":
        """The model as the extension holds it (conversion checks types and shapes)."""
        cameras = [(key, c.camera_id, c.model, c.width, c.height, c.params)
                   for key, c in self.cameras.items()]
        images = [(key, i.image_id, i.qvec, i.tvec, i.camera_id, i.name, i.xys, i.point3D_ids)
                  for key, i in self.images.items()]
        p = self.points3D
        points = (p.ids, p.xyz, p.rgb, p.error, p.track_offsets, p.track)
        return _igi._ColmapModel(cameras, images, points)
