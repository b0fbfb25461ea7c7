"""6R arms whose last three axes (4, 5, 6) are parallel; by the reversed chain also the first three.

With ω the common direction of axes 4–6, A = world_T_target · home⁻¹ =
G_1 ⋯ G_6 and R_123 = R_1 R_2 R_3:

1. ``R_A ω = R_123 ω =: v`` (turns about ω leave it fixed), so
   ``ω_2·R_3 ω = ω_2·R_1ᵀ v``; and G_4 G_5 G_6 keeps components along ω, so for
   the point p_4 the component of ``A p_4`` along v fixes the point ``G_1 G_2 p_3``
   along v, where ``v·R_1 R_2 (p_3 − p_2) = (R_3 ω)·(p_3 − p_2)``:

   ``v·R(ω_1, q_1)(p_2 − p_1) + (p_3 − p_2)·R(ω_3, q_3) ω = v·(A p_4 − p_1) − ω·(p_4 − p_3)``,
   ``v·R(ω_1, q_1) ω_2 − ω_2·R(ω_3, q_3) ω = 0``:

   subproblem 6, up to four pairs (q_1, q_3).
2. ``R(ω_2, q_2) R_3 ω = R_1ᵀ v``: subproblem 1.
3. R_456 = R_123ᵀ R_A is a turn about ω by the signed sum q_4 + q_5 + q_6: subproblem 1.
4. The point ``z = (G_1 G_2 G_3)⁻¹ A p_6`` is reached from p_4 by the planar pair 4, 5:
   subproblem 3 for q_5 (two roots), subproblem 1 for q_4, q_6 from the sum.

4 × 2 = 8 solutions in general.
"""

from __future__ import annotations

import numpy as np

from .._angles import wrap_angle
from ._positioning import side_codes
from .._forward import JointTrig, cross, radius_about
from ._screws import (apply, chain_rotation, invert, joint_motion, move_point, perpendicular_unit, rotate_about,
                      rotation_about)
from ._structure import Geometry
from .subproblems import subproblem_1, subproblem_3, subproblem_6
from ._types import Candidates, LabelCodes, SingularFlags, Singularity, Sealed
from ._three_parallel import _split_double_root


