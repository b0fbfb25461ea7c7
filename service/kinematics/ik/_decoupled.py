"""Kinematic decoupling: a positioning arm places a point, wrist joints about it set the orientation.

Spong §4.2 done generally. The point P is where the wrist axes meet (a
spherical wrist), a point on the last axis (a roll), or the tool origin (no
wrist). The wrist joints leave P where it is, so
``P_world = world_T_target · home⁻¹ · P`` is known from the target alone; the
positioner solves for it; then ``H = (G_1 ⋯ G_k)⁻¹ · world_T_target · home⁻¹``
is the motion left to the wrist, whose rotation it solves.
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from .._angles import wrap_any_float, wrap_float
from .._tolerances import ACCEPT_RESIDUAL, GEOMETRY_TOLERANCE, POLISH_RESIDUAL
from . import _scalar as scalar
from ._positioning import (IntersectingShoulder, OffsetShoulderParallelElbow, OneRevolute, OneRevoluteTwoPrismatic,
                           ParallelShoulder, PlanarTwoLink, Positioner)
from .._forward import JointTrig
from ._screws import apply, chain_rotation, invert, move_point, perpendicular_unit, rotate_about, rotation_about
from ._structure import target_error
from .subproblems import subproblem_1
from ._types import LEAN_CHUNK, NEAR_SINGULAR, Candidates, LabelCodes, SingularFlags, Sealed
from ._wrist import Roll, SphericalWrist, seen_by


#: Rows from which :meth:`DecoupledPlan.label_codes` labels one row per run: below, finding the runs costs more
#: than it saves (on the PUMA, the KUKA KR6 and the Stanford arm the two break even at about 1,000 rows; at 4,096
#: the runs save 10–12 %).
_RUNS_FROM = 1024


class DecoupledPlan(Sealed):
    """A positioner over joints 0…k−1 and an optional wrist over joints k…n−1."""

    method = "analytic"
    targets_per_chunk = LEAN_CHUNK

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

    @property
    def free_joint_steers_wrist(self) -> bool:
        """Whether a joint the position leaves free for every target (held at one value) also decides which
        orientations the wrist reaches: a spherical wrist that does not turn every way (its consecutive axes not
        perpendicular), where another value of that joint may bring an orientation within its reach."""
        return (self.positioner is not None and bool(self.positioner.free_joints)
                and isinstance(self.wrist, SphericalWrist) and not self.wrist.turns_every_way)

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
            arm_joints, arm_valid, singular, arm_near = arm.joints, arm.valid, arm.singularities, arm.near_singular
        else:
            arm_joints = np.zeros((n_targets, 1, 0))
            arm_valid = np.ones((n_targets, 1), dtype=bool)
            singular, arm_near = SingularFlags(n_targets), None
        m_arm = arm_joints.shape[1]
        joints = np.zeros((n_targets, m_arm, self.dof))
        joints[..., :k] = arm_joints
        for index, value in self.fixed.items():
            joints[..., index] = value
        if self.home_inverse is None:  # (a position target: the positioner's marks are the answer's)
            return Candidates(joints, arm_valid, singular, near_singular=arm_near)
        model = self.positioner.model if self.positioner else None
        # the joints' rotation R_1 ⋯ R_n = world_T_target · home⁻¹ (rotation part), shape (N, 3, 3)
        R_target = world_T_targets[:, :3, :3] @ self.home_inverse[:3, :3]
        complete = None
        if self.positioner is not None:
            held = self._turn_free_joints(joints, arm_valid, singular, R_target) & arm_valid.any(axis=1)
            arm_joints = joints[..., :k]
            # where the point was reached, other values of a joint held where the positioner put it may reach
            # the orientation the held one misses: those targets are not promised (the verifier's promise rule
            # would read "no valid slot" as the position out of reach)
            complete = ~held if held.any() else None
        if self.wrist is None:
            return Candidates(joints, arm_valid, singular, complete=complete, near_singular=arm_near)
        # the wrist's rotation R_H = R_Gᵀ · R_target (G the positioning joints' motion), applied to the vectors
        # the wrist reads: R_target's images, as rows, times R_G
        seen = seen_by(self.wrist, R_target)[:, None]  # (N, 1, j, 3)
        if self.positioner is not None:
            seen = seen @ chain_rotation(model.directions[:k], model.is_revolute[:k], np.nan_to_num(arm_joints))
        wrist = self.wrist.solve(seen.reshape((-1,) + seen.shape[-2:]), reference)
        m_wrist = wrist.joints.shape[1]
        wrist_joints = wrist.joints.reshape(n_targets, m_arm, m_wrist, -1)
        wrist_valid = wrist.valid.reshape(n_targets, m_arm, m_wrist)
        full = np.repeat(joints[:, :, None, :], m_wrist, axis=2)
        full[..., list(self.wrist.joints)] = wrist_joints
        valid = arm_valid[:, :, None] & wrist_valid
        for mask, flag in wrist.singularities.entries:
            singular.add((mask.reshape(n_targets, m_arm) & arm_valid).any(axis=1), flag)
        near = None  # the slots near a singular set of the wrist, or of the positioner, for the isolation check
        if wrist.near_singular is not None:
            near = wrist.near_singular.reshape(n_targets, m_arm, m_wrist)
        if arm_near is not None:
            arm_near = np.repeat(arm_near[..., None], m_wrist, axis=2)
            near = arm_near if near is None else near | arm_near
        if near is not None:
            near = near.reshape(n_targets, -1)
        return Candidates(full.reshape(n_targets, m_arm * m_wrist, self.dof), valid.reshape(n_targets, -1),
                          singular, complete=complete, near_singular=near)

    def _turn_free_joints(self, joints: np.ndarray, valid: np.ndarray, singular: SingularFlags,
                          R_target: np.ndarray) -> np.ndarray:
        """Set, in place, positioning joints the position leaves free from the target's orientation.

        ``joints`` (N, m, n) with the positioner's values, ``valid`` (N, m), ``singular`` the positioner's flags
        (N rows), ``R_target`` (N, 3, 3) the joints' rotation R_1 ⋯ R_n the target asks for. Where a flag says
        revolute joints are free (the point is on their axes: turning them keeps it), the others fixed:

        * one joint j: ``A R(ω_j, θ) B = R_target``, A and B the rotations of the joints before and after it.
          With no wrist, subproblem 1 turns a vector u normal to ω_j onto ``M u``, ``M = Aᵀ R_target Bᵀ``; with
          a roll (whose turn keeps its axis ω_r), B ω_r onto ``Aᵀ R_target ω_r``, the roll then following;
        * two joints i < j, no wrist (the point at their axes' crossing): ``M = R(ω_i, θ_i) C R(ω_j, θ_j)``
          with C the rotations between them; ``R(ω_j, θ_j)`` keeps ω_j, so subproblem 1 turns C ω_j onto
          M ω_j for θ_i, and then θ_j as for one joint with ``Cᵀ R(ω_i, θ_i)ᵀ M``.

        Where a subproblem is degenerate (the vector on the axis: only a sum is fixed) the positioner's values
        stay; with a spherical wrist that turns every way the wrist absorbs them, so they stay free. With two free
        joints and a roll, more than two and no wrist, a two-axis wrist, or a spherical wrist that does not turn
        every way (:attr:`free_joint_steers_wrist`: a joint free for every target is held for every target too),
        nothing here can set them and they stay as the positioner set them: the targets (N,) where that happened
        are returned (the caller does not promise them).
        """
        if self.free_joint_steers_wrist:
            return np.ones(len(joints), dtype=bool)
        held_rows = np.zeros(len(joints), dtype=bool)
        if isinstance(self.wrist, SphericalWrist) and self.wrist.turns_every_way:
            return held_rows
        model, k = self.positioner.model, len(self.positioner.joints)
        settable = 0 if self.wrist is not None and not isinstance(self.wrist, Roll) else (
            1 if self.wrist is not None else 2)  # how many free joints the orientation sets here
        for mask, flag in list(singular.entries):
            free = flag.joints
            if flag.relation != "free" or max(free) >= k or not model.is_revolute[list(free)].all():
                continue
            if len(free) > settable:
                held_rows |= mask
                continue
            rows = np.flatnonzero(mask)
            q = np.nan_to_num(joints[rows])  # (r, m, n)

            def turns(start: int, stop: int) -> np.ndarray:
                """The rotation of joints start … stop − 1 at q, (r, m, 3, 3)."""
                return chain_rotation(model.directions[start:stop], model.is_revolute[start:stop],
                                      q[..., start:stop])

            i, j = free[0], free[-1]
            B = turns(j + 1, k)
            wanted = np.swapaxes(turns(0, i), -1, -2) @ R_target[rows, None]  # Aᵀ R_target, (r, m, 3, 3)
            held = ~valid[rows]
            axis = model.directions[j]
            if self.wrist is not None:
                roll = model.directions[self.wrist.joints[0]]
                last = subproblem_1(axis, B @ roll, wanted @ roll)
            else:
                M = wanted @ np.swapaxes(B, -1, -2)
                if i != j:
                    C = turns(i + 1, j)
                    first = subproblem_1(model.directions[i], C @ axis, M @ axis)
                    held |= first.degenerate
                    q[..., i] = first.theta[..., 0]
                    M = np.swapaxes(rotation_about(model.directions[i], q[..., i]) @ C, -1, -2) @ M
                u = perpendicular_unit(axis)
                last = subproblem_1(axis, np.broadcast_to(u, q.shape[:-1] + (3,)), M @ u)
            held |= last.degenerate
            q[..., j] = last.theta[..., 0]
            joints[rows, :, i] = np.where(held, joints[rows, :, i], q[..., i])
            joints[rows, :, j] = np.where(held, joints[rows, :, j], q[..., j])
        return held_rows

    def wrist_volume(self, joints: np.ndarray) -> np.ndarray | None:
        """The spherical wrist's volume (:meth:`SphericalWrist.volume`) at joint vectors (..., n), shape (...,): 0
        where its outer axes align; None for a plan without a spherical wrist."""
        if not isinstance(self.wrist, SphericalWrist):
            return None
        return self.wrist.volume(joints[..., self.wrist.joints[1]])

    def positioning_jacobian(self, joints: np.ndarray, size: float) -> np.ndarray | None:
        """How the positioning joints steer the wrist centre at joint vectors (..., n): the centre's Jacobian over
        their rates, shape (..., 3, 3), a revolute column ω_i × (c − p_i) in arm sizes ``size``, a prismatic one
        its direction. It is written with joint 1's turn undone (its singular values, what it is for, are those of
        any frame): there axes 1 and 2 are at home, joint 2 turns axis 3, and joints 2 and 3 move the centre.
        None for a plan without a three-joint positioner and a spherical wrist."""
        positioner = self.positioner
        if not isinstance(self.wrist, SphericalWrist) or positioner is None or len(positioner.joints) != 3:
            return None
        model = positioner.model
        directions, points, revolute = model.directions, model.points, model.is_revolute
        q = joints[..., :3]
        centre_by_3 = move_point(directions[2:], points[2:], revolute[2:], q[..., 2:], self.point)
        centre = move_point(directions[1:2], points[1:2], revolute[1:2], q[..., 1:2], centre_by_3)

        def column(i: int, at: np.ndarray) -> np.ndarray:
            if revolute[i]:
                return np.cross(directions[i], at - points[i]) / size
            return np.broadcast_to(directions[i], at.shape)

        third = column(2, centre_by_3)  # with joint 2's turn undone too: that turn brings it beside the others
        if revolute[1]:
            third = rotate_about(directions[1], q[..., 1], third)
        return np.stack([column(0, centre), column(1, centre), third], axis=-1)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """Branch labels of full joint vectors (M, n) as arrays: the positioner's, then the wrist's.

        The positioner's labels read its own joints alone, and the wrist's slots of one arm branch share them (the
        rows come in runs, as :meth:`solve` lays them out): from :data:`_RUNS_FROM` rows, each run is labelled
        once, from its first row."""
        codes: LabelCodes = {}
        if self.positioner is not None:
            first = np.ones(len(joints), dtype=bool)  # each row that starts a run
            if len(joints) >= _RUNS_FROM:
                arm = joints[:, list(self.positioner.joints)]
                first[1:] = (arm[1:] != arm[:-1]).any(axis=1)  # a NaN differs from itself: its row is labelled alone
            if first.all():
                codes.update(self.positioner.label_codes(joints, trig))
            else:
                rows = np.flatnonzero(first)
                run_of = np.cumsum(first) - 1
                for name, (values, run_codes) in self.positioner.label_codes(
                        joints[rows], None if trig is None else trig.take(rows)).items():
                    codes[name] = (values, run_codes[run_of])
        if self.wrist is not None:
            codes.update(self.wrist.label_codes(joints, trig))
        return codes

    def solve_one(self, world_T_target: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose | None:
        """:meth:`solve` of one target (4, 4) in scalar arithmetic (:mod:`._scalar`), with the slots' branch
        labels (:meth:`label_codes`) from the same quantities, or None when the plan has no scalar path or the
        pose is not clearly generic (then :meth:`solve` and :meth:`label_codes` decide). ``reference`` (n,) as
        :meth:`solve` takes it: only the Stanford type's path reads it (its bands take the reference's values
        where the pose is generic too); the others decline wherever :meth:`solve` would read it."""
        one_pose = self._one_pose
        if one_pose is None:
            return None
        try:
            return one_pose.solve(world_T_target, reference)
        except scalar.NotGeneric:
            return None

    @cached_property
    def _one_pose(self) -> "_ArmOnePose | None":
        """The scalar solver, or None. The positioner (joints 1…k, structurally free joints none) is one of:
        an intersecting shoulder with a revolute joint 3 (the PUMA type), a slide through axis 2 (the Stanford
        type, the polar arms) or a slide that misses it (a polar arm with an offset); an offset shoulder with
        joints 2 ∥ 3, all revolute (the OPW type: KUKA, ABB, Fanuc); two parallel axes with a slide along them
        (the SCARA) or without (a planar arm); one revolute joint; one revolute joint and two slides (the
        cylindrical arms); or none (a wrist alone). What follows it is one :class:`_WristStep`: a spherical
        wrist, a roll, or nothing."""
        positioner = self.positioner
        if positioner is None:
            step = _wrist_step(self, 0)
            return _WristOnlyOnePose(self, step) if isinstance(step, _SphericalWristStep) else None
        k = len(positioner.joints)
        if positioner.free_joints or positioner.joints != tuple(range(k)):
            return None
        step = _wrist_step(self, k)
        if step is None:
            return None
        revolute = positioner.model.is_revolute
        if isinstance(positioner, (ParallelShoulder, PlanarTwoLink)):
            return _ParallelAxesOnePose(self, step)
        if isinstance(positioner, OneRevolute):
            return _OneRevoluteOnePose(self, step)
        if isinstance(positioner, OneRevoluteTwoPrismatic):
            return _CylindricalOnePose(self, step)
        if isinstance(positioner, IntersectingShoulder) and bool(revolute[2]):
            return _ShoulderOnePose(self, step)
        if isinstance(positioner, IntersectingShoulder) and positioner.slide_through_axis_2 is None:
            return _SlideElbowShoulderOnePose(self, step)
        if isinstance(positioner, IntersectingShoulder) and positioner.slide_through_axis_2 is not None:
            return _SlideShoulderOnePose(self, step)
        if (isinstance(positioner, OffsetShoulderParallelElbow) and bool(revolute[:3].all())
                and positioner.forward is not None):
            return _OffsetShoulderOnePose(self, step)
        return None


def _wrist_step(plan: DecoupledPlan, k: int) -> "_WristStep | None":
    """What follows the positioner (joints 1…k) on the scalar path: a spherical wrist (joints k+1…k+3), a roll
    (joint k+1), or nothing (a pose of an arm of k joints; a position target, any joints past the k-th held);
    None for anything else."""
    wrist, held = plan.wrist, sorted(plan.fixed)
    if isinstance(wrist, SphericalWrist) and wrist.joints == (k, k + 1, k + 2) and plan.dof == k + 3 and not held:
        return _SphericalWristStep(plan)
    if isinstance(wrist, Roll) and wrist.joints == (k,) and plan.dof == k + 1 and not held:
        return _RollStep(plan)
    if wrist is None and held == list(range(k, plan.dof)):
        return _WristStep(plan)
    return None


class _WristStep:
    """What follows the positioner on a scalar path (:class:`_ArmOnePose`), one arm branch at a time: here
    nothing, the joints past the positioner's (if any: a position target's) held at the plan's values, one slot
    per branch; its subclasses solve a roll and a spherical wrist. :meth:`target` reads what the step needs of a
    target once, :meth:`rows` appends a branch's slots; ``turned`` says whether :meth:`rows` reads the
    positioner's rotation R_G."""

    names: tuple[str, ...] = ()
    values: tuple[tuple[str, ...], ...] = ()
    slots, turned = 1, False

    def __init__(self, plan: DecoupledPlan) -> None:
        home_inverse = plan.home_inverse  # None: a position target, whose position is the point's
        # the point the positioner places, at home: home⁻¹ applied once here
        self.point_home = None if home_inverse is None else scalar.vector_of(
            home_inverse[:3, :3] @ plan.point + home_inverse[:3, 3])
        revolute = plan.positioner.model.is_revolute if plan.fixed else ()
        self.held = [wrap_float(value) if revolute[index] else float(value)
                     for index, value in sorted(plan.fixed.items())]

    def target(self, T: np.ndarray) -> tuple[scalar.Vector, tuple]:
        """The point the positioner places (T · home⁻¹ · point; a position target's own), and what :meth:`rows`
        reads of the target (4, 4)."""
        top = T[:3].tolist()
        moved = (top[0][3], top[1][3], top[2][3])
        if self.point_home is None:
            return moved, ()
        R_T = (top[0][:3], top[1][:3], top[2][:3])
        return scalar.add(scalar.mv(R_T, self.point_home), moved), self._seen(R_T)

    def _seen(self, R_T: scalar.Matrix) -> tuple:
        return ()

    def rows(self, R_G: scalar.Matrix | None, seen: tuple, arm: list[float], arm_codes: tuple[int | None, ...],
             rows: list, codes: list) -> None:
        """One arm branch's slots (joints ``arm``, turning what follows by R_G)."""
        rows.append(arm + self.held if self.held else arm)
        codes.append(arm_codes)


