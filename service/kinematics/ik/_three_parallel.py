"""6R arms whose joints 2, 3 and 4 have parallel axes: axes 5 and 6 meeting (UR5 type) or skew.

With ω_p the common direction of axes 2–4, A = world_T_target · home⁻¹ =
G_1 ⋯ G_6, and c the point where axes 5 and 6 meet:

1. Turning about axes parallel to ω_p keeps the component along ω_p, and
   G_5, G_6 leave c fixed, so ``ω_p·R(ω_1, −q_1)(A c − p_1) = ω_p·(c − p_1)``:
   subproblem 4, two shoulder roots.
2. For the rotations, ``R_1ᵀ R_A ω_6 = R_234 R(ω_5, q_5) ω_6`` with R_234 a turn
   about ω_p: subproblem 2, two wrist roots (on the whole vector: its height along
   ω_p alone holds q_5 only to second order near the wrist singularity).
3. ``R(ω_6, −q_6) R(ω_5, −q_5) ω_p = (R_1ᵀ R_A)ᵀ ω_p``: subproblem 1.
4. What is left, R_234, is a turn about ω_p by the (signed) sum q_2 + q_3 + q_4:
   subproblem 1. Where axis 6 lies along ω_p (the wrist singularity) step 3 leaves
   q_6 free for the rotation but not for step 5, which needs a q_6 the elbow reaches.
   Those values form one arc or two separate ones (two families of solutions); a
   second arc gets the slot of the other wrist root, which meets the first there.
5. The point p_4 on axis 4 reaches ``G_1⁻¹ A G_6⁻¹ G_5⁻¹ p_4`` through joints 2
   and 3: subproblem 3 for q_3 (two elbow roots), subproblem 1 for q_2, and
   q_4 from the sum.

2 × 2 × 2 = 8 solutions in general.

When axes 5 and 6 are skew (:class:`SkewWristThreeParallelPlan`) steps 1 and 2
are one subproblem 6 in (q_1, q_5), whose roots near the wrist singularity are
refined on the parts of the axes normal to ω_p (two of them meet there); steps
3–5 are the same.
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from . import _scalar as scalar
from .._angles import wrap_angle, wrap_any_float
from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from ._positioning import _flag_rows, _unit, side_codes
from .._forward import JointTrig, cross, radius_about
from ._screws import apply, invert, joint_motion, move_point, perpendicular_unit, rotate_about
from ._structure import Geometry, read_off_below, read_off_error
from .subproblems import subproblem_1, subproblem_2, subproblem_3, subproblem_4, subproblem_6
from ._types import LEAN_CHUNK, NEAR_SINGULAR, Candidates, LabelCodes, SingularFlags, Singularity, Sealed
from ._wrist import wrist_codes


class _AxesTwoToFourParallel(Sealed):
    """What the families with axes 2 ∥ 3 ∥ 4 share: steps 3–5 from candidate pairs (q1, q5), and the labels.
    A family supplies ``match`` and ``_shoulder_and_wrist`` (steps 1 and 2)."""

    method = "analytic"
    generic_count = 8
    free_joints: list[int] = []
    centre: np.ndarray

    def __init__(self, geometry: Geometry, centre: np.ndarray) -> None:
        self.geometry = geometry
        self.model = geometry.model
        self.centre = centre
        self.home_inverse = invert(self.model.home)
        self.omega_p = geometry.direction(1)
        self.signs = np.array([np.sign(geometry.direction(j) @ self.omega_p) for j in (1, 2, 3)])
        self.normal_p = perpendicular_unit(self.omega_p)
        forward = _unit(cross(geometry.direction(0), self.omega_p))
        reach = geometry.point(3) - geometry.point(0)
        self.forward = forward if forward @ reach >= 0 else -forward
        # the elbow's subproblem 3 (the point on axis 4 about axis 3, at a distance from axis 2): its least and
        # greatest distances and their radii's product ρ; and the error q6 is read off with (step 3)
        least, greatest = _distance_range(geometry.direction(2), geometry.point(3) - geometry.point(2),
                                          geometry.point(1) - geometry.point(2))
        self.elbow_range = float(least), float(greatest)
        self.elbow_rho = float(greatest**2 - least**2) / 4
        self.sixth_error = read_off_error(geometry)

    def split_band(self, distance, sixth_radius, lever_radius):
        """How far apart (rad) the two elbow roots may be and still be one double root split by the error of q6
        (floats, or arrays of candidates): :data:`SPLIT_DOUBLE_ROOT`, or wider where q6 was read off a short
        ``sixth_radius`` (the wrist near its singularity: axis 6 nearly along ω_p). q6's error, the read-off error
        over that radius, moves the point on axis 4 by its ``lever_radius`` about axis 6 times as much, and the
        ``distance`` asked of the elbow with it; the roots ±half about a double root move by ρ (1 − cos half) =
        distance · that error, so roots within 2 √(2 distance · error / ρ) of each other cannot be told from one
        (a UR3e folded to 6e-7 rad with q5 1.3e-9 from π: q6 known to 2.5e-7, the roots ±1.5e-4 rad)."""
        moved = lever_radius * self.sixth_error / sixth_radius
        return 2.0 * (2.0 * distance * moved / self.elbow_rho) ** 0.5

    def wrist_volume(self, joints: np.ndarray) -> np.ndarray:
        """How far the wrist is from its singularity at joint vectors (..., n), shape (...,): the sine of the angle
        between axis 6 and the parallel axes, which depends on q5 alone (joints 1–4 turn both alike), 0 where they
        align (:meth:`.DecoupledPlan.wrist_volume`'s counterpart, which :class:`.IdealisedPlan` bands)."""
        return self._sixth_radius(joints[..., 4])

    def _sixth_radius(self, q5: np.ndarray) -> np.ndarray:
        """ω_p turned back by q5 about axis 5, as step 3 reads q6 off it: its radius about axis 6 (...,)."""
        return radius_about(self.geometry.direction(5), rotate_about(self.geometry.direction(4), -q5, self.omega_p))

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        A = world_T_targets @ self.home_inverse  # (N, 4, 4)
        singular = SingularFlags(len(A))
        q1, q5, valid = self._shoulder_and_wrist(A, singular, reference)
        return self._complete(A, q1, q5, valid, singular, reference)

    def _shoulder_and_wrist(self, A: np.ndarray, singular: SingularFlags,
                            reference: np.ndarray | None) -> tuple[np.ndarray, ...]:
        raise NotImplementedError

    def _complete(self, A: np.ndarray, q1: np.ndarray, q5: np.ndarray, valid15: np.ndarray,
                  singular: SingularFlags, reference: np.ndarray | None) -> Candidates:
        """Steps 3–5 from candidate pairs (q1, q5) of shape (N, m): 2m joint vectors per target.

        Every product of the joints' motions is applied to the few vectors it acts on, as turns about the axes
        (:func:`rotate_about`, (N, m, 3), or (N, m, 2, 3) for two at once), not built as (N, m, 4, 4) matrices: R_1ᵀ R_A v is
        R(ω_1, −q_1) (R_A v), and G_5⁻¹ x is R(ω_5, −q_5) (x − p_5) + p_5."""
        g, w_p = self.geometry, self.omega_p
        n, m = q1.shape
        R_A, t_A = A[:, None, :3, :3], A[:, None, :3, 3]  # (N, 1, 3, 3), (N, 1, 3)
        # 3. q6: R(ω_6, −q_6) R(ω_5, −q_5) ω_p = R_Aᵀ R_1 ω_p
        p = rotate_about(g.direction(4), -q5, w_p)  # (N, m, 3)
        q = np.einsum("...ji,...j->...i", R_A, rotate_about(g.direction(0), q1, w_p))
        # q6 read off unit vectors: held free where the arm's deviation over their radius would move it
        sixth = subproblem_1(g.direction(5), p, q, free_below=read_off_below(g))
        q6 = -sixth.theta[..., 0]
        free_six = sixth.degenerate
        unrepresented = np.zeros(n, dtype=bool)
        if free_six.any():
            q6 = np.where(free_six, 0.0 if reference is None else reference[5], q6)
            q6, other_arc = self._reachable_sixth(A, q1, q5, q6, free_six)
            if np.isfinite(other_arc).any():
                q1, q5, q6, valid15, free_six, unrepresented = _second_arc_slots(
                    q1, q5, q6, valid15, free_six, other_arc)
        # 4. R_234 = R_1ᵀ R_A R_6ᵀ R_5ᵀ about ω_p: the signed sum, from where it turns the normal n_p; and
        # 5. the point on axis 4 through joints 2 and 3: G_1 G_2 G_3 p_4 = A G_6⁻¹ G_5⁻¹ p_4 (G_4 leaves p_4 where
        # it is). Both undo joint 5, then joint 6, then the target, then joint 1.
        undone_5 = rotate_about(g.direction(4), -q5[..., None], np.stack([self.normal_p, g.point(3) - g.point(4)]))
        undone_5[..., 1, :] += g.point(4) - g.point(5)
        lever = undone_5[..., 1, :]  # the point on axis 4 from axis 6's point, before q6 turns it (N, m, 3)
        undone_6 = rotate_about(g.direction(5), -q6[..., None], undone_5)  # (N, m, 2, 3)
        undone_6[..., 1, :] += g.point(5)
        in_world = np.einsum("...ij,...kj->...ki", R_A, undone_6)
        in_world[..., 1, :] += t_A - g.point(0)
        undone_1 = rotate_about(g.direction(0), -q1[..., None], in_world)
        angle_sum = subproblem_1(w_p, self.normal_p, undone_1[..., 0, :]).theta[..., 0]  # (N, m)
        z = undone_1[..., 1, :] + g.point(0)  # (N, m, 3)
        distance = np.linalg.norm(z - g.point(1), axis=-1)
        elbow = subproblem_3(g.direction(2), g.point(3) - g.point(2), g.point(1) - g.point(2), distance)
        q3 = elbow.theta  # (N, m, 2)
        moved = g.point(2) + rotate_about(g.direction(2), q3, g.point(3) - g.point(2))
        second = subproblem_1(g.direction(1), moved - g.point(1), (z - g.point(1))[..., None, :])
        q2 = second.theta[..., 0]
        s2, s3, s4 = self.signs
        q4 = s4 * (angle_sum[..., None] - s2 * q2 - s3 * q3)
        shape = (n, m, 2)
        joints = np.stack([np.broadcast_to(q1[..., None], shape), q2, q3, q4,
                           np.broadcast_to(q5[..., None], shape), np.broadcast_to(q6[..., None], shape)], axis=-1)
        valid = valid15[..., None] & elbow.valid
        valid[..., 1] &= ~elbow.merged
        relation = "sum" if np.all(self.signs > 0) else "signed_sum"
        _flag_rows((free_six & valid15).any(axis=1), Singularity("wrist", (1, 2, 3, 5), relation,
                                                   "axis 6 is parallel to axes 2–4: only q2 + q3 + q4 and q6 "
                                                   "together are determined; q6 is set to the reference value "
                                                   "(or 0), or where the elbow cannot reach with it, to the "
                                                   "nearer of two values it reaches with; where the values the "
                                                   "elbow reaches with form two separate arcs, the other arc is "
                                                   "represented too, by the other of those two values"), singular)
        singular.add(unrepresented, Singularity(
            "wrist", (1, 2, 3, 5), relation, "the values of q6 the elbow reaches with form two separate arcs "
            "and no candidate slot was left for the second one: its solutions are missing (complete: false)"))
        sixth_radius = self._sixth_radius(q5)  # (q5 as the slots hold it after a second arc)
        with np.errstate(divide="ignore", invalid="ignore"):
            band = self.split_band(distance, sixth_radius, radius_about(g.direction(5), lever))
        band = np.where(free_six, SPLIT_DOUBLE_ROOT, np.fmax(band, SPLIT_DOUBLE_ROOT))  # q6 held, not read: exact
        merged = (elbow.merged | _split_double_root(q3, valid, band)) & valid[..., 0]
        merged_rows = merged.any(axis=1)
        if merged_rows.any():
            first = np.argmax(merged, axis=1)  # the first merged slot of each row, as argwhere found it
            stretched = np.cos(q3[..., 0][np.arange(n), first]) > 0
            for kind, mask in (("stretched", merged_rows & stretched), ("folded", merged_rows & ~stretched)):
                singular.add(mask, Singularity("elbow", (2,), kind, f"the arm is fully {kind}"))
        # a free q1 (the wrist point on axis 1) held where the elbow reaches with no wrist root: another q1 may
        # reach, so the empty row is no proof (the fallback searches)
        shoulder_free = np.zeros(n, dtype=bool)
        for mask, flag in singular.entries:
            if flag.kind == "shoulder" and flag.relation == "free":
                shoulder_free |= mask
        unpromised = unrepresented | (shoulder_free & ~valid.any(axis=(1, 2)))
        near = np.repeat(sixth_radius <= NEAR_SINGULAR, 2, axis=1)  # both elbow roots of each (q1, q5)
        return Candidates(joints.reshape(n, 2 * m, 6), valid.reshape(n, 2 * m), singular,
                          complete=~unpromised if unpromised.any() else None, near_singular=near)

    def _reachable_sixth(self, A: np.ndarray, q1: np.ndarray, q5: np.ndarray, q6: np.ndarray,
                         free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """q6 where axis 6 lies along the parallel axes (``free``, (N, m)): the orientation leaves it free, the
        position does not. Turning about axis 6 carries the point on axis 4 round axis 6 (the two are apart), so
        the elbow (step 5) reaches that point only for some values of q6. The value given (the reference, or 0)
        stays where the elbow reaches; elsewhere q6 becomes the nearer of the two values that put the point in the
        middle of the distances from axis 2 that both the turn and the elbow can give, so the arm branch keeps its
        solutions (two elbow roots) instead of a least-squares slot the FK check rejects.

        The distance the elbow is asked for sweeps its range up and down once per turn. Where the elbow's band of
        distances lies strictly inside that range, the values it reaches with form two separate arcs, one where
        the distance rises and one where it falls, and each is a separate family of solutions: the two middle
        values lie one on each arc. Returns q6 (N, m) and a value on the other arc than q6's (N, m), NaN where
        the reachable values are one arc (or none)."""
        g = self.geometry
        R1 = joint_motion(g.direction(0), g.point(0), True, q1)  # (N, m, 4, 4): a rare path
        G5 = joint_motion(g.direction(4), g.point(4), True, q5)
        # the distance step 5 asks of the elbow is |R(ω_6, −q6) u − w|, u and w from a point on axis 6
        u = apply(invert(G5), g.point(3)) - g.point(5)  # (N, m, 3)
        w = apply(invert(A)[:, None], apply(R1, g.point(1))) - g.point(5)
        distance = np.linalg.norm(rotate_about(g.direction(5), -q6, u) - w, axis=-1)
        low_e, high_e = _distance_range(g.direction(2), g.point(3) - g.point(2), g.point(1) - g.point(2))
        low_c, high_c = _distance_range(g.direction(5), u, w)
        low, high = np.maximum(low_e, low_c), np.minimum(high_e, high_c)
        tol = GEOMETRY_TOLERANCE * (high_e + distance)
        out = free & ((distance < low_e - tol) | (distance > high_e + tol)) & (low <= high)
        two_arcs = free & (low_c < low_e - tol) & (high_e + tol < high_c)
        if not (out | two_arcs).any():
            return q6, np.full(q6.shape, np.nan)
        turn = subproblem_3(g.direction(5), u, w, np.where(out | two_arcs, 0.5 * (low + high), distance))
        candidates = -turn.theta  # (N, m, 2)
        gaps = np.abs(wrap_angle(candidates - q6[..., None]))
        nearer = np.where(np.nan_to_num(gaps[..., 0], nan=np.inf) <= np.nan_to_num(gaps[..., 1], nan=np.inf),
                          candidates[..., 0], candidates[..., 1])
        q6 = np.where(out, wrap_angle(nearer), q6)

        def rising(sixth: np.ndarray) -> np.ndarray:
            """Whether the distance grows with q6 there: the sign of its derivative, ω_6 · (R(ω_6, −q6) u × w)."""
            return cross(rotate_about(g.direction(5), -sixth, u), w) @ g.direction(5) > 0

        # the two middle values mirror each other about the distance's extremes: one on each arc
        other = np.where(rising(q6) == rising(candidates[..., 0]), candidates[..., 1], candidates[..., 0])
        return q6, np.where(two_arcs, wrap_angle(other), np.nan)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """Shoulder left/right: the sign of the reach to axis 4 along link 1's forward direction. Elbow up/down:
        the side of the line from axis 2 to axis 4 that axis 3 lies on, along the robot's up direction, measured
        in the plane normal to the parallel axes (so the points the description puts on them do not matter).
        Wrist: the sign of sin q5 (:func:`wrist_codes`). ``trig``: the joints' cos and sin, when shared."""
        g, m = self.geometry, self.model
        trig = JointTrig(joints) if trig is None else trig  # each joint's cos and sin, shared by the turns below
        def moved(upto: int, x: np.ndarray) -> np.ndarray:
            return move_point(m.directions[:upto], m.points[:upto], m.is_revolute[:upto], joints[:, :upto], x, trig)

        forward = rotate_about(g.direction(0), joints[:, 0], self.forward, trig[0])
        wrist_point = moved(3, g.point(3))
        shoulder = np.einsum("mi,mi->m", wrist_point - g.point(0), forward)
        shoulder_point = moved(1, g.point(1))
        elbow_point = moved(2, g.point(2)) - shoulder_point
        reach = wrist_point - shoulder_point
        normal = rotate_about(g.direction(0), joints[:, 0], self.omega_p, trig[0])  # the parallel axes, after joint 1
        elbow_point = elbow_point - np.einsum("mi,mi->m", elbow_point, normal)[:, None] * normal
        reach = reach - np.einsum("mi,mi->m", reach, normal)[:, None] * normal
        line = reach / np.maximum(np.linalg.norm(reach, axis=-1, keepdims=True), 1e-300)
        rejection = elbow_point - np.einsum("mi,mi->m", elbow_point, line)[:, None] * line
        side = rejection @ g.upward(g.direction(0))
        return {"shoulder": (("left", "right"), side_codes(shoulder, np.linalg.norm(wrist_point - g.point(0), axis=-1))),
                "elbow": (("up", "down"), side_codes(side, np.linalg.norm(elbow_point, axis=-1))),
                **wrist_codes(trig[4][1])}


class ThreeParallelPlan(_AxesTwoToFourParallel):
    """The UR5-type family: axes 2 ∥ 3 ∥ 4, axes 5 and 6 intersecting."""

    structure = "three_parallel"
    targets_per_chunk = LEAN_CHUNK

    @classmethod
    def match(cls, geometry: Geometry) -> "ThreeParallelPlan | None":
        if geometry.dof != 6 or geometry.kinds() != "RRRRRR":
            return None
        if not (geometry.parallel(1, 2) and geometry.parallel(1, 3)) or geometry.nearly_parallel(0, 1):
            return None
        if geometry.nearly_parallel(1, 4):
            return None
        centre = geometry.intersection(4, 5)
        if centre is None:
            return None
        return cls(geometry, centre)

    def _shoulder_and_wrist(self, A: np.ndarray, singular: SingularFlags,
                            reference: np.ndarray | None) -> tuple[np.ndarray, ...]:
        """Steps 1 and 2: candidate pairs (q1, q5), shape (N, 4) each, and which exist (N, 4)."""
        g, w_p = self.geometry, self.omega_p
        n = len(A)
        c_world = apply(A, self.centre)
        # 1. shoulder: two roots for q1
        shoulder = subproblem_4(w_p, g.direction(0), c_world - g.point(0), w_p @ (self.centre - g.point(0)))
        q1 = -shoulder.theta  # (N, 2)
        if reference is not None:  # the centre on axis 1: any q1 puts it there, so q1 takes the reference value
            q1 = np.where(shoulder.degenerate[..., None], reference[0], q1)
        # 2. wrist: two roots for q5. R_1ᵀ R_A ω_6 = R_234 R(ω_5, q5) ω_6 with R_234 a turn about ω_p: subproblem 2
        # on the whole vector, not subproblem 4 on its height ω_p·R_1ᵀ R_A ω_6, which near the wrist singularity
        # (height cos q5) holds q5 only to second order and merged ±q5 below 5e-7 into q5 = 0.
        sixth_in_arm = rotate_about(g.direction(0), -q1, (A[:, :3, :3] @ g.direction(5))[:, None, :])  # (N, 2, 3)
        wrist = subproblem_2(w_p, g.direction(4), sixth_in_arm, g.direction(5))
        _flag_rows(shoulder.degenerate, Singularity("shoulder", (0,), "free",
                                                    "the wrist point is on the first axis; joint 1 is free, set to the reference value (or 0)"), singular)
        _flag_rows(shoulder.merged, Singularity("shoulder", (0,), "boundary",
                                                "the two shoulder solutions meet"), singular)
        valid = shoulder.valid[:, :, None] & wrist.valid
        return (np.broadcast_to(q1[:, :, None], (n, 2, 2)).reshape(n, 4), wrist.theta2.reshape(n, 4),
                valid.reshape(n, 4))

    def solve_one(self, world_T_target: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose | None:
        """:meth:`solve` of one target (4, 4) in scalar arithmetic (:mod:`._scalar`), with the slots' branch
        labels (:meth:`label_codes`) from the same quantities, or None when the pose is not clearly generic (then
        :meth:`solve` and :meth:`label_codes` decide). The one exception to "generic": the elbow may be clearly out
        of reach for some shoulder and wrist roots, which gives a least-squares slot and an empty one, as in
        :meth:`solve`. ``reference`` is not read: :meth:`solve` reads it only where this path declines."""
        try:
            return self._one_pose.solve(world_T_target)
        except scalar.NotGeneric:
            return None

    @cached_property
    def _one_pose(self) -> "_ThreeParallelOnePose":
        return _ThreeParallelOnePose(self)


class SkewWristThreeParallelPlan(_AxesTwoToFourParallel):
    """Axes 2 ∥ 3 ∥ 4 with axes 5 and 6 skew (no common point): steps 1 and 2 become one subproblem 6.

    With c a point on axis 6 (G_6 leaves it fixed) and G_2 G_3 G_4 keeping components along ω_p:

    * position: ``ω_p·R(ω_1, −q_1)(A c − p_1) − ω_p·R(ω_5, q_5)(c − p_5) = ω_p·(p_5 − p_1)``;
    * rotation: ``ω_p·R(ω_1, −q_1) R_A ω_6 − ω_p·R(ω_5, q_5) ω_6 = 0``.

    Subproblem 6 gives up to four pairs (q_1, q_5); steps 3–5 are the UR type's. Up to 4 × 2 = 8 solutions.
    """

    structure = "three_parallel_skew_wrist"

    @classmethod
    def match(cls, geometry: Geometry) -> "SkewWristThreeParallelPlan | None":
        if geometry.dof != 6 or geometry.kinds() != "RRRRRR":
            return None
        if not (geometry.parallel(1, 2) and geometry.parallel(1, 3)) or geometry.nearly_parallel(0, 1):
            return None
        if geometry.nearly_parallel(1, 4) or geometry.intersection(4, 5) is not None:
            return None
        return cls(geometry, geometry.point(5))

    def _shoulder_and_wrist(self, A: np.ndarray, singular: SingularFlags,
                            reference: np.ndarray | None) -> tuple[np.ndarray, ...]:
        g, w_p = self.geometry, self.omega_p
        c_world = apply(A, self.centre)  # the centre is a point on axis 6 here
        pair = subproblem_6(-g.direction(0), g.direction(4),
                            w_p, c_world - g.point(0), -w_p, self.centre - g.point(4), w_p @ (g.point(4) - g.point(0)),
                            w_p, A[:, :3, :3] @ g.direction(5), -w_p, g.direction(5), 0.0)
        if pair.degenerate.any():  # axis 6 on axis 1: only q1 + q6 (or q1 − q6, axes opposed) is determined
            same_sense = (A[:, :3, :3] @ g.direction(5)) @ g.direction(0) > 0
            for relation, rows in (("sum", same_sense), ("difference", ~same_sense)):
                singular.add(pair.degenerate & rows, Singularity(
                    "shoulder", (0, 5), relation, f"axis 6 lies on axis 1: only their {relation} is determined; "
                    "q1 is set to the reference value (or 0)"))
        singular.add(pair.merged, Singularity("shoulder", (0, 4), "boundary", "two (q1, q5) solutions meet"))
        q1 = pair.theta1
        if pair.degenerate.any():  # the equations do not involve q1 there, so q5 holds for any value of it
            q1 = np.where(pair.degenerate[:, None], 0.0 if reference is None else reference[0], q1)
            return q1, pair.theta2, pair.valid
        return self._refined_pairs(A, q1, pair.theta2, pair.valid)

    def _refined_pairs(self, A: np.ndarray, q1: np.ndarray, q5: np.ndarray,
                       valid: np.ndarray) -> tuple[np.ndarray, ...]:
        """Subproblem 6's pairs (q1, q5), shape (N, m), refined, with the root that met a pair's root restored.

        Subproblem 6 equates the heights along ω_p of w = R_1ᵀ R_A ω_6 and u = R(ω_5, q_5) ω_6. At the wrist
        singularity both are at an extreme (u = ±ω_p): two roots meet and the pair holds them only to the square
        root of the rounding (q5 ~ 1e-7 instead of 0); step 3 then turns q6 by whatever that error points to,
        where the elbow may not reach (no solution), and near it the second root is merged away. The same
        condition on the parts normal to ω_p, ``|w⊥|² = |u⊥|²``, keeps every digit there (1 − h² does not).
        Each step linearises w⊥ (in q1), u⊥ (in q5) and the position equation and solves the resulting
        quadratic on the position's line, moving to its root nearer the pair (:func:`_nearer_root_on_line`).

        Where that quadratic's other root lies within :data:`_PARTNER_REACH` and one of the two roots tilts axis 6
        off ω_p (step 3 fixes q6 there; where neither does, both are the one singular branch, q6 free), the other
        root is the merged one: it is refined the same way and takes a slot of its own (the pairs widen to make
        room, with one to spare). Returns q1, q5 and valid, (N, m) or wider."""
        near = valid & (self._wrist_tilt(np.where(valid, q5, 0.0)) < _REFINE_BELOW)
        if not near.any():
            return q1, q5, valid
        rows, slots = np.nonzero(near)
        targets = A[rows]  # one per refined pair, each pair (K, 1)
        root_1, root_5 = self._refined(targets, q1[rows, slots][:, None], q5[rows, slots][:, None])
        _, (other_1, other_5) = self._quadratic_step(targets, root_1, root_5)
        q1, q5 = q1.copy(), q5.copy()
        q1[rows, slots], q5[rows, slots] = wrap_angle(root_1[:, 0]), wrap_angle(root_5[:, 0])
        partner = (np.nan_to_num(np.hypot(other_1, other_5), nan=np.inf) <= _PARTNER_REACH)[:, 0]
        if not partner.any():
            return q1, q5, valid
        rows, slots, targets = rows[partner], slots[partner], targets[partner]
        partner_1, partner_5 = self._refined(targets, root_1[partner] + other_1[partner],
                                             root_5[partner] + other_5[partner])
        partner_1, partner_5 = wrap_angle(partner_1[:, 0]), wrap_angle(partner_5[:, 0])
        present = (valid[rows] & (np.abs(wrap_angle(partner_1[:, None] - q1[rows])) <= _SAME_ROOT)
                   & (np.abs(wrap_angle(partner_5[:, None] - q5[rows])) <= _SAME_ROOT)).any(axis=1)
        tilted = (self._wrist_tilt(q5[rows, slots]) > GEOMETRY_TOLERANCE) | (self._wrist_tilt(partner_5)
                                                                           > GEOMETRY_TOLERANCE)
        kept = tilted & ~present  # present: both roots were apart enough for subproblem 6
        if not kept.any():
            return q1, q5, valid
        rows, partner_1, partner_5 = rows[kept], partner_1[kept], partner_5[kept]
        # room for every partner and one slot to spare (a second arc of q6, :func:`_second_arc_slots`)
        extra = np.full((len(q1), int(np.bincount(rows).max()) + 1), np.nan)
        q1, q5 = np.concatenate([q1, extra], axis=1), np.concatenate([q5, extra], axis=1)
        valid = np.concatenate([valid, np.zeros(extra.shape, dtype=bool)], axis=1)
        for row, first, fifth in zip(rows.tolist(), partner_1.tolist(), partner_5.tolist()):
            spare = int(np.argmin(valid[row]))  # the first empty slot
            q1[row, spare], q5[row, spare], valid[row, spare] = first, fifth, True
        return q1, q5, valid

    def _refined(self, targets: np.ndarray, q1: np.ndarray, q5: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:data:`_REFINE_STEPS` steps of :meth:`_quadratic_step` from pairs (q1, q5) of shape (K, 1) for targets
        A (K, 4, 4)."""
        for _ in range(_REFINE_STEPS):
            (step_1, step_5), _ = self._quadratic_step(targets, q1, q5)
            q1, q5 = q1 + step_1, q5 + step_5
        return q1, q5

    def _quadratic_step(self, A: np.ndarray, q1: np.ndarray, q5: np.ndarray) -> tuple[tuple[np.ndarray, ...], ...]:
        """One step of :meth:`_refined_pairs` at pairs (q1, q5) of shape (N, m) for targets A (N, 4, 4): the step
        to the nearer root of the linearised equations and the step to the other, each a pair (Δq1, Δq5) of (N, m)."""
        g, w_p = self.geometry, self.omega_p
        axis_1, axis_5 = g.direction(0), g.direction(4)
        wanted = rotate_about(axis_1, -q1, (A[:, :3, :3] @ g.direction(5))[:, None, :])  # w = R_1ᵀ R_A ω_6
        turned = rotate_about(axis_5, q5, g.direction(5))  # u
        arm = rotate_about(axis_1, -q1, (apply(A, self.centre) - g.point(0))[:, None, :])
        offset = rotate_about(axis_5, q5, self.centre - g.point(4))
        position = arm @ w_p - offset @ w_p - w_p @ (g.point(4) - g.point(0))
        slope_1, slope_5 = -cross(axis_1, arm) @ w_p, -cross(axis_5, offset) @ w_p
        normal = self._normal_part
        return _nearer_root_on_line(normal(wanted), normal(-cross(axis_1, wanted)), normal(turned),
                                    normal(cross(axis_5, turned)), position, slope_1, slope_5)

    def _normal_part(self, v: np.ndarray) -> np.ndarray:
        """The part of vectors (..., 3) normal to the parallel axes."""
        return v - (v @ self.omega_p)[..., None] * self.omega_p

    def _wrist_tilt(self, q5: np.ndarray) -> np.ndarray:
        """|u⊥|, how far joint 5 tilts axis 6 off the parallel axes (q5's shape): at most GEOMETRY_TOLERANCE, step 3
        leaves q6 free, as :func:`subproblem_1` judges it."""
        g = self.geometry
        return np.linalg.norm(self._normal_part(rotate_about(g.direction(4), q5, g.direction(5))), axis=-1)


#: Steps of :meth:`SkewWristThreeParallelPlan._refined_pairs` (each converges quadratically, a double root in one)
_REFINE_STEPS = 3
#: Pairs that tilt axis 6 off ω_p by less than this are refined: subproblem 6 holds a root to about the rounding
#: over its distance from the other root, which is about this tilt (further off, its Newton steps suffice)
_REFINE_BELOW = 1e-2
#: How far (rad) the other root of the linearised equations may lie for it to be the root merged with a pair's
#: (the linearisation's error is the square of the step: 1e-4 leaves 1e-8, which the steps then remove)
_PARTNER_REACH = 1e-4
#: Refined roots closer than this (rad) are one: they agree to ~1e-15, and two roots that step 3 tells apart (one
#: tilting axis 6 more than GEOMETRY_TOLERANCE) lie ~1e-9 apart or more
_SAME_ROOT = 1e-11


def _nearer_root_on_line(w: np.ndarray, w_slope: np.ndarray, u: np.ndarray, u_slope: np.ndarray, position: np.ndarray,
                         slope_1: np.ndarray, slope_5: np.ndarray) -> tuple[tuple[np.ndarray, ...], ...]:
    """The steps (s1, s5) that solve ``|w + s1 w_slope|² = |u + s5 u_slope|²`` on the line
    ``position + slope_1 s1 + slope_5 s5 = 0``: the one nearer (0, 0) and the other (NaN where the quadratic has
    no second root). w, u and the slopes (..., 3); the rest (...). Where the roots are complex (a double root
    split by rounding) both are its vertex."""
    norm = np.hypot(slope_1, slope_5)
    norm = np.where(norm > 0.0, norm, 1.0)
    foot = -position / norm
    start_1, start_5 = foot * slope_1 / norm, foot * slope_5 / norm  # the point of the line nearest (0, 0)
    along_1, along_5 = -slope_5 / norm, slope_1 / norm
    a, a_slope = w + start_1[..., None] * w_slope, along_1[..., None] * w_slope
    b, b_slope = u + start_5[..., None] * u_slope, along_5[..., None] * u_slope
    quadratic = np.einsum("...i,...i", a_slope, a_slope) - np.einsum("...i,...i", b_slope, b_slope)
    half_linear = np.einsum("...i,...i", a, a_slope) - np.einsum("...i,...i", b, b_slope)
    constant = np.einsum("...i,...i", a - b, a + b)
    discriminant = np.maximum(half_linear**2 - quadratic * constant, 0.0)
    big = -half_linear - np.copysign(np.sqrt(discriminant), half_linear)  # no cancellation
    with np.errstate(divide="ignore", invalid="ignore"):
        near = np.where(big != 0.0, constant / big, 0.0)
        far = np.where(quadratic != 0.0, big / quadratic, np.nan)
    swap = np.abs(far) < np.abs(near)
    near, far = np.where(swap, far, near), np.where(swap, near, far)
    return (start_1 + near * along_1, start_5 + near * along_5), (start_1 + far * along_1, start_5 + far * along_5)


def _distance_range(k: np.ndarray, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest of ``||R(k, θ) p − q||`` over θ (k a unit axis through the origin)."""
    along = (p - q) @ k
    radius_p, radius_q = radius_about(k, p), radius_about(k, q)
    return np.hypot(radius_p - radius_q, along), np.hypot(radius_p + radius_q, along)


def _second_arc_slots(q1: np.ndarray, q5: np.ndarray, q6: np.ndarray, valid: np.ndarray, free: np.ndarray,
                      other_arc: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each candidate (q1, q5) of shape (N, m) whose free q6 has a second arc (``other_arc`` finite) gets a slot of
    its own row for that arc's value: the first slot after it (then from the start) that is empty or repeats
    its (q1, q5) (at the wrist singularity the two wrist roots meet, so the other root's slot is one of those).
    Returns q1, q5, q6, valid and free with those slots filled, and the rows (N,) where a second arc found no
    slot."""
    q1, q5, q6, valid, free = (np.array(x) for x in (q1, q5, q6, valid, free))
    n, m = q1.shape
    source = valid & free & np.isfinite(other_arc)
    taken = np.zeros((n, m), dtype=bool)
    unrepresented = np.zeros(n, dtype=bool)
    for slot in range(m):
        pending = source[:, slot] & ~taken[:, slot]
        if not pending.any():
            continue
        taken[:, slot] |= pending
        for spare in [*range(slot + 1, m), *range(slot)]:
            repeats = (valid[:, spare] & free[:, spare]
                       & (np.abs(wrap_angle(q1[:, spare] - q1[:, slot])) <= DUPLICATE_TOLERANCE)
                       & (np.abs(wrap_angle(q5[:, spare] - q5[:, slot])) <= DUPLICATE_TOLERANCE))
            fill = pending & ~taken[:, spare] & (~valid[:, spare] | repeats)
            q1[fill, spare], q5[fill, spare], q6[fill, spare] = q1[fill, slot], q5[fill, slot], other_arc[fill, slot]
            valid[fill, spare] = free[fill, spare] = taken[fill, spare] = True
            pending &= ~fill
        unrepresented |= pending
    return q1, q5, q6, valid, free, unrepresented


#: Two elbow roots closer than this (rad) are one double root split by rounding upstream (a root of
#: subproblem 6 is good to ~1e-12 in an arm's chain, and a double root to about its square root). Both stay
#: (each is FK-verified); the target is reported at the stretched or folded boundary.
SPLIT_DOUBLE_ROOT = 1e-4


def _split_double_root(elbow: np.ndarray, valid: np.ndarray, band: float | np.ndarray = SPLIT_DOUBLE_ROOT
                       ) -> np.ndarray:
    """Where the two elbow roots (..., 2) are both valid and a split double root apart: within ``band`` (rad; a
    float, or one per candidate (...)) of each other."""
    gap = np.abs(wrap_angle(elbow[..., 0] - elbow[..., 1]))
    return valid[..., 0] & valid[..., 1] & (np.nan_to_num(gap, nan=np.inf) <= band)


class _ThreeParallelOnePose:
    """:class:`ThreeParallelPlan` (the UR5 type), step for step, with the plan's constants as floats (built once
    per plan)."""

    names = ("shoulder", "elbow", "wrist")
    values = (("left", "right"), ("up", "down"), ("no_flip", "flip"))

    def __init__(self, plan: ThreeParallelPlan) -> None:
        model = plan.model
        d = self.directions = [scalar.vector_of(direction) for direction in model.directions]
        p = self.points = [scalar.vector_of(point) for point in model.points]
        self.home_inverse = scalar.matrix_of(plan.home_inverse[:3, :3]), scalar.vector_of(plan.home_inverse[:3, 3])
        self.centre = scalar.vector_of(plan.centre)
        w_p = self.omega_p = scalar.vector_of(plan.omega_p)
        self.normal_p = scalar.vector_of(plan.normal_p)
        self.signs = [float(s) for s in plan.signs]
        # the subproblems with their fixed vectors: 4 for the shoulder (the centre's height along ω_p), 2 for the
        # wrist (axis 6 turned about axis 5, then about ω_p), 1 for q6, for the sum q2 + q3 + q4 and for q2, 3 for
        # the elbow
        self.shoulder, self.height = scalar.Height(w_p, d[0]), scalar.dot(w_p, scalar.sub(self.centre, p[0]))
        self.wrist = scalar.TwoTurns(w_p, d[4])
        self.wrist_start = self.wrist.start(d[5])
        self.sixth, self.second = scalar.Turn(d[5]), scalar.Turn(d[1])
        self.sixth_free_below = read_off_below(plan.geometry)  # as the array solver's q6
        self.parallel = scalar.Turn(w_p)
        self.normal_p_coordinates = self.parallel.coordinates(self.normal_p)
        self.elbow_turn = scalar.Turn(d[2])
        self.p4_from_3 = scalar.sub(p[3], p[2])
        self.elbow_coordinates = (self.elbow_turn.coordinates(self.p4_from_3),
                                  self.elbow_turn.coordinates(scalar.sub(p[1], p[2])))
        self.p4_from_5 = scalar.sub(p[3], p[4])
        # the widest band the array solver's split double root of the elbow has where this path answers (axis 6
        # at least NEAR_SINGULAR from the parallel axes): the elbow's greatest distance, and the point on axis 4's
        # radius about axis 6 bounded by the arm's constants; roots within it (times the margin) are declined
        lever = scalar.norm(self.p4_from_5) + scalar.norm(scalar.sub(p[4], p[5]))
        self.split_within = scalar.MARGIN * max(SPLIT_DOUBLE_ROOT,
                                                plan.split_band(plan.elbow_range[1], NEAR_SINGULAR, lever))
        # the labels' constants, and the elbow (point on axis 3 from axis 2) in the plane normal to ω_p
        self.forward = scalar.vector_of(plan.forward)
        self.up = scalar.vector_of(plan.geometry.upward(plan.geometry.direction(0)))
        self.elbow = scalar.reject(scalar.sub(p[2], p[1]), w_p)
        self.elbow_length = scalar.norm(self.elbow)
        self.dof = plan.geometry.dof

    def solve(self, T: np.ndarray) -> scalar.OnePose:
        """The eight slots for a target (4, 4), or NotGeneric."""
        top = T[:3].tolist()
        R_T, t_T = (top[0][:3], top[1][:3], top[2][:3]), (top[0][3], top[1][3], top[2][3])
        H, h = self.home_inverse
        R_A = scalar.mm(R_T, H)
        t_A = scalar.add(scalar.mv(R_T, h), t_T)
        d, p, w_p = self.directions, self.points, self.omega_p
        c_world = scalar.add(scalar.mv(R_A, self.centre), t_A)  # as the array solver: A · centre
        s2, s3, s4 = self.signs
        wrap, Turn = wrap_any_float, scalar.Turn
        rows: list[list[float] | None] = []
        codes: list[tuple[int | None, ...]] = []
        for theta1 in self.shoulder.angles(self.shoulder.of(scalar.sub(c_world, p[0])), self.height):
            if math.isnan(theta1):  # the shoulder's second root where it has only a least-squares one
                rows += [None] * 4
                codes += [(None, None, None)] * 4
                continue
            q1 = -theta1
            R1 = scalar.rotation(d[0], q1)
            R_rest = scalar.mtm(R1, R_A)
            wanted_p = self.sixth.coordinates(scalar.mtv(R_rest, w_p))
            for pair in self.wrist.angles(self.wrist_start, self.wrist.goal(scalar.mv(R_rest, d[5]))):
                if pair is None:  # the second wrist root where the cones miss (a least-squares one)
                    rows += [None] * 2
                    codes += [(None, None, None)] * 2
                    continue
                q5 = pair[1]
                sixth_from = self.sixth.coordinates(scalar.rotate(d[4], -q5, w_p))
                if sixth_from[3] <= NEAR_SINGULAR:  # the array solver checks that the solutions there are isolated
                    raise scalar.NotGeneric
                q6 = -Turn.angle(sixth_from, wanted_p, self.sixth_free_below)
                R5, R6 = scalar.rotation(d[4], q5), scalar.rotation(d[5], q6)
                # R234 = R_rest R6ᵀ R5ᵀ, applied to the normal of ω_p
                R234_normal = scalar.mv(R_rest, scalar.mtv(R6, scalar.mtv(R5, self.normal_p)))
                angle_sum = Turn.angle(self.normal_p_coordinates, self.parallel.coordinates(R234_normal))
                # the point on axis 4: G_5⁻¹ then G_6⁻¹ (turns about axes through p5, p6), then A, then G_1⁻¹
                y = scalar.add(p[4], scalar.mtv(R5, self.p4_from_5))
                y = scalar.add(p[5], scalar.mtv(R6, scalar.sub(y, p[5])))
                p4_world = scalar.add(scalar.mv(R_A, y), t_A)
                to_point = scalar.mtv(R1, scalar.sub(p4_world, p[0]))
                z1 = scalar.sub(scalar.add(p[0], to_point), p[1])
                # labels: joint 1 turns the arm about axis 1 (the up direction), so they are taken before it does
                shoulder = scalar.side_code(scalar.dot(to_point, self.forward), scalar.norm(to_point))
                reach = scalar.reject(z1, w_p)
                length = scalar.norm(reach)
                line = (reach[0] / length, reach[1] / length, reach[2] / length) if length > 1e-300 else None
                wrist_code = scalar.wrist_code(q5)
                q5, q6 = wrap(q5), wrap(q6)
                # this shoulder and wrist may leave the point out of the elbow's reach: a least-squares root
                # (then rejected by the FK check) and an empty slot, as in the array solver
                z1_coordinates = self.second.coordinates(z1)
                elbow_roots = Turn.angles_at_distance(*self.elbow_coordinates, scalar.norm(z1), out_of_reach=True)
                if abs(wrap(elbow_roots[0] - elbow_roots[1])) <= self.split_within:  # (False for a NaN)
                    raise scalar.NotGeneric  # maybe one split double root: the array solver flags it
                for q3 in elbow_roots:
                    if math.isnan(q3):
                        rows.append(None)
                        codes.append((None, None, None))
                        continue
                    moved = scalar.add(p[2], scalar.rotate(d[2], q3, self.p4_from_3))
                    q2 = Turn.angle(self.second.coordinates(scalar.sub(moved, p[1])), z1_coordinates)
                    q4 = s4 * (angle_sum - s2 * q2 - s3 * q3)
                    rows.append([wrap(q1), q2, q3, wrap(q4), q5, q6])
                    side = None if line is None else scalar.side_code(
                        scalar.dot(scalar.reject(scalar.rotate(d[1], q2, self.elbow), line), self.up), self.elbow_length)
                    codes.append((shoulder, side, wrist_code))
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof, slots_as_array=True)
