"""Collision shapes: capsules, spheres and boxes, fixed to a link or to the world.

Every shape is a value: frozen, its arrays read-only, float64, in the robot's
length unit. A shape fixed to a link is given in that link's frame
(:class:`LinkShape`); an obstacle in the world frame (:class:`Obstacle`).

Link indices are those of :func:`~service.kinematics.link_frames`: 0 is the
base frame, i the frame that moves with joint i (the convention's own frames),
n the flange.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union

import numpy as np

from .._errors import InvalidInputError
from .._rotations import check_rotation
from .._tolerances import ROUNDING_TOLERANCE


def _point(value, what: str) -> np.ndarray:
    array = np.array(value, dtype=float)
    if array.shape != (3,):
        raise InvalidInputError(f"{what} must be 3 numbers, got shape {array.shape}", location=(what,))
    if not np.isfinite(array).all():
        raise InvalidInputError(f"{what} must be finite", location=(what,))
    array.setflags(write=False)
    return array


def _radius(value: float) -> float:
    radius = float(value)
    if not (np.isfinite(radius) and radius >= 0.0):
        raise InvalidInputError(f"radius must be a finite number ≥ 0, not {value}", location=("radius",))
    return radius


@dataclass(frozen=True, eq=False)
class Capsule:
    """The points within ``radius`` of the segment from ``start`` (3,) to ``end`` (3,); a sphere when they meet."""

    start: np.ndarray
    end: np.ndarray
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", _point(self.start, "from"))
        object.__setattr__(self, "end", _point(self.end, "to"))
        object.__setattr__(self, "radius", _radius(self.radius))


@dataclass(frozen=True, eq=False)
class Sphere:
    """The points within ``radius`` of ``center`` (3,)."""

    center: np.ndarray
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _point(self.center, "center"))
        object.__setattr__(self, "radius", _radius(self.radius))


@dataclass(frozen=True, eq=False)
class Box:
    """A box of edge lengths ``size`` (3,), centred at ``center`` (3,), its edges along the columns of
    ``rotation`` (3, 3) (identity: along the frame's axes).

    A rotation that is orthonormal only to the input tolerance (``ORTHONORMAL_TOLERANCE``, say written with a
    few decimals) is replaced by the nearest rotation, so that distances measure a true box; one orthonormal to
    rounding is kept as given."""

    center: np.ndarray
    size: np.ndarray
    rotation: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _point(self.center, "center"))
        size = _point(self.size, "size")
        if (size <= 0.0).any():
            raise InvalidInputError(f"size must be three numbers > 0, not {size.tolist()}", location=("size",))
        object.__setattr__(self, "size", size)
        rotation = np.eye(3) if self.rotation is None else check_rotation(self.rotation)
        if np.abs(rotation.T @ rotation - np.eye(3)).max() > ROUNDING_TOLERANCE:
            # accepted within ORTHONORMAL_TOLERANCE, but a box is measured as a box: the nearest rotation
            # (polar factor U V^T of the SVD; check_rotation has ruled out reflections)
            left, _, right = np.linalg.svd(rotation)
            rotation = left @ right
        rotation.setflags(write=False)
        object.__setattr__(self, "rotation", rotation)

    @property
    def half_size(self) -> np.ndarray:
        """Half the edge lengths, shape (3,)."""
        return 0.5 * self.size


Shape = Union[Capsule, Sphere, Box]


def restated(shape: Shape, a_T_b: np.ndarray) -> Shape:
    """``shape``, given in frame b, restated in frame a; ``a_T_b`` shape (4, 4), a rigid transform.

    >>> turn = np.array([[0., -1, 0, 1], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])  # Rz(90°), then 1 along x
    >>> restated(Capsule([0, 0, 0], [2, 0, 0], 0.1), turn).end.tolist()
    [1.0, 2.0, 0.0]
    """
    R, p = a_T_b[:3, :3], a_T_b[:3, 3]
    if isinstance(shape, Capsule):
        return Capsule(R @ shape.start + p, R @ shape.end + p, shape.radius)
    if isinstance(shape, Sphere):
        return Sphere(R @ shape.center + p, shape.radius)
    return Box(R @ shape.center + p, shape.size, R @ shape.rotation)


def scaled(shape: Shape, factor: float) -> Shape:
    """``shape`` with every length multiplied by ``factor`` > 0 (a change of length unit)."""
    if isinstance(shape, Capsule):
        return Capsule(shape.start * factor, shape.end * factor, shape.radius * factor)
    if isinstance(shape, Sphere):
        return Sphere(shape.center * factor, shape.radius * factor)
    return Box(shape.center * factor, shape.size * factor, shape.rotation)


@dataclass(frozen=True, eq=False)
class LinkShape:
    """A shape fixed to link ``link`` (0 = base … n = flange), in that link's frame; ``name`` for messages."""

    link: int
    shape: Shape
    name: str = ""


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A shape fixed in the world frame; ``name`` is how answers refer to it."""

    name: str
    shape: Shape