class ThreeParallelAtEndPlan(Sealed):
    """Axes 4 ∥ 5 ∥ 6, axes 1–3 of any other geometry (axis 3 not parallel to them)."""

    method = "analytic"
    structure = "three_parallel_at_end"
    generic_count = 8
    free_joints: list[int] = []

    @classmethod
    def match(cls, geometry: Geometry) -> "ThreeParallelAtEndPlan | None":
        if geometry.dof != 6 or geometry.kinds() != "RRRRRR":
            return None
        if not (geometry.parallel(3, 4) and geometry.parallel(3, 5)) or geometry.nearly_parallel(2, 3):
            return None
        # step 1 turns ω_2 by q_1 and ω by q_3: axes 1 and 2, or 2 and 3, (nearly) parallel leave one of them
        # fixed only by a rounding of the geometry; axis 1 exactly parallel to ω is the free base, nearly parallel
        # goes to the idealised arm
        if geometry.nearly_parallel(0, 1) or geometry.nearly_parallel(1, 2) \
                or (geometry.nearly_parallel(0, 3) and not geometry.parallel(0, 3)):
            return None
        return cls(geometry)

    def __init__(self, geometry: Geometry) -> None:
        self.geometry = geometry
        self.model = geometry.model
        self.home_inverse = invert(self.model.home)
        self.omega = geometry.direction(3)
        self.signs = np.array([np.sign(geometry.direction(j) @ self.omega) for j in (3, 4, 5)])
        self.normal = perpendicular_unit(self.omega)
        # the range of ||R(ω_5, q) (p_6 − p_5) − (p_4 − p_5)|| over q: the reach of the pair 4, 5 from axis 4
        along = geometry.direction(4)
        a, b = geometry.point(5) - geometry.point(4), geometry.point(3) - geometry.point(4)
        ra, rb = np.linalg.norm(a - (a @ along) * along), np.linalg.norm(b - (b @ along) * along)
        rise = (a - b) @ along
        self.reach = (float(np.hypot(ra - rb, rise)), float(np.hypot(ra + rb, rise)))
        # the bend of joint 5 at which axes 4, 5, 6 lie on one line in the plane normal to ω, p_6 beyond p_5
        w = self.omega
        def planar(x: np.ndarray) -> np.ndarray:
            return x - (x @ w) * w
        beyond, before = planar(geometry.point(5) - geometry.point(4)), planar(geometry.point(4) - geometry.point(3))
        self.stretched5 = (float(np.arctan2(cross(beyond, before) @ geometry.direction(4), beyond @ before))
                           if np.linalg.norm(beyond) * np.linalg.norm(before) > 0 else 0.0)

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        g, w = self.geometry, self.omega
        n = len(world_T_targets)
        A = world_T_targets @ self.home_inverse  # (N, 4, 4)
        R_A = A[:, :3, :3]
        v = R_A @ w  # (N, 3)
        p1, p2, p3, p4, p5, p6 = (g.point(j) for j in range(6))
        h1, h2, h3 = g.direction(0), g.direction(1), g.direction(2)
        height = np.einsum("ni,ni->n", v, apply(A, p4) - p1) - w @ (p4 - p3)
        pair = subproblem_6(h1, h3, v, p2 - p1, p3 - p2, w, height, v, h2, -h2, w, 0.0)
        q1, q3 = pair.theta1, pair.theta2  # (N, 4)
        R3w = rotate_about(h3, q3, w)
        if pair.degenerate.any():
            q1 = np.where(pair.degenerate[:, None], self._free_base(A, v, q3, R3w, reference), q1)
        R1 = rotation_about(h1, q1)
        second = subproblem_1(h2, R3w, np.einsum("nsji,nj->nsi", R1, v))
        q2 = second.theta[..., 0]
        free_two = second.degenerate
        if free_two.any():
            q2 = np.where(free_two, 0.0 if reference is None else reference[1], q2)
        M3 = (joint_motion(h1, p1, True, q1) @ joint_motion(h2, p2, True, q2) @ joint_motion(h3, p3, True, q3))
        R456 = np.swapaxes(M3[..., :3, :3], -1, -2) @ R_A[:, None]
        angle_sum = subproblem_1(w, self.normal, R456 @ self.normal).theta[..., 0]  # (N, 4)
        z = apply(invert(M3), apply(A, p6)[:, None])  # (N, 4, 3)
        elbow = subproblem_3(g.direction(4), p6 - p5, p4 - p5, np.linalg.norm(z - p4, axis=-1))
        q5 = elbow.theta  # (N, 4, 2)
        moved = p5 + rotate_about(g.direction(4), q5, p6 - p5)
        fourth = subproblem_1(g.direction(3), moved - p4, (z - p4)[..., None, :])
        q4 = fourth.theta[..., 0]
        s4, s5, s6 = self.signs
        q6 = s6 * (angle_sum[..., None] - s4 * q4 - s5 * q5)
        shape = (n, 4, 2)
        joints = np.stack([np.broadcast_to(q1[..., None], shape), np.broadcast_to(q2[..., None], shape),
                           np.broadcast_to(q3[..., None], shape), q4, q5, q6], axis=-1)
        valid = pair.valid[..., None] & elbow.valid
        valid[..., 1] &= ~elbow.merged
        singular = SingularFlags(n)
        singular.add(pair.degenerate, Singularity("base", (0, 3, 4, 5), "free",
                                                  "axis 1 is parallel to axes 4–6: joint 1 is free and set to "
                                                  "the reference value (or 0); q4, q5 and q6 follow it"))
        singular.add(pair.merged, Singularity("base", (0, 2), "boundary", "two (q1, q3) solutions meet"))
        relation = "sum" if np.all(self.signs > 0) else "signed_sum"
        singular.add((free_two & pair.valid).any(axis=1),
                     Singularity("base", (1, 3, 4, 5), relation,
                                 "axis 2 is parallel to axes 4–6: only q2 and q4 + q5 + q6 together are determined; "
                                 "q2 is set to the reference value (or 0)"))
        merged = (elbow.merged | _split_double_root(q5, valid)) & valid[..., 0]
        merged_rows = merged.any(axis=1)
        if merged_rows.any():
            first = np.argmax(merged, axis=1)
            bend = q5[..., 0][np.arange(n), first] - self.stretched5
            stretched = np.cos(bend) > 0
            for kind, mask in (("stretched", merged_rows & stretched), ("folded", merged_rows & ~stretched)):
                singular.add(mask, Singularity("elbow", (4,), kind, f"axes 4–6 are {kind} in line"))
        return Candidates(joints.reshape(n, 8, 6), valid.reshape(n, 8), singular)

    def _free_base(self, A: np.ndarray, v: np.ndarray, q3: np.ndarray, R3w: np.ndarray,
                   reference: np.ndarray | None) -> np.ndarray:
        """q1 (N, 4) where axis 1 is parallel to axes 4–6 (v = ±ω_1): joints 1, 4, 5, 6 then form a planar chain
        with one self-motion, and subproblem 6 leaves q1 free. The representative q1 puts the point of axis 6 at
        the middle of the distances from axis 4 that both joint 1 and the pair 4, 5 can give:
        ``||G_1⁻¹ A p_6 − G_2 G_3 p_4|| = δ``, subproblem 3; the root nearest the reference value (or 0)."""
        g = self.geometry
        p1, p2, p3, p4 = (g.point(j) for j in range(4))
        h1, h2, h3 = g.direction(0), g.direction(1), g.direction(2)
        q2 = subproblem_1(h2, R3w, np.broadcast_to(v[:, None], R3w.shape)).theta[..., 0]  # R_1ᵀ v = v here
        y = joint_motion(h2, p2, True, q2) @ joint_motion(h3, p3, True, q3)
        y = apply(y, p4)  # (N, 4, 3): G_2 G_3 p_4
        # the distance that joint 1 sweeps, [near, far], meets the reach of the pair 4, 5 (the pose is reached)
        tip = np.broadcast_to((apply(A, g.point(5)) - p1)[:, None], y.shape)
        radial = radius_about(h1, tip), radius_about(h1, y - p1)
        rise = (tip - (y - p1)) @ h1
        near, far = np.hypot(radial[0] - radial[1], rise), np.hypot(radial[0] + radial[1], rise)
        low, high = np.maximum(near, self.reach[0]), np.minimum(far, self.reach[1])
        roots = subproblem_3(-h1, tip, y - p1, 0.5 * (low + np.maximum(low, high)))
        target = 0.0 if reference is None else float(reference[0])
        near = np.argmin(np.abs(wrap_angle(np.nan_to_num(roots.theta, nan=1e9) - target)), axis=-1)
        return np.take_along_axis(roots.theta, near[..., None], -1)[..., 0]

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        return {"elbow": parallel_elbow_codes(self.geometry, joints, 3, trig)}


