"""Two revolute joints, a spherical wrist, then a slide: the telescoping tool of an RR–RRR–P arm.

The slide comes after the wrist, so the wrist centre is not fixed by the target: it lies on a line
whose direction the target sets. A slide does not turn anything, so the rotation of the five
revolute joints is known from the target, ``Q = R_target · R_home⁻¹``. With c the wrist centre and
v its slide direction at q = 0, the wrist joints keep c and turn the slide, so
``G₁G₂(c) = x_c − s Q v`` where ``x_c = world_T_target · home⁻¹ · c`` (the wrist centre if the slide
were at 0). That is subproblem 5 with a slide of per-target direction
(:func:`~.subproblems.subproblem_5_prismatic`): up to 4 ``(q₁, q₂, s)``. Each leaves the wrist
``R_w = (R₁R₂)ᵀ Q``: 2 solutions, 8 in all.
"""

from __future__ import annotations

import numpy as np

from .._forward import JointTrig
from ._screws import apply, chain_rotation, invert
from ._structure import Geometry
from .subproblems import subproblem_5_prismatic
from ._types import Candidates, LabelCodes, SingularFlags, Singularity
from ._wrist import SphericalWrist, seen_by


class SlideAfterSphericalWrist:
    """Revolute joints 1, 2, a spherical wrist over joints 3–5 and a slide as joint 6; see the module notes."""

    method = "analytic"
    structure = "revolute_pair+spherical_wrist+slide"
    generic_count = 8
    free_joints: list[int] = []

    @classmethod
    def match(cls, geometry: Geometry) -> "SlideAfterSphericalWrist | None":
        if geometry.dof != 6 or geometry.kinds() != "RRRRRP":
            return None
        centre = geometry.common_point((2, 3, 4))
        if centre is None or geometry.on_axis(1, centre) or geometry.intersection(0, 1) is not None \
                or geometry.parallel(0, 1):
            return None  # the wrist centre must move on a circle about a skew axis 2
        return cls(geometry, centre)

    def __init__(self, geometry: Geometry, centre: np.ndarray) -> None:
        self.geometry = geometry
        self.model = geometry.model
        self.centre = centre
        self.home_inverse = invert(self.model.home)
        self.wrist = SphericalWrist(geometry, (2, 3, 4))

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        g, c, n_targets = self.geometry, self.centre, len(world_T_targets)
        motion = world_T_targets @ self.home_inverse
        Q = motion[:, :3, :3]
        centre_world = apply(motion, c)  # (N, 3): the wrist centre with the slide at 0
        k1, k2, o1, o2 = g.direction(0), g.direction(1), g.point(0), g.point(1)
        sol = subproblem_5_prismatic(k1, k2, o2 - o1, c - o2, centre_world - o1, -(Q @ g.direction(5)),
                                     slide_turns=False)
        q1 = sol.phi
        if sol.phi_free.any():  # the wrist centre on axis 1
            q1 = np.where(sol.phi_free, 0.0 if reference is None else reference[0], q1)
        arm = np.stack([q1, sol.theta], axis=-1)  # (N, 4, 2)
        # (N, 4, j, 3): R_armᵀ Q applied to the wrist's vectors, as rows times R_arm
        seen = seen_by(self.wrist, Q)[:, None] @ chain_rotation(self.model.directions[:2],
                                                                self.model.is_revolute[:2], np.nan_to_num(arm))
        wrist = self.wrist.solve(seen.reshape((-1,) + seen.shape[-2:]), reference)
        m_wrist = wrist.joints.shape[1]
        joints = np.zeros((n_targets, 4, m_wrist, 6))
        joints[..., :2] = arm[:, :, None, :]
        joints[..., 2:5] = wrist.joints.reshape(n_targets, 4, m_wrist, 3)
        joints[..., 5] = sol.s[:, :, None]
        arm_ok = sol.valid & sol.exact
        valid = arm_ok[:, :, None] & wrist.valid.reshape(n_targets, 4, m_wrist)
        singular = SingularFlags(n_targets)
        singular.add(sol.phi_free.any(axis=1), Singularity("shoulder", (0,), "free", "the wrist centre is on the "
                                                           "first joint's axis; joint 1 is set to the reference "
                                                           "value (or 0)"))
        singular.add(sol.merged, Singularity("positioner", (0, 1, 5), "boundary", "two solutions of joints 1, 2 "
                                             "and the slide meet: the wrist centre's line touches its workspace"))
        for mask, flag in wrist.singularities.entries:
            singular.add((mask.reshape(n_targets, 4) & arm_ok).any(axis=1), flag)
        return Candidates(joints.reshape(n_targets, -1, 6), valid.reshape(n_targets, -1), singular)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        return self.wrist.label_codes(joints, trig)