class _RollStep(_WristStep):
    """Joint 4 a roll: subproblem 1 about its axis on a normal of it, as R_Gᵀ · R_target turns that normal
    (:class:`Roll`)."""

    slots, turned = 1, True

    def __init__(self, plan: DecoupledPlan) -> None:
        super().__init__(plan)
        roll = plan.wrist
        self.turn = scalar.Turn(scalar.vector_of(roll.axis))
        self.normal = self.turn.coordinates(scalar.vector_of(roll.normal))
        self.normal_home = scalar.vector_of(plan.home_inverse[:3, :3] @ roll.normal)

    def _seen(self, R_T: scalar.Matrix) -> tuple:
        return (scalar.mv(R_T, self.normal_home),)

    def rows(self, R_G: scalar.Matrix | None, seen: tuple, arm: list[float], arm_codes: tuple[int | None, ...],
             rows: list, codes: list) -> None:
        rows.append([*arm, self.turn.angle(self.normal, self.turn.coordinates(scalar.mtv(R_G, seen[0])))])
        codes.append(arm_codes)


class _SphericalWristStep(_WristStep):
    """Joints 4–6 a spherical wrist: its two slots per arm branch, and its label."""

    names = ("wrist",)
    values = (("no_flip", "flip"),)
    slots, turned = 2, True

    def __init__(self, plan: DecoupledPlan) -> None:
        super().__init__(plan)
        wrist = plan.wrist
        home_inverse = plan.home_inverse
        a, b, axis_c = (scalar.vector_of(axis) for axis in wrist.axes)
        # the wrist's last axis and its normal at home
        self.axis_c_home = scalar.vector_of(home_inverse[:3, :3] @ wrist.axes[2])
        self.normal_home = scalar.vector_of(home_inverse[:3, :3] @ wrist.normal)
        # subproblem 2 about the wrist's first two axes, 1 about its last (the normal)
        self.wrist, self.wrist_axes = scalar.TwoTurns(a, b, wrist.free_below), (a, b)
        self.wrist_volume = wrist.volume_terms
        self.wrist_start = self.wrist.start(axis_c)
        self.last_turn = scalar.Turn(axis_c)
        self.last_normal = self.last_turn.coordinates(scalar.vector_of(wrist.normal))

    def _seen(self, R_T: scalar.Matrix) -> tuple:
        """The wrist's last axis and normal as the target turns them."""
        return scalar.mv(R_T, self.axis_c_home), scalar.mv(R_T, self.normal_home)

    def rows(self, R_G: scalar.Matrix | None, seen: tuple, arm: list[float], arm_codes: tuple[int | None, ...],
             rows: list, codes: list) -> None:
        """The wrist's two slots for one arm branch: what is left to the wrist, R_Gᵀ · R_target, applied to its
        last axis and normal."""
        axis_c, normal = seen
        wanted = scalar.mtv(R_G, normal)
        a, b = self.wrist_axes
        u, w = self.wrist_volume
        pairs = self.wrist.angles(self.wrist_start, self.wrist.goal(scalar.mtv(R_G, axis_c)))
        # the wrist's axes near aligned (not at the least-squares pair of cones that miss, which is coplanar):
        # the array path holds q_a within its band (SphericalWrist), and checks that the solutions there are
        # isolated (NEAR_SINGULAR: far wider than that band). The two roots' volumes are equal up to sign (the
        # last axis's two images mirror each other across the plane of the first two), so one is read.
        if pairs[1] is not None:
            qb = pairs[0][1]
            if abs(u * math.cos(qb) + w * math.sin(qb)) <= NEAR_SINGULAR:
                raise scalar.NotGeneric
        for roots in pairs:
            if roots is None:
                rows.append(None)
                codes.append((None,) * (len(arm_codes) + 1))
                continue
            qa, qb = roots
            unwound = scalar.rotate(b, -qb, scalar.rotate(a, -qa, wanted))
            qc = scalar.Turn.angle(self.last_normal, self.last_turn.coordinates(unwound))
            rows.append([*arm, qa, qb, qc])
            codes.append((*arm_codes, scalar.wrist_code(qb)))


