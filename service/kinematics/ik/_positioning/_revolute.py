"""Positioners of revolute joints only, beyond the shoulders: one joint on its circle (:class:`OneRevolute`), two
parallel axes in their plane (:class:`PlanarTwoLink`), two meeting axes on their sphere (:class:`IntersectingPair`)
and three joints whose last two axes are skew (:class:`SkewAxes`, Pieper's quartic)."""

from __future__ import annotations

import numpy as np

from ..._tolerances import GEOMETRY_TOLERANCE
from ..._forward import JointTrig, cross, radius_about
from .._screws import rotate_about
from .._structure import Geometry
from .._types import LabelCodes, SingularFlags, Singularity
from ..subproblems import subproblem_1, subproblem_2_chain, subproblem_3, subproblem_5
from ._base import Needs, Positioner, PositionerResult, _common_normal_feet, _flag_rows, side_codes


class OneRevolute(Positioner):
    """One revolute joint placing a point on the circle it sweeps: ``R(ω, q)(w − p) = x − p``, subproblem 1.

    One solution where x is on that circle (the point's height along ω and its distance from the axis
    kept), none elsewhere. The positioner of a two-joint arm whose second joint is a roll placing a full
    pose: the roll keeps the points of its axis, so the target fixes where one of them goes. Such an arm is,
    for instance, a planar three-joint arm with two coaxial joints once one of them is held
    (:mod:`._coaxial`). With the point on the axis every q keeps it there: the joint is free (the reference
    value, or 0) and flagged, and a full pose's orientation then fixes it (``DecoupledPlan``).
    """

    name = "one_revolute"
    generic_count = 1
    needs = Needs(kinds=("R",))

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        """Joint values (N, 1, 1) carrying the point to targets (N, 3), valid (N, 1) where on the circle."""
        g, (i,) = self.geometry, self.joints
        turn = subproblem_1(g.direction(i), self.point - g.point(i), targets - g.point(i), scale=g.length_scale)
        free = turn.degenerate  # (N,): the point (or the target) on the axis
        q = np.where(free[:, None], 0.0 if reference is None else reference[i], turn.theta)
        singular = SingularFlags(len(targets))
        _flag_rows(free, Singularity("shoulder", (i,), "free", f"the point is on axis {i + 1}; joint {i + 1} is "
                                     "set to the reference value (or 0)"), singular)
        return PositionerResult(q[..., None], turn.exact, singular)



class PlanarTwoLink(Positioner):
    """Two revolute joints with parallel axes placing a point in their plane (Spong Example 3.1).

    The distance from axis 1 fixes q₂ (subproblem 3, elbow up/down), then q₁ by
    subproblem 1. The point's height along the axes cannot change: a target
    off that plane is unreachable.

    With the point on axis 2 (a link of length 0, as in a planar arm with two coaxial joints once one is
    held, :mod:`._coaxial`) q₂ never moves it: subproblem 3 is degenerate for every target, q₂ is a free
    joint (the reference value, or 0) and one solution remains.
    """

    name = "planar_two_link"
    generic_count = 2
    needs = Needs(kinds=("RR",), parallel=((0, 1),))

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "PlanarTwoLink":
        if geometry.on_axis(joints[1], point):  # subproblem 3 is degenerate for every target
            return cls(geometry, joints, point, generic_count=1, free_joints=(joints[1],))
        return cls(geometry, joints, point)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j) = self.geometry, self.joints
        u = g.direction(i)
        radial = targets - g.point(i)
        reach = np.linalg.norm(radial - np.outer(radial @ u, u), axis=-1)
        in_plane = np.abs((targets - self.point) @ u) <= GEOMETRY_TOLERANCE * g.length_scale
        in_plane_projector = np.eye(3) - np.outer(u, u)
        elbow = subproblem_3(g.direction(j), in_plane_projector @ (self.point - g.point(j)),
                             in_plane_projector @ (g.point(i) - g.point(j)), reach)
        q2 = elbow.theta  # (N, 2)
        if self.free_joints:  # degenerate: the representative is the reference value (or 0), not SP3's 0
            q2 = np.where(elbow.valid, 0.0 if reference is None else reference[j], q2)
        w2 = g.point(j) + rotate_about(g.direction(j), q2, self.point - g.point(j))
        first = subproblem_1(u, w2 - g.point(i), (targets - g.point(i))[:, None, :], scale=g.length_scale)
        q1 = first.theta[..., 0]
        free = first.degenerate
        if free.any():
            q1 = np.where(free, 0.0 if reference is None else reference[i], q1)
        joints = np.stack([q1, q2], axis=-1)
        valid = elbow.valid & elbow.exact & first.exact[..., 0] & in_plane[:, None]
        valid[:, 1] &= ~free[:, 1]
        if self.free_joints:
            valid[:, 1] = False  # one representative of the free elbow
        singular = SingularFlags(len(targets))
        _flag_rows(elbow.merged, Singularity("elbow", (j,), "stretched_or_folded",
                                             "the arm is fully stretched or folded"), singular)
        _flag_rows(free.any(axis=1), Singularity("shoulder", (i,), "free",
                                                 "the point is on the first axis; joint 1 is free"), singular)
        return PositionerResult(joints, valid, singular)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        g, (i, j) = self.geometry, self.joints
        up = g.upward(g.direction(i))
        elbow = self._moved(joints, i + 1, g.point(j), trig) - g.point(i)
        point = self._moved(joints, j + 1, self.point, trig) - g.point(i)
        side = np.einsum("mi,i->m", cross(point, elbow), up)
        return {"elbow": (("up", "down"), side_codes(side, np.linalg.norm(point, axis=-1) * np.linalg.norm(elbow, axis=-1)))}



