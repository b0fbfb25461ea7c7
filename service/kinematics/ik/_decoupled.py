"""Kinematic decoupling: a positioning arm places a point, wrist joints about it set the orientation.

Spong §4.2 done generally. The point P is where the wrist axes meet (a
spherical wrist), a point on the last axis (a roll), or the tool origin (no
wrist). The wrist joints leave P where it is, so
``P_world = world_T_target · home⁻¹ · P`` is known from the target alone; the
positioner solves for it; then ``H = (G_1 ⋯ G_k)⁻¹ · world_T_target · home⁻¹``
is the motion left to the wrist, whose rotation it solves.
"""

from __future__ import annotations

import numpy as np

from ._positioning import Positioner
from ._screws import apply, chain_rotation, invert
from ._types import Branch, Candidates, LabelCodes, SingularFlags, branches_from_codes
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
            return Candidates(joints, arm_valid, [], singular)
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
        return Candidates(full.reshape(n_targets, m_arm * m_wrist, self.dof), valid.reshape(n_targets, -1), [],
                          singular)

    def labels(self, joints: np.ndarray) -> list[Branch]:
        return branches_from_codes(self.label_codes(joints), len(joints))

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        """Branch labels of full joint vectors (M, n) as arrays: the positioner's, then the wrist's."""
        codes: LabelCodes = {}
        for part in (self.positioner, self.wrist):
            if part is not None:
                codes.update(part.label_codes(joints))
        return codes