class _ArmOnePose:
    """What the scalar one-pose paths of :class:`DecoupledPlan` share: the step after the positioner
    (:class:`_WristStep`), the labels' names (the positioner's ``arm_names``, then the step's), and the
    positioner's isolation band, with the plan's constants as floats (built once per plan)."""

    arm_names: tuple[str, ...] = ()
    arm_values: tuple[tuple, ...] = ()

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        self.step, self.dof = step, plan.dof
        self.names, self.values = self.arm_names + step.names, self.arm_values + step.values
        # the positioner's isolation band (its near_singular): a point this near an axis it reads an angle about
        self.near_axis = 0.0 if plan.positioner is None else NEAR_SINGULAR * plan.positioner.geometry.length_scale

    def _empty(self, rows: list, codes: list, branches: int) -> None:
        """The slots of ``branches`` arm branches that do not exist (and of what follows them)."""
        count = branches * self.step.slots
        rows += [None] * count
        codes += [(None,) * len(self.names)] * count


class _IntersectingShoulderOnePose(_ArmOnePose):
    """What the scalar paths of an :class:`IntersectingShoulder` whose joint 3 does not slide through axis 2
    share: joint 3's two values at the target's distance from the centre (:meth:`_thirds`, the subclass's), then
    subproblem 2 about axes 1 and 2 for each, in the positioner's slot order, and the shoulder's label (with the
    subclass's elbow label, :meth:`_elbow_codes`)."""

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        positioner = plan.positioner
        d = self.directions = [scalar.vector_of(direction) for direction in positioner.model.directions]
        self.centre, self.geometry = scalar.vector_of(positioner.centre), positioner.geometry
        self.shoulder = scalar.TwoTurns(d[0], d[1])  # subproblem 2 about axes 1 and 2 (where the arm turns it)
        # the shoulder label's constants
        forward, self.in_plane, up = positioner.label_constants
        self.forward, self.up = scalar.vector_of(forward), scalar.vector_of(up)
        self.on_axis = GEOMETRY_TOLERANCE * 10 * positioner.geometry.length_scale

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The slots for a target (4, 4) (eight with a spherical wrist), or NotGeneric (``reference``: not read,
        see :meth:`DecoupledPlan.solve_one`)."""
        point_world, seen = self.step.target(T)
        d, c, shoulder, step = self.directions, self.centre, self.shoulder, self.step
        target = scalar.sub(point_world, c)
        goal = shoulder.goal(target)
        error = target_error(self.geometry, scalar.norm(point_world), rounding=0.0)  # as the array path's
        rows, codes = [], []
        for q3, R_3, reach_local in self._thirds(scalar.norm(target)):
            elbow_side = self._elbow_side(reach_local)
            start = shoulder.start(reach_local)
            if goal[3] <= self.near_axis or start[3] <= self.near_axis:  # IntersectingShoulder's near_singular:
                raise scalar.NotGeneric  # the array path checks that the solutions there are isolated
            for pair in shoulder.angles(start, goal, error):
                if pair is None:  # no arm branch here: its wrist slots are empty too
                    self._empty(rows, codes, 1)
                    continue
                q1, q2 = pair
                R_1, R_2 = scalar.rotation(d[0], q1), scalar.rotation(d[1], q2)
                R_G = scalar.mm(R_1, R_2) if step.turned else None  # (a slide turns nothing)
                if R_G is not None and R_3 is not None:
                    R_G = scalar.mm(R_G, R_3)
                step.rows(R_G, seen, [q1, q2, q3], self._arm_codes(R_2, reach_local, elbow_side), rows, codes)
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)

    def _arm_codes(self, R_2: scalar.Matrix, reach_local: scalar.Vector,
                   elbow_side: scalar.Vector | None) -> tuple[int | None, ...]:
        """:meth:`IntersectingShoulder.label_codes` of one arm branch. Joint 1 turns about axis 1, which is the up
        direction and carries the forward one with it, so only joint 2's turn R_2 matters."""
        reach = scalar.mv(R_2, reach_local)
        length = math.sqrt(reach[0] * reach[0] + reach[1] * reach[1] + reach[2] * reach[2])
        if scalar.norm(scalar.reject(reach, self.directions[0])) <= scalar.MARGIN * self.on_axis:
            return (None,) * len(self.arm_names)  # the point near axis 1: the array labeller decides
        return (scalar.side_code(scalar.dot(reach, self.forward), length), *self._elbow_codes(R_2, elbow_side))


