"""Kinematic decoupling: a positioning arm places a point, wrist joints about it set the orientation.

Spong §4.2 done generally. The point P is where the wrist axes meet (a
spherical wrist), a point on the last axis (a roll), or the tool origin (no
wrist). The wrist joints leave P where it is, so
``P_world = world_T_target · home⁻¹ · P`` is known from the target alone; the
positioner solves for it; then ``H = (G_1 ⋯ G_k)⁻¹ · world_T_target · home⁻¹``
is the motion left to the wrist, whose rotation it solves.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from .._tolerances import GEOMETRY_TOLERANCE
from . import _scalar as scalar
from ._positioning import IntersectingShoulder, Positioner
from ._screws import apply, chain_rotation, invert
from ._types import Candidates, LabelCodes, SingularFlags
from ._wrist import Roll, SphericalWrist


class DecoupledPlan:
    """A positioner over joints 0…k−1 and an optional wrist over joints k…n−1."""

    method = "analytic"

    def __init__(self, positioner: Positioner | None, wrist: SphericalWrist | Roll | None, point: np.ndarray,
                 home: np.ndarray | None, dof: int, fixed: dict[int, float] | None = None) -> None:
        """``home`` is world_T_tool at q = 0, or None for a position-only target (no wrist then)."""
        self.positioner = positioner
        self.wrist = wrist
        self.point = point
        self.home_inverse = None if home is None else invert(home)
        self.dof = dof
        self.fixed = fixed or {}
        parts = [part.name for part in (positioner, wrist) if part is not None]
        self.structure = "+".join(parts)
        self.generic_count = (positioner.generic_count if positioner else 1) * (wrist.generic_count if wrist else 1)

    @property
    def free_joints(self) -> list[int]:
        """Joints the target does not determine: those held for a position-only target, and any the
        positioner finds structurally free (each set to the reference value or 0)."""
        positioner = self.positioner.free_joints if self.positioner is not None else ()
        return sorted(set(self.fixed) | set(positioner))

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        """Candidates (N, m, n) for targets (N, 4, 4)."""
        n_targets = len(world_T_targets)
        if self.home_inverse is None:  # position-only: the target position is the point's
            point_world = world_T_targets[:, :3, 3]
        else:
            point_world = apply(world_T_targets @ self.home_inverse, self.point)
        k = len(self.positioner.joints) if self.positioner else 0
        if self.positioner is not None:
            arm = self.positioner.solve(point_world, reference)
            arm_joints, arm_valid, singular = arm.joints, arm.valid, arm.singularities
        else:
            arm_joints = np.zeros((n_targets, 1, 0))
            arm_valid = np.ones((n_targets, 1), dtype=bool)
            singular = SingularFlags(n_targets)
        m_arm = arm_joints.shape[1]
        joints = np.zeros((n_targets, m_arm, self.dof))
        joints[..., :k] = arm_joints
        for index, value in self.fixed.items():
            joints[..., index] = value
        if self.wrist is None:
            return Candidates(joints, arm_valid, singular)
        model = self.positioner.model if self.positioner else None
        # the wrist's rotation: H = G⁻¹ · world_T_target · home⁻¹, of which only the rotation is needed
        R_target = world_T_targets[:, :3, :3] @ self.home_inverse[:3, :3]
        if self.positioner is not None:
            R_G = chain_rotation(model.directions[:k], model.is_revolute[:k], np.nan_to_num(arm_joints))
            R_H = np.swapaxes(R_G, -1, -2) @ R_target[:, None]
        else:
            R_H = R_target[:, None]
        wrist = self.wrist.solve(R_H.reshape(-1, 3, 3), reference)
        m_wrist = wrist.joints.shape[1]
        wrist_joints = wrist.joints.reshape(n_targets, m_arm, m_wrist, -1)
        wrist_valid = wrist.valid.reshape(n_targets, m_arm, m_wrist)
        full = np.repeat(joints[:, :, None, :], m_wrist, axis=2)
        full[..., list(self.wrist.joints)] = wrist_joints
        valid = arm_valid[:, :, None] & wrist_valid
        for mask, flag in wrist.singularities.entries:
            singular.add((mask.reshape(n_targets, m_arm) & arm_valid).any(axis=1), flag)
        return Candidates(full.reshape(n_targets, m_arm * m_wrist, self.dof), valid.reshape(n_targets, -1),
                          singular)

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        """Branch labels of full joint vectors (M, n) as arrays: the positioner's, then the wrist's."""
        codes: LabelCodes = {}
        for part in (self.positioner, self.wrist):
            if part is not None:
                codes.update(part.label_codes(joints))
        return codes

    def solve_one(self, world_T_target: np.ndarray) -> Candidates | None:
        """:meth:`solve` of one target (4, 4) in scalar arithmetic (:mod:`._scalar`), or None when the plan is
        not the PUMA type or the pose is not clearly generic (then :meth:`solve` decides)."""
        one_pose = self._one_pose
        return None if one_pose is None else scalar.one_pose_candidates(one_pose.solve, world_T_target)

    def label_codes_one(self, joints: np.ndarray, valid: np.ndarray) -> LabelCodes | None:
        """:meth:`label_codes` of one pose's slots (1, m, n) where ``valid`` (1, m), in scalar arithmetic, or
        None (then :meth:`label_codes` decides)."""
        one_pose = self._one_pose
        return None if one_pose is None else scalar.one_pose_label_codes(one_pose, joints, valid)

    @cached_property
    def _one_pose(self) -> "_ShoulderWristOnePose | None":
        """The scalar solver when joints 1–3 are an intersecting shoulder with a revolute joint 3 and joints 4–6 a
        spherical wrist (the PUMA type), else None."""
        positioner = self.positioner
        if (isinstance(positioner, IntersectingShoulder) and isinstance(self.wrist, SphericalWrist)
                and not self.fixed and not positioner.free_joints and positioner.joints == (0, 1, 2)
                and self.wrist.joints == (3, 4, 5) and bool(positioner.model.is_revolute[2])):
            return _ShoulderWristOnePose(self)
        return None


class _ShoulderWristOnePose:
    """:class:`DecoupledPlan` with an :class:`IntersectingShoulder` (revolute joint 3) and a spherical wrist."""

    def __init__(self, plan: DecoupledPlan) -> None:
        positioner, wrist, model = plan.positioner, plan.wrist, plan.positioner.model
        self.directions = [scalar.vector_of(d) for d in model.directions]
        self.points = [scalar.vector_of(p) for p in model.points]
        self.frame_3 = scalar.plane_axes(self.directions[2])
        self.centre, self.point = scalar.vector_of(positioner.centre), scalar.vector_of(plan.point)
        self.home_inverse = scalar.matrix_of(plan.home_inverse[:3, :3]), scalar.vector_of(plan.home_inverse[:3, 3])
        self.axes = [scalar.vector_of(a) for a in wrist.axes]
        self.normal = scalar.vector_of(wrist.normal)
        self.frame_c = scalar.plane_axes(self.axes[2])
        forward, in_plane, up = positioner.label_constants
        self.forward, self.in_plane, self.up = scalar.vector_of(forward), in_plane, scalar.vector_of(up)
        self.on_axis = GEOMETRY_TOLERANCE * 10 * positioner.geometry.length_scale

    names = ("shoulder", "elbow", "wrist")
    values = (("left", "right"), ("up", "down"), ("no_flip", "flip"))

    def codes(self, q: list[float]) -> tuple[int, int, int]:
        """:meth:`IntersectingShoulder.label_codes` and :func:`wrist_codes` for one joint vector."""
        d, p, c = self.directions, self.points, self.centre
        forward = scalar.rotate(d[0], q[0], self.forward)
        reach = scalar.sub(scalar.moved(d, p, q, 3, self.point), c)
        if scalar.norm(scalar.reject(reach, d[0])) <= scalar.MARGIN * self.on_axis:  # the point near axis 1
            raise scalar.NotGeneric
        shoulder = scalar.side_code(scalar.dot(reach, forward), scalar.norm(reach))
        elbow = scalar.sub(scalar.moved(d, p, q, 2, p[2]), c)
        if self.in_plane:  # in the arm's plane, normal to axis 2
            normal = scalar.rotate(d[0], q[0], d[1])
            elbow, reach = scalar.reject(elbow, normal), scalar.reject(reach, normal)
        length = scalar.norm(reach)
        line = (reach[0] / length, reach[1] / length, reach[2] / length)
        side = scalar.dot(scalar.reject(elbow, line), self.up)
        return shoulder, scalar.side_code(side, scalar.norm(elbow)), scalar.wrist_code(q[4])

    def solve(self, T: np.ndarray) -> list[list[float]]:
        (R_T0, R_T1, R_T2, t_T) = T[:3].T.tolist()  # the target's columns
        R_T = tuple(zip(R_T0, R_T1, R_T2))  # rows
        H, h = self.home_inverse
        R_target = scalar.mm(R_T, H)
        # the wrist point: (T · home⁻¹) · point
        translation = scalar.add(scalar.mv(R_T, h), tuple(t_T))
        point_world = scalar.add(scalar.mv(R_target, self.point), translation)
        d, p, c, w = self.directions, self.points, self.centre, self.point
        target = scalar.sub(point_world, c)
        third = scalar.subproblem_3(d[2], self.frame_3, scalar.sub(w, p[2]), scalar.sub(c, p[2]), scalar.norm(target))
        joints = []
        for q3 in third:
            w3 = scalar.add(p[2], scalar.rotate(d[2], q3, scalar.sub(w, p[2])))
            for q1, q2 in scalar.subproblem_2_chain(d[0], d[1], scalar.sub(w3, c), target):
                R_G = scalar.mm(scalar.mm(scalar.rotation(d[0], q1), scalar.rotation(d[1], q2)), scalar.rotation(d[2], q3))
                R_H = scalar.mtm(R_G, R_target)
                for qa, qb, qc in self._wrist(R_H):
                    joints.append([q1, q2, q3, qa, qb, qc])
        return joints

    def _wrist(self, R_w: scalar.Matrix) -> list[tuple[float, float, float]]:
        a, b, c = self.axes
        target_axis = scalar.mv(R_w, c)
        wanted = scalar.mv(R_w, self.normal)
        roots = []
        for qa, qb in scalar.subproblem_2_chain(a, b, c, target_axis):
            unwound = scalar.rotate(b, -qb, scalar.rotate(a, -qa, wanted))
            roots.append((qa, qb, scalar.subproblem_1(c, self.frame_c, self.normal, unwound)))
        return roots
