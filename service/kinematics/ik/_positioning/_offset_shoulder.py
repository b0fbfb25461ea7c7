"""Offset shoulders: joint 1 (revolute or prismatic) ahead of a revolute joint 2 whose axis it does not meet,
then joint 3 parallel to axis 2 (:class:`OffsetShoulderParallelElbow`, the ortho-parallel arms) or meeting it
(:class:`OffsetShoulderIntersectingElbow`)."""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..._tolerances import GEOMETRY_TOLERANCE, RECOGNITION_TOLERANCE
from ..._forward import JointTrig, radius_about
from .._screws import rotate_about
from .._structure import Geometry
from .._types import NEAR_SINGULAR, LabelCodes, SingularFlags, Singularity
from ..subproblems import (
    prismatic_to_distance,
    prismatic_to_plane,
    subproblem_1,
    subproblem_2_chain,
    subproblem_3,
    subproblem_4,
)
from ._base import Needs, Positioner, PositionerResult, _common_normal_feet, _flag_rows, _slot_grid, _unit, side_codes


class OffsetShoulderParallelElbow(Positioner):
    """Joint 1, then revolute joint 2 with a revolute joint 3 parallel to it (or a slide normal to it).

    The ortho-parallel basis of the KUKA KR and Quantec, ABB IRB 140/6700, Fanuc LR Mate and
    Yaskawa arms (Brandstötter et al. 2014, "OPW"), and any arm whose axes 2 ∥ 3 are offset from
    axis 1 at any angle: IK-Geo's ``spherical_two_parallel`` positioner. Joints 2 and 3 keep the
    point's height along their common direction u, so with y the target with joint 1 undone,
    ``u·y = u·w``: subproblem 4 for a revolute joint 1 (two roots: front and back), linear for a
    prismatic one. In the plane normal to u it is the planar two-link arm: the distance from axis
    2 to y fixes joint 3 (subproblem 3, elbow up and down; a quadratic for a slide) and joint 2
    follows by subproblem 1. Four solutions in all (two with a prismatic joint 1).

    Labels (revolute joints 1 and 3): ``shoulder`` left/right is the sign of the point's reach from
    axis 1 along link 1's forward direction, the direction of the shoulder offset (the common
    normal from axis 1 to axis 2): front is left, as for :class:`IntersectingShoulder`. ``elbow``
    up/down is the side of the line from the shoulder (axis 2's foot of that normal) to the point
    on which the elbow (axis 3) lies, along the robot's up direction, in the arm's plane.
    """

    name = "offset_shoulder_parallel_elbow"
    generic_count = 4
    needs = Needs(kinds=("?R?",))

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, *, shoulder: np.ndarray,
                 forward: np.ndarray | None, generic_count: int | None = None) -> None:
        super().__init__(geometry, joints, point, generic_count=generic_count)
        #: axis 2's foot (3,) of the common normal from axis 1 (a slide 1: a point of axis 2)
        self.shoulder = shoulder
        #: link 1's forward direction (3,), the shoulder offset normal to axis 1; None for a slide 1
        self.forward = forward

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "OffsetShoulderParallelElbow | None":
        i, j, k = joints
        u = geometry.direction(j)
        if geometry.model.is_revolute[k]:
            if not geometry.parallel(j, k) or geometry.on_axis(k, point):
                return None
        elif abs(float(geometry.direction(k) @ u)) > GEOMETRY_TOLERANCE:
            return None
        if geometry.model.is_revolute[i]:
            if geometry.nearly_parallel(i, j):
                return None  # (nearly) parallel to u: joint 1 hardly changes the height subproblem 4 solves for
        elif abs(float(geometry.direction(i) @ u)) <= RECOGNITION_TOLERANCE:
            # a slide (nearly) normal to u moves the point across the plane, not along u: the height equation
            # would divide by its component along u, turning a rounding of the geometry into a long slide
            return None
        if geometry.model.is_revolute[i]:
            shoulder_on_1, shoulder = _common_normal_feet(geometry.point(i), geometry.direction(i),
                                                          geometry.point(j), u)
            offset = shoulder - shoulder_on_1
            forward = _unit(offset - (offset @ geometry.direction(i)) * geometry.direction(i))
            return cls(geometry, joints, point, shoulder=shoulder, forward=forward)
        return cls(geometry, joints, point, shoulder=geometry.point(j), forward=None, generic_count=2)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        u, w, n_targets = g.direction(j), self.point, len(targets)
        if g.model.is_revolute[i]:
            o = g.point(i)
            # u·R(k1, −q1)(x − o) = u·(w − o): subproblem 4 for −q1
            first = subproblem_4(u, g.direction(i), targets - o, np.full(n_targets, float(u @ (w - o))))
            q1 = -first.theta
            if first.degenerate.any():  # the target on axis 1: joint 1 free
                q1 = np.where(first.degenerate[:, None], 0.0 if reference is None else reference[i], q1)
            y = o + rotate_about(g.direction(i), -q1, (targets - o)[:, None, :])  # (N, 2, 3)
        else:
            first = prismatic_to_plane(u, targets, -g.direction(i), np.full(n_targets, float(u @ w)))
            q1 = first.s
            y = targets[:, None, :] - q1[..., None] * g.direction(i)
        in_plane, elbow_to_point, elbow_to_shoulder = self._plane_constants
        reach = np.linalg.norm((y - g.point(j)) @ in_plane, axis=-1)  # (N, m1)
        if g.model.is_revolute[k]:
            third = subproblem_3(g.direction(k), elbow_to_point, elbow_to_shoulder, reach)
            q3 = third.theta  # (N, m1, 2)
            w3 = g.point(k) + rotate_about(g.direction(k), q3, w - g.point(k))
        else:
            third = prismatic_to_distance(in_plane @ (w - g.point(j)), g.direction(k), np.zeros(3), reach)
            q3 = third.s
            w3 = w + q3[..., None] * g.direction(k)
        # judged against the arm's size, as every positioner's subproblem 1 is: with the elbow folded the point is
        # near axis 2, and an arm exact recognition accepted (within 1e-8 of its size) misses its height along
        # axis 2 by more than 1e-9 of that short distance (a LR Mate moved by ~1e-11 lost its front branch)
        second = subproblem_1(u, w3 - g.point(j), y[:, :, None, :] - g.point(j), scale=g.length_scale)
        q2 = second.theta[..., 0]
        if second.degenerate.any():  # the point on axis 2 (the elbow folded onto it)
            q2 = np.where(second.degenerate, 0.0 if reference is None else reference[j], q2)
        m = q3.shape[1] * 2
        joints = np.empty((n_targets, m, 3))
        joints[..., 0] = _slot_grid(q1, q3)
        joints[..., 1] = q2.reshape(n_targets, m)
        joints[..., 2] = q3.reshape(n_targets, m)
        first_ok = first.valid & first.exact
        if g.model.is_revolute[i]:
            first_ok[:, 1] &= ~first.degenerate
        valid = (first_ok[:, :, None] & third.valid & third.exact & second.exact[..., 0]).reshape(n_targets, m)
        singular = SingularFlags(n_targets)
        if g.model.is_revolute[i]:
            _flag_rows(first.degenerate, Singularity("shoulder", (i,), "free", "the point is on the first "
                                                     "joint's axis; joint 1 is set to the reference value (or 0)"),
                       singular)
            _flag_rows(first.merged, Singularity("shoulder", (i,), "boundary", "the point is as near axis 1 as "
                                                 "the shoulder offset allows: front and back meet"), singular)
        merged = (third.merged & first_ok).any(axis=1)
        if g.model.is_revolute[k] and merged.any():  # (no elbow flag to set otherwise)
            folded = self._folded(q3[:, :, 0])
            _flag_rows((third.merged & first_ok & ~folded).any(axis=1),
                       Singularity("elbow", (k,), "stretched", "the arm is fully stretched"), singular)
            _flag_rows((third.merged & first_ok & folded).any(axis=1),
                       Singularity("elbow", (k,), "folded", "the arm is fully folded"), singular)
        elif not g.model.is_revolute[k]:
            _flag_rows(merged, Singularity("reach", (k,), "boundary",
                                           "the point is at the nearest reach of the prismatic joint"), singular)
        _flag_rows((second.degenerate & first_ok[:, :, None]).any(axis=(1, 2)),
                   Singularity("elbow", (j,), "free", "the point is on axis 2; joint 2 is set to the reference "
                               "value (or 0)"), singular)
        # subproblem 4 reads q1 off the target's radius about axis 1, subproblem 1 q2 off the placed point's about
        # axis 2 (as IntersectingShoulder's): slots solved near either are checked for isolation
        near = NEAR_SINGULAR * g.length_scale
        near_axes = radius_about(u, w3 - g.point(j)) <= near  # (N, m1, 2): axis 2
        if g.model.is_revolute[i]:  # and axis 1, for every slot of the target
            near_axes |= (radius_about(g.direction(i), targets - g.point(i)) <= near)[:, None, None]
        return PositionerResult(joints, valid, singular, near_axes.reshape(n_targets, m))

    @cached_property
    def _plane_constants(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The projector onto the arm's plane (normal to axis 2), and in it the point and axis 2 seen from axis 3."""
        g, (_, j, k) = self.geometry, self.joints
        u = g.direction(j)
        in_plane = np.eye(3) - np.outer(u, u)
        return in_plane, in_plane @ (self.point - g.point(k)), in_plane @ (g.point(j) - g.point(k))

    def _folded(self, q3: np.ndarray) -> np.ndarray:
        """Whether joint 3 at q3 brings the point nearer axis 2 than its opposite turn (the folded elbow)."""
        g, (_, j, k) = self.geometry, self.joints
        u = g.direction(j)
        in_plane = np.eye(3) - np.outer(u, u)
        at = g.point(k) + rotate_about(g.direction(k), q3, self.point - g.point(k))
        opposite = g.point(k) + rotate_about(g.direction(k), q3 + np.pi, self.point - g.point(k))
        return (np.linalg.norm((at - g.point(j)) @ in_plane, axis=-1)
                < np.linalg.norm((opposite - g.point(j)) @ in_plane, axis=-1))

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        g, (i, j, k) = self.geometry, self.joints
        if not (g.model.is_revolute[i] and g.model.is_revolute[k]) or self.forward is None:
            return {}
        axis = g.direction(i)
        trig = JointTrig(joints) if trig is None else trig  # each joint's cos and sin, shared by the turns below
        point = self._moved(joints, k + 1, self.point, trig)
        reach = point - g.point(i)
        reach = reach - np.outer(reach @ axis, axis)
        forward = rotate_about(axis, joints[:, i], self.forward, trig[i])
        codes: LabelCodes = {"shoulder": (("left", "right"), side_codes(np.einsum("mi,mi->m", reach, forward),
                                                                       np.linalg.norm(point - g.point(i), axis=-1)))}
        shoulder = self._moved(joints, i + 1, self.shoulder, trig)
        normal = rotate_about(axis, joints[:, i], g.direction(j), trig[i])
        elbow = self._moved(joints, k, g.point(k), trig) - shoulder
        line = point - shoulder
        elbow = elbow - np.einsum("mi,mi->m", elbow, normal)[:, None] * normal
        line = line - np.einsum("mi,mi->m", line, normal)[:, None] * normal
        line = line / np.maximum(np.linalg.norm(line, axis=-1, keepdims=True), 1e-300)
        rejection = elbow - np.einsum("mi,mi->m", elbow, line)[:, None] * line
        codes["elbow"] = (("up", "down"), side_codes(rejection @ g.upward(axis), np.linalg.norm(elbow, axis=-1)))
        return codes



class OffsetShoulderIntersectingElbow(Positioner):
    """Joint 1 (revolute or prismatic), then revolute joints 2 and 3 whose axes meet at a point c.

    IK-Geo's ``spherical_two_intersecting`` positioner. Joints 2 and 3 turn about axes through c,
    so the point keeps its distance from c: ``‖x − G₁ c‖ = ‖w − c‖`` fixes joint 1 (subproblem 3
    for a revolute joint, a quadratic for a slide: two roots), and then
    ``R(ω₂, q₂) R(ω₃, q₃)(w − c) = y − c``, with y the target with joint 1 undone, is subproblem
    2 (two roots): four solutions. No textbook names its branches, so it gives no labels.
    """

    name = "offset_shoulder_intersecting_elbow"
    generic_count = 4
    needs = Needs(kinds=("?RR",), meeting=(1, 2))

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "OffsetShoulderIntersectingElbow | None":
        if geometry.nearly_coincident(point, centre):
            return None  # the point at c (or nearly, as rounded: joints 2 and 3 read off it): the idealised family's
        if geometry.model.is_revolute[joints[0]] and geometry.on_axis(joints[0], centre):
            return None  # all three axes through one point: it cannot place a point
        if geometry.nearly_on_axis(joints[2], point):
            return None  # joint 3 never moves the point (two joints cannot place it), or nearly: q3 read off it
        return cls(geometry, joints, point, centre)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        c, w, n_targets = self.centre, self.point, len(targets)
        radius = np.full(n_targets, float(np.linalg.norm(w - c)))
        if g.model.is_revolute[i]:
            o = g.point(i)
            first = subproblem_3(g.direction(i), c - o, targets - o, radius)
            q1 = first.theta
            if first.degenerate.any():  # the target on axis 1: joint 1 free
                q1 = np.where(first.degenerate[:, None], 0.0 if reference is None else reference[i], q1)
            y = o + rotate_about(g.direction(i), -q1, (targets - o)[:, None, :])
        else:
            first = prismatic_to_distance(np.broadcast_to(c, targets.shape), g.direction(i), targets, radius)
            q1 = first.s
            y = targets[:, None, :] - q1[..., None] * g.direction(i)
        pair = subproblem_2_chain(g.direction(j), g.direction(k), w - c, y - c)
        q2, q3 = pair.theta1, pair.theta2  # (N, 2, 2)
        free = pair.degenerate  # (N, 2): y on axis 2
        if free.any():
            start = 0.0 if reference is None else reference[j]
            back = rotate_about(g.direction(j), -start, y - c)
            q3_free = subproblem_1(g.direction(k), w - c, back).theta[..., 0]
            q2 = np.where(free[..., None], start, q2)
            q3 = np.where(free[..., None], q3_free[..., None], q3)
        first_ok = first.valid & first.exact
        if g.model.is_revolute[i]:
            first_ok[:, 1] &= ~first.degenerate
        valid = first_ok[:, :, None] & pair.valid & pair.exact
        valid[..., 1] &= ~free
        joints = np.stack([np.broadcast_to(q1[:, :, None], q2.shape), q2, q3], axis=-1).reshape(n_targets, 4, 3)
        singular = SingularFlags(n_targets)
        joint_1 = "the first joint's axis" if g.model.is_revolute[i] else "the slide"
        _flag_rows(first.merged, Singularity("shoulder", (i,), "boundary", f"the two solutions of {joint_1} meet: "
                                             "the point is at the edge of the reach"), singular)
        if g.model.is_revolute[i]:
            _flag_rows(first.degenerate, Singularity("shoulder", (i,), "free", "the point is on the first joint's "
                                                     "axis; joint 1 is set to the reference value (or 0)"), singular)
        _flag_rows((free & first_ok).any(axis=1), Singularity("elbow", (j,), "free", "the point is on axis 2; "
                                                              "joint 2 is set to the reference value (or 0)"),
                   singular)
        _flag_rows((pair.merged & first_ok).any(axis=1), Singularity("elbow", (j, k), "boundary", "the two "
                                                                     "solutions of joints 2 and 3 meet"), singular)
        return PositionerResult(joints, valid.reshape(n_targets, 4), singular)