def parallel_elbow_codes(geometry: Geometry, joints: np.ndarray, first: int, trig: JointTrig | None = None
                         ) -> tuple[tuple[str, str], np.ndarray]:
    """Elbow up/down of the planar chain of parallel axes first, first + 1, first + 2, for joints (M, n): the side
    of the line from the first axis to the third that the middle axis lies on, along the robot's up direction,
    measured in the plane normal to the parallel axes (−1 where it is on the line, or where that plane holds no
    up: the parallel axes vertical)."""
    m = geometry.model
    trig = JointTrig(joints) if trig is None else trig  # each joint's cos and sin, shared by the turns below
    def moved(upto: int, x: np.ndarray) -> np.ndarray:
        return move_point(m.directions[:upto], m.points[:upto], m.is_revolute[:upto], joints[:, :upto], x, trig)

    start, middle, end = (moved(first + j, geometry.point(first + j)) for j in range(3))
    normal = chain_rotation(m.directions[:first], m.is_revolute[:first], joints[:, :first], trig) \
        @ geometry.direction(first)
    def planar(x: np.ndarray) -> np.ndarray:
        return x - np.einsum("mi,mi->m", x, normal)[:, None] * normal

    elbow, reach = planar(middle - start), planar(end - start)
    line = reach / np.maximum(np.linalg.norm(reach, axis=-1, keepdims=True), 1e-300)
    rejection = elbow - np.einsum("mi,mi->m", elbow, line)[:, None] * line
    up = planar(np.broadcast_to(geometry.up, normal.shape))
    return ("up", "down"), side_codes(np.einsum("mi,mi->m", rejection, up), np.linalg.norm(elbow, axis=-1))