class _ShoulderOnePose(_IntersectingShoulderOnePose):
    """:class:`DecoupledPlan` with an :class:`IntersectingShoulder` whose joint 3 is revolute: subproblem 3 about
    axis 3, then the shoulder, and the shoulder's and the elbow's labels."""

    arm_names = ("shoulder", "elbow")
    arm_values = (("left", "right"), ("up", "down"))

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        model, d, c = plan.positioner.model, self.directions, self.centre
        p2, w = scalar.vector_of(model.points[2]), scalar.vector_of(plan.point)
        # subproblem 3 about axis 3: the wrist point's distance from the centre
        self.elbow_turn = scalar.Turn(d[2])
        self.point_from_3 = scalar.sub(w, p2)
        self.elbow_coordinates = (self.elbow_turn.coordinates(self.point_from_3),
                                  self.elbow_turn.coordinates(scalar.sub(c, p2)))
        self.centre_to_3 = scalar.sub(p2, c)
        # the elbow (point on axis 3) from the centre before joints 1 and 2 turn it, in the arm's plane if the
        # labels work there (axes 2 ∥ 3), and its length
        elbow = scalar.sub(p2, c)
        self.elbow = scalar.reject(elbow, d[1]) if self.in_plane else elbow
        self.elbow_length = scalar.norm(self.elbow)

    def _thirds(self, distance: float) -> list[tuple[float, scalar.Matrix | None, scalar.Vector]]:
        """Joint 3's two values that put the point at ``distance`` from the centre (subproblem 3), each with its
        turn R_3 and the point from the centre so placed (joints 1 and 2 turn it about the centre)."""
        d = self.directions
        thirds = []
        for q3 in self.elbow_turn.angles_at_distance(*self.elbow_coordinates, distance):
            R_3 = scalar.rotation(d[2], q3)
            thirds.append((q3, R_3, scalar.add(scalar.mv(R_3, self.point_from_3), self.centre_to_3)))
        return thirds

    def _elbow_side(self, reach_local: scalar.Vector) -> scalar.Vector:
        """The elbow's offset from the centre–point line (in the arm's plane when axes 2 ∥ 3), before joints 1
        and 2 turn the arm: :meth:`IntersectingShoulder.label_codes` measures it along the up direction."""
        if self.in_plane:
            reach_local = scalar.reject(reach_local, self.directions[1])
        length = scalar.norm(reach_local)
        return scalar.reject(self.elbow, (reach_local[0] / length, reach_local[1] / length, reach_local[2] / length))

    def _elbow_codes(self, R_2: scalar.Matrix, elbow_side: scalar.Vector) -> tuple[int | None]:
        """The elbow's label: the side of the centre–point line its offset lies on, along the up direction."""
        return (scalar.side_code(scalar.dot(scalar.mv(R_2, elbow_side), self.up), self.elbow_length),)


