"""Geometric facts about a robot's joint axes, read off its screw model.

Everything here works on the product-of-exponentials model (axes and points in
the world frame at q = 0), so the facts do not depend on the DH convention,
on the frame choices, or on base and tool transforms. Tests use tolerances
relative to the robot's size, never exact equality.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._forward import ScrewModel
from .._tolerances import GEOMETRY_TOLERANCE


@dataclass(frozen=True)
class Geometry:
    """A screw model plus the length scale used for relative tolerances.

    ``up`` (3,) is the robot's up direction in the world frame: the z axis of
    its base frame, so that a base transform (a tilted or ceiling mount) does
    not change which side of an arm is "up". ``link_x`` (n, 3), when known, holds
    the x axis of each link frame 1…n at q = 0, in the world frame: along the
    common normal of joint axes i and i+1 in every DH convention, with the
    sense the robot's designer chose. The textbook's "front" is defined by it
    (θ1 = atan2(yc, xc) puts the wrist centre along x1).
    """

    model: ScrewModel
    length_scale: float
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    link_x: np.ndarray | None = None

    @property
    def dof(self) -> int:
        return len(self.model.is_revolute)

    def kinds(self, indices: range | tuple[int, ...] | None = None) -> str:
        """Joint kinds as a string such as ``"RRP"``."""
        indices = range(self.dof) if indices is None else indices
        return "".join("R" if self.model.is_revolute[i] else "P" for i in indices)

    def direction(self, i: int) -> np.ndarray:
        return self.model.directions[i]

    def point(self, i: int) -> np.ndarray:
        return self.model.points[i]

    def parallel(self, i: int, j: int) -> bool:
        """Whether the axes (or sliding directions) of joints i and j are parallel or anti-parallel."""
        return bool(np.linalg.norm(np.cross(self.direction(i), self.direction(j))) <= GEOMETRY_TOLERANCE * 10)

    def intersection(self, i: int, j: int) -> np.ndarray | None:
        """The point where two non-parallel revolute axes meet, or None if they are skew or parallel."""
        if self.parallel(i, j):
            return None
        return _closest_common_point([self.point(i), self.point(j)], [self.direction(i), self.direction(j)],
                                     self.length_scale)

    def common_point(self, indices: tuple[int, ...]) -> np.ndarray | None:
        """The point where all the given revolute axes meet, if they do (at least two non-parallel)."""
        if not all(self.model.is_revolute[i] for i in indices):
            return None
        directions = [self.direction(i) for i in indices]
        if all(self.parallel(indices[0], i) for i in indices[1:]):
            return None
        return _closest_common_point([self.point(i) for i in indices], directions, self.length_scale)

    def upward(self, direction: np.ndarray) -> np.ndarray:
        """``direction`` or its opposite, whichever has a non-negative component along :attr:`up`."""
        return -direction if float(direction @ self.up) < -1e-12 else direction

    def on_axis(self, i: int, point: np.ndarray) -> bool:
        """Whether ``point`` lies on the axis of revolute joint i."""
        offset = point - self.point(i)
        return bool(np.linalg.norm(np.cross(self.direction(i), offset)) <= GEOMETRY_TOLERANCE * 10 * self.length_scale)


def _closest_common_point(points: list[np.ndarray], directions: list[np.ndarray], scale: float) -> np.ndarray | None:
    """Least-squares point nearest to every line; None unless it lies on all of them."""
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for p, k in zip(points, directions):
        projector = np.eye(3) - np.outer(k, k)
        A += projector
        b += projector @ p
    if np.linalg.matrix_rank(A, tol=1e-9) < 3:
        return None
    x = np.linalg.solve(A, b)
    for p, k in zip(points, directions):
        if np.linalg.norm(np.cross(k, x - p)) > GEOMETRY_TOLERANCE * 10 * scale:
            return None
    return x