class IntersectingPair(Positioner):
    """Two revolute joints whose axes meet at a point c (not parallel), placing a point on a sphere about c.

    ``R(ω₁, q₁) R(ω₂, q₂)(w − c) = x − c`` is subproblem 2: two solutions. The pair places the point
    only on the sphere of radius ``‖w − c‖``: another target is unreachable. The positioner of an arm
    with one joint fewer than six, such as a six-joint arm with two coaxial joints once one of them is
    held (:mod:`._coaxial`). Joint 1 is free when the target is on axis 1, joint 2 when the point is on
    axis 2, both when the point is c. No textbook names its branches, so it gives no labels.
    """

    name = "intersecting_pair"
    generic_count = 2
    needs = Needs(kinds=("RR",), meeting=(0, 1))

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j) = self.geometry, self.joints
        c, n_targets = self.centre, len(targets)
        pair = subproblem_2_chain(g.direction(i), g.direction(j), self.point - c, targets - c)
        q1, q2 = pair.theta1, pair.theta2  # (N, 2)
        start = {i: 0.0 if reference is None else float(reference[i]), j: 0.0 if reference is None
                 else float(reference[j])}
        # the chain form's theta1 is free with the target on axis 1, theta2 with the point on axis 2
        on_axis_1 = radius_about(g.direction(i), targets - c) <= GEOMETRY_TOLERANCE * g.length_scale
        on_axis_2 = pair.degenerate & ~on_axis_1
        both = on_axis_1 & (np.linalg.norm(self.point - c) <= GEOMETRY_TOLERANCE * g.length_scale)
        if pair.degenerate.any():
            q1 = np.where(on_axis_1[:, None], start[i], q1)
            second = subproblem_1(g.direction(j), self.point - c, rotate_about(g.direction(i), -start[i], targets - c))
            q2 = np.where(on_axis_1[:, None], np.where(both, start[j], second.theta[..., 0])[:, None], q2)
            q2 = np.where(on_axis_2[:, None], start[j], q2)
            if on_axis_2.any():
                first = subproblem_1(g.direction(i), rotate_about(g.direction(j), start[j], self.point - c),
                                     targets - c)
                q1 = np.where(on_axis_2[:, None], first.theta, q1)
        joints = np.stack([q1, q2], axis=-1)
        valid = pair.valid & pair.exact
        singular = SingularFlags(n_targets)
        _flag_rows(both, Singularity("shoulder", (i, j), "free", "the point is at the axes' crossing; joints "
                                     f"{i + 1} and {j + 1} are set to the reference values (or 0)"), singular)
        _flag_rows(on_axis_1 & ~both, Singularity("shoulder", (i,), "free", f"the point is on axis {i + 1}; joint "
                                                  f"{i + 1} is set to the reference value (or 0)"), singular)
        _flag_rows(on_axis_2, Singularity("shoulder", (j,), "free", f"the point is on axis {j + 1}; joint {j + 1} is "
                                          "set to the reference value (or 0)"), singular)
        _flag_rows(pair.merged, Singularity("shoulder", (i, j), "boundary", "the two solutions meet"), singular)
        return PositionerResult(joints, valid, singular)



class SkewAxes(Positioner):
    """Three revolute joints whose second and third axes are skew: Pieper's quartic, by subproblem 5.

    The general 3R positioner (IK-Geo's ``spherical`` family). With o₂, o₃ the feet of the common
    normal of axes 2 and 3 and o₁ a point on axis 1, the target x = G₁G₂G₃ w reads
    ``(o₁ − o₂) + R(−ω₁, q₁)(x − o₁) = R(ω₂, q₂)((o₃ − o₂) + R(ω₃, q₃)(w − o₃))``: subproblem 5,
    up to four solutions. With o₂, o₃ on the common normal the equations always separate the
    angles (the length and height rows of subproblem 5 are independent for the third axis). No
    textbook names its branches, so it gives no labels.
    """

    name = "skew_axes"
    generic_count = 4
    needs = Needs(kinds=("RRR",))

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, *,
                 feet: tuple[np.ndarray, np.ndarray]) -> None:
        super().__init__(geometry, joints, point)
        #: the feet (3,) on axes 2 and 3 of their common normal
        self.feet = feet

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "SkewAxes | None":
        _, j, k = joints
        if geometry.nearly_parallel(j, k):
            return None  # the common normal's feet would run off to where the rounding puts them
        feet = _common_normal_feet(geometry.point(j), geometry.direction(j), geometry.point(k), geometry.direction(k))
        if geometry.nearly_coincident(*feet) or geometry.nearly_on_axis(k, point):
            return None  # axes that (nearly) meet, a point (nearly) on axis 3: the idealised arm's families answer
        return cls(geometry, joints, point, feet=feet)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        (o2, o3), o1 = self.feet, g.point(i)
        sol = subproblem_5(-g.direction(i), g.direction(j), g.direction(k), o1 - o2, targets - o1, o3 - o2,
                           self.point - o3)
        q1 = sol.theta1
        if sol.degenerate.any() and reference is not None:  # the target on axis 1: joint 1 free
            q1 = np.where(sol.degenerate[:, None], reference[i], q1)
        joints = np.stack([q1, sol.theta2, sol.theta3], axis=-1)
        singular = SingularFlags(len(targets))
        _flag_rows(sol.degenerate, Singularity("shoulder", (i,), "free", "the point is on the first joint's "
                                               "axis; joint 1 is set to the reference value (or 0)"), singular)
        _flag_rows(sol.merged, Singularity("positioner", self.joints, "boundary", "two solutions of the "
                                           "positioner meet: the point is on the edge of the workspace"), singular)
        return PositionerResult(joints, sol.valid, singular)