class _SlideElbowShoulderOnePose(_IntersectingShoulderOnePose):
    """:class:`DecoupledPlan` with an :class:`IntersectingShoulder` whose third joint slides along a line that
    misses axis 2 (a polar arm with an offset): the slide's two values at the target's distance from the centre
    (:func:`.subproblems.prismatic_to_distance`), then the shoulder, and the shoulder's label (a slide has no
    elbow label)."""

    arm_names = ("shoulder",)
    arm_values = (("left", "right"),)

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        self.point = scalar.vector_of(plan.positioner.point)
        self.slide = scalar.vector_of(plan.positioner.geometry.direction(plan.positioner.joints[2]))

    def _thirds(self, distance: float) -> list[tuple[float, scalar.Matrix | None, scalar.Vector]]:
        p, v, c = self.point, self.slide, self.centre
        return [(s, None, (p[0] + s * v[0] - c[0], p[1] + s * v[1] - c[1], p[2] + s * v[2] - c[2]))
                for s in scalar.slide_to_distance(p, v, c, distance)]

    def _elbow_side(self, reach_local: scalar.Vector) -> None:
        return None

    def _elbow_codes(self, R_2: scalar.Matrix, elbow_side: None) -> tuple[()]:
        return ()


class _SlideShoulderOnePose(_ArmOnePose):
    """:class:`DecoupledPlan` with an :class:`IntersectingShoulder` whose third joint slides normal to axis 2
    along a line crossing it (the Stanford type) and a spherical wrist: the shoulder and the slide in the slide's
    frame as :meth:`.SlideThroughAxis2.solve` works them out, a reference's values taken where they lie in the
    bands (near the fold, a reference in the band of a moves it by up to band² / 2a: far more than rounding), then
    subproblem 1 for joint 1, in its slot order (the two shoulder solutions ±a, each with the slide's two signs),
    and the shoulder's label (a slide has no elbow label)."""

    arm_names = ("shoulder",)
    arm_values = (("left", "right"),)

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        positioner, model = plan.positioner, plan.positioner.model
        self.frame = positioner.slide_through_axis_2
        self.first, self.second = scalar.vector_of(model.directions[0]), scalar.vector_of(model.directions[1])
        self.first_turn = scalar.Turn(self.first)
        self.n1, self.n2 = scalar.vector_of(self.frame.n1), scalar.vector_of(self.frame.n2)
        self.centre, self.geometry = scalar.vector_of(positioner.centre), positioner.geometry
        self.forward = scalar.vector_of(positioner.label_constants[0])
        size = positioner.geometry.length_scale
        self.exact_within, self.at_centre = GEOMETRY_TOLERANCE * size, 0.5 * ACCEPT_RESIDUAL * size

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The slots for a target (4, 4) (eight with a spherical wrist), or NotGeneric; ``reference`` (n,) as
        :meth:`DecoupledPlan.solve`."""
        point_world, seen = self.step.target(T)
        frame, k1, k2, n1, n2 = self.frame, self.first, self.second, self.n1, self.n2
        y = scalar.sub(point_world, self.centre)
        height = scalar.dot(y, k1)
        radius = scalar.norm((y[0] - height * k1[0], y[1] - height * k1[1], y[2] - height * k1[2]))
        rounding = target_error(self.geometry, scalar.norm(point_world))
        along, _, across_squared, band_along, band_squared = frame.reach(height, radius, rounding)
        # clear of the bands: the two shoulder solutions apart (so joint 2 not free), the point off the centre
        if not (across_squared > scalar.MARGIN * band_squared and scalar.norm(y) > scalar.MARGIN * self.at_centre):
            raise scalar.NotGeneric
        across, first_sign = math.sqrt(across_squared), 1.0
        if reference is not None:  # its values where they lie clearly inside the bands, none where clearly outside
            q1_ref, q2_ref, q3_ref = (float(value) for value in reference[:3])
            slide_ref, turn_ref = q3_ref - frame.foot, frame.psi0 + q2_ref
            along_ref, across_ref = slide_ref * math.cos(turn_ref), slide_ref * math.sin(turn_ref)
            if scalar.clearly_within(abs(along - along_ref), band_along):
                along = along_ref
            if scalar.clearly_within(abs(across_ref * across_ref - across_squared), band_squared):
                across, first_sign = abs(across_ref), (-1.0 if across_ref < 0 else 1.0)
        if radius <= self.near_axis:  # the target near axis 1: the array path checks the solutions there
            raise scalar.NotGeneric
        on_first_axis = max(rounding / POLISH_RESIDUAL, self.at_centre)
        goal = self.first_turn.coordinates(y)
        rows, codes = [], []
        for signed in (first_sign * across, -first_sign * across):
            psi = math.atan2(signed, along)
            t = along * math.cos(psi) + signed * math.sin(psi)  # the displacement along R(k2, q2) v
            if abs(t) <= self.near_axis:  # (SlideThroughAxis2.solve's near_singular, as the radius below)
                raise scalar.NotGeneric  # the array path checks that the solutions there are isolated
            for turn, slide in ((psi, t), (psi + math.pi, -t)):
                c, s = math.cos(turn), math.sin(turn)
                turned = (frame.height * k2[0] + slide * (c * n1[0] + s * n2[0]),
                          frame.height * k2[1] + slide * (c * n1[1] + s * n2[1]),
                          frame.height * k2[2] + slide * (c * n1[2] + s * n2[2]))
                start = self.first_turn.coordinates(turned)
                q1 = scalar.Turn.angle(start, goal, on_first_axis / max(start[4], goal[4]))
                if reference is not None and scalar.clearly_within(abs(wrap_any_float(q1 - q1_ref)), rounding / radius):
                    q1 = wrap_any_float(q1_ref)  # an azimuth seen on a radius r is known to rounding / r
                if not scalar.MARGIN * scalar.norm(scalar.sub(scalar.rotate(k1, q1, turned), y)) \
                        <= self.exact_within:
                    raise scalar.NotGeneric
                q2 = wrap_any_float(turn - frame.psi0)
                shoulder_code = scalar.side_code(scalar.dot(turned, self.forward), scalar.norm(turned))
                R_G = scalar.mm(scalar.rotation(k1, q1), scalar.rotation(k2, q2)) if self.step.turned else None
                self.step.rows(R_G, seen, [q1, q2, frame.foot + slide], (shoulder_code,), rows, codes)
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)


class _OffsetShoulderOnePose(_ArmOnePose):
    """:class:`DecoupledPlan` with an :class:`OffsetShoulderParallelElbow` (joints 1–3 revolute, 2 ∥ 3: the OPW
    arms) and a spherical wrist: subproblem 4 for joint 1 (front and back), 3 for joint 3 (elbow up and down), 1
    for joint 2, in the positioner's slot order, and its labels, all in the frame of the arm before joint 1 turns
    it (joint 1 leaves its axis, and the up direction along it, where they are)."""

    arm_names = ("shoulder", "elbow")
    arm_values = (("left", "right"), ("up", "down"))

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        positioner, model = plan.positioner, plan.positioner.model
        d = self.directions = [scalar.vector_of(direction) for direction in model.directions]
        o, p2, p3 = (scalar.vector_of(model.points[j]) for j in range(3))
        u, w = d[1], scalar.vector_of(plan.point)
        self.origin, self.point_2, self.point_3 = o, p2, p3
        # u · R(axis 1, −q1)(x − o) = u · (w − o): subproblem 4 for θ = −q1
        self.front_back, self.height = scalar.Height(u, d[0]), scalar.dot(u, scalar.sub(w, o))
        # in the plane normal to u: subproblem 3 about axis 3 for the distance from axis 2, then 1 about axis 2
        self.elbow_turn, self.second_turn = scalar.Turn(d[2]), scalar.Turn(u)
        self.elbow_coordinates = (self.elbow_turn.coordinates(scalar.reject(scalar.sub(w, p3), u)),
                                  self.elbow_turn.coordinates(scalar.reject(scalar.sub(p2, p3), u)))
        self.point_from_3 = scalar.sub(w, p3)
        # the labels' constants: the forward direction (along the shoulder offset), the shoulder (axis 2's foot of
        # the common normal) and the up direction along axis 1
        self.forward, self.shoulder = scalar.vector_of(positioner.forward), scalar.vector_of(positioner.shoulder)
        self.up = scalar.vector_of(positioner.geometry.upward(model.directions[0]))
        self.elbow_from_2 = scalar.sub(p3, p2)

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The slots for a target (4, 4) (eight with a spherical wrist), or NotGeneric (``reference``: not read,
        see :meth:`DecoupledPlan.solve_one`)."""
        point_world, seen = self.step.target(T)
        d, o, p2, p3, step = self.directions, self.origin, self.point_2, self.point_3, self.step
        from_origin = scalar.sub(point_world, o)
        if scalar.norm(scalar.reject(from_origin, d[0])) <= self.near_axis:  # OffsetShoulderParallelElbow's
            raise scalar.NotGeneric  # near_singular: the array path checks that the solutions there are isolated
        thetas = scalar.Height.angles(self.front_back.of(from_origin), self.height)
        if math.isnan(thetas[1]):  # clearly out of reach: the array path words why
            raise scalar.NotGeneric
        rows, codes = [], []
        for theta in thetas:
            q1 = wrap_float(-theta)
            # the target with joint 1 undone, and what the labels measure there
            y_from_origin = scalar.rotate(d[0], theta, from_origin)
            y_from_2 = scalar.sub(scalar.add(o, y_from_origin), p2)
            reach = scalar.norm(scalar.reject(y_from_2, d[1]))
            shoulder_code = scalar.side_code(scalar.dot(y_from_origin, self.forward), scalar.norm(from_origin))
            target_2 = self.second_turn.coordinates(y_from_2)
            elbows = self.elbow_turn.angles_at_distance(*self.elbow_coordinates, reach, out_of_reach=True)
            if math.isnan(elbows[1]):  # this side clearly out of reach: the least-squares root is no solution
                self._empty(rows, codes, 2)
                continue
            for q3 in elbows:
                point_3 = scalar.add(scalar.sub(p3, p2), scalar.rotate(d[2], q3, self.point_from_3))
                placed = self.second_turn.coordinates(point_3)
                if placed[3] <= self.near_axis:  # the placed point near axis 2 (as above)
                    raise scalar.NotGeneric
                q2 = self.second_turn.angle(placed, target_2)
                R_2 = scalar.rotation(d[1], q2)
                elbow_code = self._elbow_code(R_2, y_from_origin)
                R_G = scalar.mm(scalar.mm(scalar.rotation(d[0], q1), R_2), scalar.rotation(d[2], q3)) \
                    if step.turned else None
                step.rows(R_G, seen, [q1, q2, q3], (shoulder_code, elbow_code), rows, codes)
        if not any(rows):  # out of reach on both sides: the array path words why
            raise scalar.NotGeneric
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)

    def _elbow_code(self, R_2: scalar.Matrix, y_from_origin: scalar.Vector) -> int | None:
        """:meth:`OffsetShoulderParallelElbow.label_codes`' elbow before joint 1 turns the arm: the side of the
        shoulder–point line the elbow (axis 3) lies on, in the arm's plane, along the up direction."""
        u = self.directions[1]
        elbow = scalar.reject(scalar.add(scalar.sub(self.point_2, self.shoulder), scalar.mv(R_2, self.elbow_from_2)),
                              u)
        line = scalar.reject(scalar.sub(scalar.add(self.origin, y_from_origin), self.shoulder), u)
        length = scalar.norm(line)
        if length <= 1e-300:
            return None
        line = (line[0] / length, line[1] / length, line[2] / length)
        rejection = scalar.reject(elbow, line)
        return scalar.side_code(scalar.dot(rejection, self.up), scalar.norm(elbow))


