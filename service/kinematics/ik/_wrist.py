"""Wrists: revolute joints whose axes meet at one point, solving orientation alone.

Given ``R_w``, the rotation the wrist joints must produce (the positioning
joints' motion already removed), these solve
``R(ω_a, q_a) R(ω_b, q_b) R(ω_c, q_c) = R_w`` (spherical wrist) or
``R(ω_a, q_a) R(ω_b, q_b) = R_w`` (two axes meeting: an arm with one joint fewer than six, such as
one with two coaxial joints) or ``R(ω, q) = R_w`` (a final roll). Axes are the home axes of the screw
model.

A wrist reads ``R_w`` only through the few home vectors it turns (:attr:`reads`, (k, 3)): its ``solve`` takes
``R_w`` applied to them (:func:`seen_by`), which the caller can compute without building ``R_w``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._tolerances import ACCEPT_RESIDUAL, GEOMETRY_TOLERANCE
from .._angles import wrap_angle
from .._forward import JointTrig, cross, radius_about
from ._screws import perpendicular_unit, rotate_about
from ._structure import Geometry, read_off_below
from .subproblems import subproblem_1, subproblem_2_chain
from ._types import NEAR_SINGULAR, LabelCodes, SingularFlags, Singularity, Sealed


def seen_by(wrist, R_w: np.ndarray) -> np.ndarray:
    """``R_w`` (..., 3, 3) applied to each of the wrist's :attr:`reads` vectors: what its ``solve`` takes,
    shape (..., k, 3)."""
    return np.einsum("...ij,kj->...ki", R_w, wrist.reads)


@dataclass
class WristResult:
    """``joints`` (N, m, k) for the wrist joints, ``valid`` (N, m), singular flags per target, and, when the wrist
    gives it, the slots (N, m) it solved near its alignment (see :attr:`~._types.Candidates.near_singular`)."""

    joints: np.ndarray
    valid: np.ndarray
    singularities: SingularFlags
    near_singular: np.ndarray | None = None


def wrist_codes(sine: np.ndarray) -> LabelCodes:
    """Wrist label codes from the sines of the middle wrist joint's angles (M,): 0 ``no_flip`` when positive, else
    1 ``flip``.

    The flip is (q_a + π, −q_b, q_c + π) (textbook §2.3, §3.2). When the sine is
    zero (within the tolerance at which subproblem 2 finds the first joint free)
    the outer axes are aligned, the two branches are one family and no wrist
    label applies (−1).
    """
    codes = np.where(sine > 0, 0, 1).astype(np.int8)
    codes[np.abs(sine) <= 10 * GEOMETRY_TOLERANCE] = -1
    return {"wrist": (("no_flip", "flip"), codes)}


#: The volume of the wrist's unit axes (|det|) below which q_a is fixed only within a band: the error of R_w
#: (rounding, and the positioning joints' own, ~1e-12 near a singularity) moves q_a and q_c along their null
#: motion by about that over the volume (a PUMA with right angles 1e-5 off at q5 = 1e-9: volume 1e-9, q4 1.4e-6
#: off; the catalogue's PUMA at q5 = 5e-9: q4 1.3e-3 off).
ALIGNED_BELOW = 1e-8
#: Where q_a is fixed only within a band, the reference's q_a represents the root when R(a, q_a) R(b, q_b) ω_c
#: misses R_w ω_c by at most this (unit vectors): the FK check then accepts the solution it gives.
BAND_MISS = 0.1 * ACCEPT_RESIDUAL


class SphericalWrist(Sealed):
    """Three revolute joints meeting at the wrist centre (Spong §4.2–4.4, done with subproblems).

    Subproblem 2 turns ω_c's home direction onto ``R_w ω_c`` with joints a and
    b (two roots: the wrist flip), then subproblem 1 finds q_c from a vector
    normal to ω_c. When ``R_w ω_c`` lies on ω_a (the middle joint aligns the
    outer axes), only q_a ± q_c is determined: q_a takes the reference value
    (or 0) and the singularity is reported. "Lies on" allows for the arm's
    own error: an arm whose relations hold within ``GEOMETRY_TOLERANCE`` but
    not exactly (a URDF's π/2 written to 11 digits) gives ``R_w`` with that
    error, and q_a, seen on the radius of ``R_w ω_c`` about ω_a, with that
    error over the radius (see :attr:`free_below`). Where the two roots meet
    (a wrist whose angles are not right ones, as CAD rounding leaves them,
    folds its flip pair near the aligned pose), q_a is fixed only within a band
    (:data:`ALIGNED_BELOW`): it takes the reference value when that reaches
    ``R_w ω_c`` within :data:`BAND_MISS`, and the fold (or the near
    alignment) is reported.

    Labels: see :func:`wrist_codes`.
    """

    name = "spherical_wrist"
    generic_count = 2

    def __init__(self, geometry: Geometry, joints: tuple[int, int, int]) -> None:
        self.geometry = geometry
        self.joints = joints
        self.axes = [geometry.direction(j) for j in joints]
        self.normal = perpendicular_unit(self.axes[2])
        self.reads = np.stack([self.axes[2], self.normal])  # ω_c and its normal

    def solve(self, seen: np.ndarray, reference: np.ndarray | None) -> WristResult:
        """The wrist's joints for ``seen`` (N, 2, 3): R_w ω_c and R_w times ω_c's normal (:func:`seen_by`)."""
        a, b, c = self.axes
        target_axis = seen[..., 0, :]  # (..., 3)
        pair = subproblem_2_chain(a, b, c, target_axis[..., None, :])
        qa, qb = pair.theta1[..., 0, :], pair.theta2[..., 0, :]  # (..., 2)
        free = pair.degenerate[..., 0] | (radius_about(a, target_axis) <= self.free_below)
        if free.any():
            start = 0.0 if reference is None else reference[self.joints[0]]
            back = rotate_about(a, -start, target_axis)
            qb_free = subproblem_1(b, c, back).theta[..., 0]
            qa = np.where(free[..., None], start, qa)
            qb = np.where(free[..., None], qb_free[..., None], qb)
        valid = pair.valid[..., 0, :].copy()
        valid[..., 1] &= ~free
        # where the two roots meet (the cones touch, or cross within rounding: a fold, where the flip pair is one),
        # or the axes nearly align (their volume below ALIGNED_BELOW), the target fixes q_a only within a band:
        # the root nearest the reference takes its value where that reaches R_w ω_c within BAND_MISS
        met = pair.merged[..., 0] & ~free
        volume = self.volume(qb)
        aligned = (volume <= ALIGNED_BELOW) & pair.exact[..., 0, :]  # (..., 2); a miss's pair is coplanar
        band = (met[..., None] | aligned) & valid & ~free[..., None]
        if reference is not None and band.any():
            held = reference[self.joints[0]]
            qb_held = subproblem_1(b, c, rotate_about(a, -held, target_axis)).theta[..., 0]
            miss = np.linalg.norm(rotate_about(a, held, rotate_about(b, qb_held, c)) - target_axis, axis=-1)
            gap = np.where(band, np.abs(wrap_angle(qa - held)), np.inf)
            nearest = np.arange(2) == np.argmin(gap, axis=-1)[..., None]
            moved = band & nearest & (miss <= BAND_MISS)[..., None]
            qa = np.where(moved, held, qa)
            qb = np.where(moved, qb_held[..., None], qb)
        # q_c: R(c, q_c) u = (R_a R_b)^T R_w u
        wanted = seen[..., 1:, :]  # (..., 1, 3)
        unwound = rotate_about(b, -qb, rotate_about(a, -qa, wanted))
        qc = subproblem_1(c, self.normal, unwound).theta[..., 0]
        joints = np.stack([qa, qb, qc], axis=-1)
        singular = SingularFlags(len(seen))
        if free.any():
            aligned = rotate_about(b, qb[..., 0], c) @ a
            for relation, mask in (("sum", free & (aligned > 0)), ("difference", free & ~(aligned > 0))):
                singular.add(mask, Singularity(
                    "wrist", (self.joints[0], self.joints[2]), relation,
                    f"the first and last wrist axes are aligned: only q{self.joints[0] + 1} "
                    f"{'+' if relation == 'sum' else '−'} q{self.joints[2] + 1} is determined; "
                    f"q{self.joints[0] + 1} is set to the reference value (or 0)"))
        singular.add(met, Singularity(
            "wrist", self.joints, "boundary", f"the two wrist solutions meet (a fold of the wrist flip): "
            f"q{self.joints[0] + 1} is fixed only within a band, and set to the reference value where it lies in "
            f"it"))
        singular.add(band.any(axis=-1) & ~met, Singularity(
            "wrist", self.joints, "aligned", f"the wrist axes are nearly aligned: q{self.joints[0] + 1} is fixed "
            f"only within a band, and set to the reference value where it lies in it"))
        # (a root moved to the reference's q_a lies in the band, far inside NEAR_SINGULAR: its volume stands)
        return WristResult(joints, valid, singular, volume <= NEAR_SINGULAR)

    def volume(self, qb: np.ndarray) -> np.ndarray:
        """|det| of the wrist's three unit axes at q_b (...,), which q_a turns together (so it does not count):
        the wrist's part of the arm's Jacobian is singular where it vanishes. a·(b × R(b, q_b) c) is
        u cos q_b + w sin q_b (:attr:`volume_terms`)."""
        u, w = self.volume_terms
        return np.abs(u * np.cos(qb) + w * np.sin(qb))

    @cached_property
    def volume_terms(self) -> tuple[float, float]:
        """(u, w) = (a·(b × c), a·(b × (b × c))) of the wrist's axes: its volume at q_b is |u cos q_b + w sin q_b|."""
        a, b, c = self.axes
        return float(a @ cross(b, c)), float(a @ cross(b, cross(b, c)))

    @property
    def turns_every_way(self) -> bool:
        """Whether the wrist reaches every orientation: its consecutive axes are perpendicular (the angle between
        its first axis and its last one's image ranges over |θ_ab − θ_bc| … θ_ab + θ_bc, all of 0 … π only then)."""
        a, b, c = self.axes
        return abs(float(a @ b)) <= GEOMETRY_TOLERANCE and abs(float(b @ c)) <= GEOMETRY_TOLERANCE

    @property
    def free_below(self) -> float:
        """The radius of ``R_w ω_c`` about ω_a (unit vectors) at or below which q_a is held as free
        (:func:`read_off_below`: relations rounded more coarsely than exact recognition accepts, which this plan
        does not assume, do not count)."""
        return read_off_below(self.geometry)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        middle = self.joints[1]
        return wrist_codes(np.sin(joints[:, middle]) if trig is None else trig[middle][1])


class Roll:
    """One revolute joint turning the tool about its own axis: subproblem 1 on a vector normal to it."""

    name = "roll"
    generic_count = 1

    def __init__(self, geometry: Geometry, joint: int) -> None:
        self.geometry = geometry
        self.joints = (joint,)
        self.axis = geometry.direction(joint)
        self.normal = perpendicular_unit(self.axis)
        self.reads = self.normal[None]

    def solve(self, seen: np.ndarray, reference: np.ndarray | None) -> WristResult:
        """The roll for ``seen`` (N, 1, 3): R_w times a normal of the axis (:func:`seen_by`)."""
        q = subproblem_1(self.axis, self.normal, seen[..., 0, :]).theta  # (..., 1)
        return WristResult(q[..., None], np.ones(q.shape, dtype=bool), SingularFlags(len(seen)))

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        return {}


class TwoAxisWrist(Sealed):
    """Two revolute joints whose axes meet at the wrist centre (not parallel): ``R(ω_a, q_a) R(ω_b, q_b) = R_w``.

    ``R(ω_b, q_b)`` keeps ω_b, so ``R(ω_a, q_a) ω_b = R_w ω_b`` (subproblem 1) gives q_a, and q_b follows by
    subproblem 1 on a vector normal to ω_b. One solution; only a rotation of that two-parameter form is
    reachable (``valid`` where the first subproblem is exact; the FK check decides the rest). The wrist of a
    five-joint arm placing a full pose, for instance a six-joint arm with two coaxial wrist joints once one is
    held (:mod:`._coaxial`).
    """

    name = "two_axis_wrist"
    generic_count = 1

    def __init__(self, geometry: Geometry, joints: tuple[int, int]) -> None:
        self.geometry = geometry
        self.joints = joints
        self.axes = [geometry.direction(j) for j in joints]
        self.normal = perpendicular_unit(self.axes[1])
        self.reads = np.stack([self.axes[1], self.normal])  # ω_b and its normal

    def solve(self, seen: np.ndarray, reference: np.ndarray | None) -> WristResult:
        """The two joints for ``seen`` (N, 2, 3): R_w ω_b and R_w times ω_b's normal (:func:`seen_by`)."""
        a, b = self.axes
        first = subproblem_1(a, b, seen[..., 0, :])  # theta (..., 1)
        qa = first.theta
        wanted = seen[..., 1:, :]  # (..., 1, 3)
        qb = subproblem_1(b, self.normal, rotate_about(a, -qa, wanted)).theta[..., 0]
        return WristResult(np.stack([qa, qb], axis=-1), first.exact.copy(), SingularFlags(len(seen)))

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        return {}
