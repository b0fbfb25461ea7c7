"""Positioning arms: the first joints of a chain placing one point.

Each positioner solves ``x = exp([S_1] q_1) ⋯ exp([S_k] q_k) · w`` for the
joint values that carry a point ``w`` (given at q = 0, world frame) to
targets ``x`` (N, 3), by reducing it to geometric subproblems. Each class is
named after the family it solves and states its equations. Results are
vectorised over the N targets: candidate slots of shape (N, m, k) with a
validity mask, plus per-target singular flags.

Each family declares the joint kinds and axis relations it needs (:class:`~._base.Needs`);
:func:`find_positioner` asks the families in :data:`POSITIONERS` order. Modules:

* ``_base``: the result record, the base class and its declarative match, the shared helpers;
* ``_intersecting_shoulder``: revolute joints 1 and 2 meeting, then any joint 3 (elbow arms, PUMA);
* ``_slide_through_axis_2``: that shoulder with a slide crossing axis 2 (the Stanford and polar arms);
* ``_offset_shoulder``: joint 1 offset from axis 2, joint 3 parallel to it or meeting it (the OPW arms);
* ``_revolute``: revolute-only positioners of one to three joints (planar, meeting pair, skew axes);
* ``_slides``: the SCARA, cylindrical and Cartesian positioners and skew axes with a slide.
"""

from __future__ import annotations

import numpy as np

from .._structure import Geometry
from ._base import Needs, Positioner, PositionerResult, _flag_rows, _unit, side_codes
from ._intersecting_shoulder import IntersectingShoulder
from ._offset_shoulder import OffsetShoulderIntersectingElbow, OffsetShoulderParallelElbow
from ._revolute import IntersectingPair, OneRevolute, PlanarTwoLink, SkewAxes
from ._slide_through_axis_2 import SlideThroughAxis2
from ._slides import Cartesian, OneRevoluteTwoPrismatic, ParallelShoulder, SkewAxesWithSlide

__all__ = [
    "Cartesian",
    "IntersectingPair",
    "IntersectingShoulder",
    "Needs",
    "OffsetShoulderIntersectingElbow",
    "OffsetShoulderParallelElbow",
    "OneRevolute",
    "OneRevoluteTwoPrismatic",
    "ParallelShoulder",
    "PlanarTwoLink",
    "POSITIONERS",
    "Positioner",
    "PositionerResult",
    "SkewAxes",
    "SkewAxesWithSlide",
    "SlideThroughAxis2",
    "_flag_rows",
    "_unit",
    "find_positioner",
    "side_codes",
]

#: The families in the order they are asked: the first that matches is the arm's.
POSITIONERS = (IntersectingShoulder, ParallelShoulder, OneRevoluteTwoPrismatic, Cartesian, PlanarTwoLink,
               IntersectingPair, OneRevolute,
               OffsetShoulderParallelElbow, OffsetShoulderIntersectingElbow, SkewAxes, SkewAxesWithSlide)


def find_positioner(geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> Positioner | None:
    """The first positioning family that matches these joints, or None."""
    for family in POSITIONERS:
        solver = family.match(geometry, joints, point)
        if solver is not None:
            return solver
    return None