class _ParallelAxesOnePose(_ArmOnePose):
    """:class:`DecoupledPlan` with joints 1 and 2 about parallel axes: a :class:`ParallelShoulder` (the SCARA arm,
    a slide along them) or a :class:`PlanarTwoLink` (the point in their plane): the slide from the height (or the
    height checked), subproblem 3 about axis 2 for the distance from axis 1 (the two branches, in the
    positioner's slot order), 1 about axis 1, and the branch's label (the SCARA's assembly mode, the planar arm's
    elbow), as the positioner's ``solve`` and ``label_codes`` work them out."""

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        positioner = plan.positioner
        g, joints = positioner.geometry, positioner.joints
        i, j = joints[:2]
        if isinstance(positioner, ParallelShoulder):
            self.arm_names, self.arm_values = ("assembly_mode",), ((1, 2),)
        else:
            self.arm_names, self.arm_values = ("elbow",), (("up", "down"),)
        super().__init__(plan, step)
        directions = positioner.model.directions
        self.size = g.length_scale
        self.point = scalar.vector_of(positioner.point)
        u = self.u = scalar.vector_of(g.direction(i))
        self.slide = None if len(joints) == 2 else scalar.vector_of(g.direction(joints[2]))
        self.along = None if self.slide is None else scalar.dot(u, self.slide)
        self.axis_1, self.axis_2 = scalar.vector_of(g.point(i)), scalar.vector_of(g.point(j))
        self.turn_1, self.elbow_turn = scalar.Turn(u), scalar.Turn(scalar.vector_of(g.direction(j)))
        self.axis_1_from_2 = self.elbow_turn.coordinates(scalar.reject(scalar.sub(self.axis_1, self.axis_2), u))
        # the joints' rotation (a slide turns nothing) and the label's constants
        self.first, self.second = scalar.vector_of(directions[i]), scalar.vector_of(directions[j])
        self.elbow = scalar.sub(self.axis_2, self.axis_1)
        self.up = scalar.vector_of(g.upward(g.direction(i)))

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The two slots for a target (4, 4), or NotGeneric (``reference``: not read, see
        :meth:`DecoupledPlan.solve_one`)."""
        x, seen = self.step.target(T)
        u, step = self.u, self.step
        height = scalar.dot(u, x) - scalar.dot(u, self.point)
        if self.slide is None:  # PlanarTwoLink's in_plane: the height clearly kept (off the plane the arrays word it)
            if not scalar.MARGIN * abs(height) <= GEOMETRY_TOLERANCE * self.size:
                raise scalar.NotGeneric
            arm, w3 = [], self.point
        else:
            slide = height / self.along  # prismatic_to_plane
            arm = [slide]
            w3 = scalar.add(self.point, (self.slide[0] * slide, self.slide[1] * slide, self.slide[2] * slide))
        from_1 = scalar.sub(x, self.axis_1)
        reach = scalar.norm(scalar.reject(from_1, u))
        from_2 = scalar.sub(w3, self.axis_2)
        roots = self.elbow_turn.angles_at_distance(self.elbow_turn.coordinates(scalar.reject(from_2, u)),
                                                   self.axis_1_from_2, reach, out_of_reach=True)
        if math.isnan(roots[1]):  # clearly out of reach: the array path words why
            raise scalar.NotGeneric
        target = self.turn_1.coordinates(from_1)
        from_1_length = scalar.norm(from_1)
        rows, codes = [], []
        for q2 in roots:
            w2 = scalar.add(scalar.rotate(self.elbow_turn.k, q2, from_2), self.axis_2)
            placed = self.turn_1.coordinates(scalar.sub(w2, self.axis_1))
            q1 = self.turn_1.angle(placed, target, scale=self.size)  # the point clear of axis 1, reached exactly
            elbow = scalar.rotate(self.first, q1, self.elbow)
            side = scalar.dot(scalar.cross(from_1, elbow), self.up)
            R_G = scalar.mm(scalar.rotation(self.first, q1), scalar.rotation(self.second, q2)) if step.turned else None
            step.rows(R_G, seen, [q1, q2, *arm], (scalar.side_code(side, from_1_length * scalar.norm(elbow)),), rows,
                      codes)
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)


class _OneRevoluteOnePose(_ArmOnePose):
    """:class:`DecoupledPlan` with a :class:`OneRevolute` positioner (a two-joint arm whose second joint is a
    roll, placing a full pose): subproblem 1 about axis 1, clearly exact (the target on the circle the point
    sweeps) and clear of the axis (where the joint is free); no label."""

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        positioner = plan.positioner
        g, (i,) = positioner.geometry, positioner.joints
        self.size, self.axis = g.length_scale, scalar.vector_of(g.point(i))
        self.turn = scalar.Turn(scalar.vector_of(g.direction(i)))
        self.placed = self.turn.coordinates(scalar.sub(scalar.vector_of(positioner.point), self.axis))
        self.direction = scalar.vector_of(positioner.model.directions[i])

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The one slot for a target (4, 4), or NotGeneric (``reference``: not read)."""
        x, seen = self.step.target(T)
        q1 = self.turn.angle(self.placed, self.turn.coordinates(scalar.sub(x, self.axis)), scale=self.size)
        rows, codes = [], []
        self.step.rows(scalar.rotation(self.direction, q1) if self.step.turned else None, seen, [q1], (), rows, codes)
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)


