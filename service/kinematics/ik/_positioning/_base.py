"""What every positioner shares: its result record, its base class with the declarative match, and the helpers
of several families (label codes from a side, singular-flag rows, unit vectors, common-normal feet, slot grids).

A family declares what it needs of its joints in a :class:`Needs` (joint kinds, axes that meet, axes that are
parallel); :meth:`Positioner.match` checks that table the same way for every family and then asks the family's
own :meth:`Positioner._fit` for the conditions no table states. ``_fit`` computes the family's constants and
passes them to the constructor, so a positioner is complete when built and nothing is set on it afterwards.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fnmatch import fnmatchcase

import numpy as np

from ..._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from ..._forward import JointTrig, cross
from .._screws import chain_motion, move_point
from .._structure import Geometry
from .._types import LabelCodes, SingularFlags, Singularity, Sealed


@dataclass
class PositionerResult:
    """Candidate joint values for the positioning joints.

    ``joints`` (N, m, k); ``valid`` (N, m); ``singularities`` a list of N lists; ``near_singular`` (N, m), when
    the positioner gives it, the slots it read an angle off a short radius for (see
    :attr:`~.._types.Candidates.near_singular`).
    """

    joints: np.ndarray
    valid: np.ndarray
    singularities: SingularFlags = field(default_factory=lambda: SingularFlags(0))
    near_singular: np.ndarray | None = None


def _unit(v: np.ndarray) -> np.ndarray | None:
    norm = np.linalg.norm(v)
    return v / norm if norm > GEOMETRY_TOLERANCE else None


def side_codes(side: np.ndarray, size: np.ndarray) -> np.ndarray:
    """One label code per row (M,) from the sign of ``side`` (M,): 0 (the label's first value) when above 0, else 1.

    Where ``|side| <= DUPLICATE_TOLERANCE * size`` the row sits where its two
    branches meet (a stretched or folded elbow, aligned Assur links, a wrist
    point at the shoulder's boundary): the label does not apply (−1).
    """
    codes = np.where(side > 0, 0, 1).astype(np.int8)
    codes[np.abs(side) <= DUPLICATE_TOLERANCE * size] = -1
    return codes


def _flag_rows(flags: np.ndarray, template: Singularity, rows: SingularFlags) -> None:
    rows.add(flags, template)


def _common_normal_feet(p1: np.ndarray, d1: np.ndarray, p2: np.ndarray, d2: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """The points of two non-parallel lines (point, unit direction) nearest each other: the common normal's feet."""
    w = p1 - p2
    b, d, e = float(d1 @ d2), float(d1 @ w), float(d2 @ w)
    normal = cross(d1, d2)
    denominator = float(normal @ normal)  # sin² of the angle, without the cancellation of 1 − b²
    s, t = (b * e - d) / denominator, (e - b * d) / denominator
    return p1 + s * d1, p2 + t * d2


def _slot_grid(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Slots (N, m1·m2) from the outer product of two slot sets (N, m1) and (N, m1, m2)."""
    return np.broadcast_to(first[:, :, None], second.shape).reshape(len(first), -1)


@dataclass(frozen=True)
class Needs:
    """What a positioning family needs of its joints, before the conditions only its own code states.

    Positions below count in the family's ``joints`` (0 is its first joint), not in the arm.
    """

    #: the joint-kind sequences it takes, one pattern each: "R" revolute, "P" prismatic, "?" either
    kinds: tuple[str, ...]
    #: two joints whose axes must meet; the crossing (3,) is the positioner's ``centre``
    meeting: tuple[int, int] | None = None
    #: pairs of joints whose axes must be parallel
    parallel: tuple[tuple[int, int], ...] = ()


class Positioner(Sealed):
    """Base class: the joints it moves, its generic solution count and its labels."""

    name: str = ""
    #: the family's generic solution count (an arm whose fit finds a structurally free joint has fewer)
    generic_count: int = 0
    #: what the family needs of its joints (:meth:`match` checks it)
    needs: Needs = Needs(kinds=())

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray,
                 centre: np.ndarray | None = None, *, generic_count: int | None = None,
                 free_joints: tuple[int, ...] = ()) -> None:
        self.geometry = geometry
        self.joints = joints
        self.point = np.asarray(point, dtype=float)
        self.model = geometry.model
        #: the crossing (3,) of the axes ``needs.meeting`` names, world frame at q = 0; None without
        self.centre = centre
        #: this arm's generic solution count: the family's unless its fit says fewer
        self.generic_count = type(self).generic_count if generic_count is None else generic_count
        #: joints the target never determines (structurally free): set to the reference value or 0
        self.free_joints = free_joints

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "Positioner | None":
        """The family's positioner for these joints (indices into the arm) placing ``point`` (3,), or None when
        they are not of the family: first the :attr:`needs` table, then the family's own :meth:`_fit`."""
        needs = cls.needs
        kinds = geometry.kinds(joints)
        if not any(fnmatchcase(kinds, pattern) for pattern in needs.kinds):
            return None
        if not all(geometry.parallel(joints[a], joints[b]) for a, b in needs.parallel):
            return None
        centre = None
        if needs.meeting is not None:
            centre = geometry.intersection(joints[needs.meeting[0]], joints[needs.meeting[1]])
            if centre is None:
                return None
        return cls._fit(geometry, joints, np.asarray(point, dtype=float), centre)

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "Positioner | None":
        """The positioner once :attr:`needs` holds: the family's own conditions and constants (none here)."""
        return cls(geometry, joints, point, centre)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        raise NotImplementedError

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """The same labels as arrays: name → (values, codes (M,), −1 where the label is left out); ``trig`` the
        joints' cos and sin, when the caller shares them."""
        return {}

    def _moved(self, q: np.ndarray, upto: int, x: np.ndarray, trig: JointTrig | None = None) -> np.ndarray:
        """exp([S_1] q_1) ⋯ exp([S_upto] q_upto) applied to the point x (3,), for joint values (..., n) (``trig``
        their cos and sin, when shared)."""
        m = self.model
        return move_point(m.directions[:upto], m.points[:upto], m.is_revolute[:upto], q[..., :upto], x, trig)

    def _motion(self, q: np.ndarray, upto: int) -> np.ndarray:
        """exp([S_1] q_1) ⋯ exp([S_upto] q_upto) for joint values (..., n)."""
        m = self.model
        return chain_motion(m.directions[:upto], m.points[:upto], m.is_revolute[:upto], q[..., :upto])