class _CylindricalOnePose(_ArmOnePose):
    """:class:`DecoupledPlan` with a :class:`OneRevoluteTwoPrismatic` positioner (the cylindrical RPP and PRP
    arms): the slides from the height along the revolute axis (linear) and the distance from it (a quadratic),
    then subproblem 1 for the revolute joint, in the positioner's slot order, as its ``solve`` works them out (it
    gives no label)."""

    def __init__(self, plan: DecoupledPlan, step: _WristStep) -> None:
        super().__init__(plan, step)
        positioner = plan.positioner
        g, r = positioner.geometry, positioner.revolute
        omega, p, V_pre, V_post, perp, a, nullspace, P, Q, Pn, Qn = positioner.equations
        self.a, self.a_squared, self.nullspace = a.tolist(), float(a @ a), nullspace.tolist()
        self.omega, self.axis = scalar.vector_of(omega), scalar.vector_of(p)
        self.point = scalar.vector_of(positioner.point)
        self.point_from_axis = scalar.sub(self.point, self.axis)
        self.beta = scalar.vector_of(perp @ (positioner.point - p))
        # the (3, 2) matrices by rows, and the null direction's images
        self.P, self.Q, self.V_pre, self.V_post = (scalar.matrix_of(M) for M in (P, Q, V_pre, V_post))
        self.Pn, self.Qn = scalar.vector_of(Pn), scalar.vector_of(Qn)
        self.geometry, self.size, self.revolute = g, g.length_scale, r
        self.turn = scalar.Turn(self.omega)
        order = list(positioner.joints)
        self.columns = (order.index(r), order.index(positioner.slides[0]), order.index(positioner.slides[1]))
        self.direction = scalar.vector_of(positioner.model.directions[r])

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The two slots for a target (4, 4), or NotGeneric; ``reference`` (n,) as :meth:`DecoupledPlan.solve`."""
        x, seen = self.step.target(T)
        omega, (a0, a1), (n0, n1) = self.omega, self.a, self.nullspace
        b = scalar.dot(scalar.sub(x, self.point), omega)
        s0 = (b * a0 / self.a_squared, b * a1 / self.a_squared)
        alpha = scalar.reject(scalar.sub(x, self.axis), omega)
        lhs = tuple(alpha[i] - (self.P[i][0] * s0[0] + self.P[i][1] * s0[1]) for i in range(3))
        rhs = tuple(self.beta[i] + (self.Q[i][0] * s0[0] + self.Q[i][1] * s0[1]) for i in range(3))
        A = scalar.dot(self.Pn, self.Pn) - scalar.dot(self.Qn, self.Qn)
        B = -2 * scalar.dot(lhs, self.Pn) - 2 * scalar.dot(rhs, self.Qn)
        C = scalar.dot(lhs, lhs) - scalar.dot(rhs, rhs)
        band = target_error(self.geometry, scalar.norm(x))  # an azimuth on a radius is known to this / radius
        rows, codes = [], []
        for t in scalar.quadratic(A, B, C, self.size):
            if t != t:  # a linear row's second slot
                self._empty(rows, codes, 1)
                continue
            s = (s0[0] + t * n0, s0[1] + t * n1)
            body = scalar.add(self.point_from_axis, tuple(row[0] * s[0] + row[1] * s[1] for row in self.V_post))
            world = scalar.sub(scalar.sub(x, self.axis), tuple(row[0] * s[0] + row[1] * s[1] for row in self.V_pre))
            placed, wanted = self.turn.coordinates(body), self.turn.coordinates(world)
            if min(placed[3], wanted[3]) <= scalar.MARGIN * band:  # the point near the axis: the joint free there
                raise scalar.NotGeneric
            theta = self.turn.angle(placed, wanted, scale=self.size)
            if reference is not None and scalar.clearly_within(
                    abs(wrap_any_float(theta - float(reference[self.revolute]))) * wanted[3], band):
                theta = wrap_any_float(float(reference[self.revolute]))
            arm = [0.0, 0.0, 0.0]
            arm[self.columns[0]], arm[self.columns[1]], arm[self.columns[2]] = theta, s[0], s[1]
            R_G = scalar.rotation(self.direction, theta) if self.step.turned else None
            self.step.rows(R_G, seen, arm, (), rows, codes)
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)


class _WristOnlyOnePose(_ArmOnePose):
    """:class:`DecoupledPlan` of a spherical wrist alone (a three-joint arm placing an orientation): its two
    slots, turned by nothing before it."""

    _UNTURNED = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    def solve(self, T: np.ndarray, reference: np.ndarray | None = None) -> scalar.OnePose:
        """The two slots for a target (4, 4), or NotGeneric (``reference``: not read)."""
        _, seen = self.step.target(T)
        rows, codes = [], []
        self.step.rows(self._UNTURNED, seen, [], (), rows, codes)
        return scalar.OnePose(rows, codes, self.names, self.values, self.dof)
