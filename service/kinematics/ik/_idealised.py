"""Closed forms for geometry as files state it: solve the idealised arm, refine on the true arm.

A description rounded the way CAD exports and vendors round (π/2 written
1.5708, axes 1e-5 off parallel, lengths to 0.1 mm) is not exactly of any
family, but :func:`~._structure.idealised` snaps it to one within
:data:`~service.kinematics._tolerances.RECOGNITION_TOLERANCE`. This plan runs
that family's closed form on the idealised arm, then Newton-refines every
candidate on the true arm (FK and Jacobian of the robot as described); the
usual FK check then verifies it at the usual tolerance.

When is the answer still complete? The true arm is the idealised one moved by
δ (``deviation``: radians, or fractions of the arm's size). Its real solutions
are the idealised ones continued, except where a pair of roots meets, which
near δ = 0 happens only close to where the idealised arm's roots meet (a
boundary or singular target). A row is claimed complete only when

1. every idealised solution refines to a verified solution of the true arm,
   and no two refine to the same one (no root pair merged or vanished);
2. no other candidate (a subproblem's least-squares answer, the nearest the
   idealised arm gets on that branch, before or after refinement) comes within
   :data:`NEAR_MISS` × δ of the target on the true arm without reaching it:
   there a root pair the idealised arm lacks could appear. Every change of the
   solution count of a decoupled family happens where one of its subproblems'
   root pairs meets, which is where those least-squares answers lie. (For an
   arm with fewer joints than the target constrains, such as a SCARA's pose, a
   candidate of another sheet that Gauss–Newton leaves stalled at a residual of
   at least 1e-3 δ is clearly apart and does not count);
3. the idealised family reports no singularity for the target (a free joint or
   merged roots, whose continuation under the perturbation is not isolated),
   and no solution is within :data:`SINGULAR_MARGIN` × δ (or
   :data:`SINGULAR_FLOOR` × √δ) of a singularity of
   the true arm (σ_min of its scaled Jacobian, and of its position rows alone
   for an arm with fewer joints than the pose constrains, whose positioning
   joints may be singular where the whole Jacobian is not); for a row with no solution at
   all, no candidate is, nor any slot left empty whose value comes within √δ
   of the target (there a step of the closed form is ill-conditioned:
   the UR type's q6 from q5 ≈ 0 turns by O(1) under a δ change of the target,
   so the least-squares answers after it may lie far from a solution the true
   arm has, and criterion 2 would not see it); and no idealised solution has
   its spherical wrist within √(:data:`WRIST_ALIGNMENT_BAND` × δ) of aligning
   its outer axes, a band that widens where the positioning joints steer the
   wrist centre poorly (see there), nor its wrist centre within
   √(:data:`AXIS_2_BAND` × δ) arm sizes of axis 2, where joint 2 is free (for a
   row with no solution, no candidate's);
4. the idealised family promises the target on its own arm, and leaves no
   joint free for every pose target: along such a joint the idealised arm has a
   one-parameter family, the true arm isolated roots or none, and refining the
   value it was held at finds at most the nearest (a five-joint arm of a sweep,
   rounded by 1e-5, whose point lies on axis 2: held at q2 = 0, refined to a
   stall, and its own pose at q2 = −0.12 promised unreachable).

The true arm, a general arm near a decoupled one, may have more solutions in
the complex domain (up to 16 for a 6R); the extra ones come from infinity
(x = tan(θ/2) → ±i) as δ grows from 0 and stay far from real for small δ,
so they do not break this count.

Otherwise the row is marked incomplete and the caller's fallback answers it:
the general solver when there is one (:data:`GENERAL_SOLVER` in ``_solve``),
else the numeric search, with ``complete: false``. The refined solutions found
here are kept either way.
"""

from __future__ import annotations

import numpy as np

from .._forward import JointTrig, ScrewModel, geometric_jacobian
from .._robot import Robot, ScrewJoint
from .._tolerances import ACCEPT_RESIDUAL
from ._structure import arm_size
from ._types import Candidates, LabelCodes, Sealed
from ._gauss_newton import gauss_newton
from ._goals import PoseGoal
from ._verify import POLISH_FROM, first_of_each, residual_arrays, wrap_revolute

#: A rejected candidate whose true-arm residual (fraction of the arm's size, or radians) is within this many times
#: the idealisation's deviation marks the row incomplete: the perturbation moves the tool by at most a few δ
#: (each of up to six axes turned by δ about a point on the arm), so a smaller margin could miss a root pair.
NEAR_MISS = 50.0

#: An idealised candidate is one of the idealised arm's solutions when its residual there (fraction of the arm's
#: size, or radians) is below this: the closed forms are exact to rounding, a few digits fewer near a singularity.
IDEAL_RESIDUAL = 1e-7

#: A solution where the smallest singular value of the true arm's scaled Jacobian is within this many times the
#: deviation is near a singular set of the arm (a wrist or shoulder singularity, where the idealised family has a
#: free joint): the perturbation there may move or split the roots by more than Newton's step can be trusted to
#: follow, so the row is not claimed complete. (Root pairs meeting at a fold need no such margin: a pair that
#: vanishes fails criterion 1, a pair that appears is a near miss, criterion 2.)
SINGULAR_MARGIN = 10.0

#: ... and within this many times √δ, where that is wider (arms moved by less than (this / SINGULAR_MARGIN)² = 1e-6).
#: Where two singular sets meet, σ_min is about the product of the distances from each, and the idealised family's
#: root pairs there meet, which moves them by √δ, not δ: Stanford arms moved by 1e-10 with the slide 1e-7 from the
#: shoulder's centre and the wrist at q5 ≈ π read σ_min of 15–35 δ (5e-4 √δ) at the refined solutions, eight of them
#: verified, and the pose's own configuration, 1.5 rad from every one, was left out; UR5s moved by 1e-10 with q5 and
#: q2 near singular (23 of 150 such poses) listed none within 1e-3 … 0.05 rad of their own. At this floor the arms
#: rounded as CAD exports round (δ ≥ 1e-6) keep their margin of 10 δ.
SINGULAR_FLOOR = 0.01

#: An idealised solution whose spherical wrist is within √(this × δ) of aligning its outer axes (the wrist's volume,
#: :meth:`~._decoupled.DecoupledPlan.wrist_volume`) marks the row incomplete. At the alignment the idealised arm has a
#: one-parameter family (only q_a ± q_c fixed), the true arm isolated roots along it, and the idealised flip pair
#: meets there: a pair that meets moves by √δ under a change δ, not by δ. Within that band the refinement reaches the
#: true roots nearest the idealised read-off of q_a, not every one: the PUMA and Stanford arms moved by 1e-8 … 1e-5 at
#: q5 ≈ π put their flip pair 1e-4 … 1e-2 from the alignment, refined to verified solutions clear of the true arm's
#: singularities, and the pose's own configuration, 1.1 … 1.2 rad from every listed one, was left out.
#:
#: The change the wrist sees is δ through positioning joints that steer the wrist centre well, and δ / σ through joints
#: whose Jacobian at the centre has a smallest singular value σ (in arm sizes,
#: :meth:`~._decoupled.DecoupledPlan.positioning_jacobian`): their values, and the frame they hand the wrist, move
#: by that much. So the band is √(max(this, 1 / σ) × δ). A Stanford arm moved by 1e-10 at q2 ≈ π (the steering's σ
#: 3e-6) and q5 ≈ 0 had its flip pair at 3.3 √δ, outside √(10 δ), and was promised without the
#: pose's own configuration; with 1 / σ the band is 0.015 there.
WRIST_ALIGNMENT_BAND = 10.0

#: An idealised candidate whose wrist centre is within √(this × δ) arm sizes of axis 2 marks the row incomplete: there
#: joint 2 turns the centre about itself (it is free on the axis), the idealised arm has a one-parameter family, and
#: the true arm's roots near it are not the idealised ones continued. The Stanford type passes its slide through
#: axis 2; an idealised arm whose slide line misses the axis by δ is solved from the reach alone (the slide known to
#: √(h δ) there, h the shoulder's offset). Stanford arms moved by 1e-6 (δ 2.5e-6) with the slide 1e-7 … 1e-5 from the
#: crossing listed eight refined solutions whose centre was 0.9 … 1.7 √δ from the axis, clear of the true
#: arm's singularities (σ_min 2e-4 … 4e-4 against a margin of 2.5e-5), and not the pose's own configuration (slide
#: 1e-7, 1.6 rad from every listed one): 5 of 100 such poses at each of two seeds; a third promised one unreachable,
#: its least-squares candidates at the crossing (so a candidate of a row without a solution counts too). At 5 the
#: rounded catalogue arms and the Doosan M1013 URDF keep their promises but for 5 of 500 of the Fanuc LR Mate's (8 →
#: 13). Axis 1 needs no band: its distance is the shoulder's free joint of every arm, where 0 of 500 poses of KR6,
#: IRB120 and LR Mate arms moved by 1e-10 … 1e-6 with the centre 1e-7 … 1e-2 from it broke a promise, and a band
#: of 10 δ on every positioning axis withdrew 39 of the Doosan's 500 (35 → 74 incomplete).
AXIS_2_BAND = 5.0

#: Newton (Gauss–Newton) steps from an idealised solution onto the true arm. The start is δ-close, so a regular root
#: is reached to machine precision in two or three; more steps only help near a fold, which criterion 3 excludes.
REFINE_STEPS = 6


class IdealisedPlan(Sealed):
    """A family's plan for the idealised arm, answering for the true ``robot``."""

    method = "analytic"

    def __init__(self, inner, model: ScrewModel, robot: Robot, deviation: float, size: float,
                 constrain_orientation: bool) -> None:
        """``inner`` is the family's plan for the idealised arm, whose screw model is ``model``."""
        self.inner = inner
        #: the idealised arm as a robot of its own (its screws and home pose), whose FK is the core's chain program
        self.ideal_robot = Robot.from_screws(
            [ScrewJoint(f"q{index + 1}", "revolute" if turns else "prismatic", tuple(axis.tolist()),
                        tuple(point.tolist()))
             for index, (axis, point, turns) in enumerate(zip(model.directions, model.points, model.is_revolute))],
            model.home)
        self.robot = robot
        self.deviation = deviation
        self.size = size
        self.constrain_orientation = constrain_orientation
        task = (6 if constrain_orientation else 3)
        #: the target constrains more than the arm's joints can set (a SCARA's pose, a planar arm's position)
        self.under_determined = robot.dof < task
        self.structure = inner.structure
        self.generic_count = inner.generic_count

    @property
    def free_joints(self) -> list[int]:
        return self.inner.free_joints

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        """Candidates (N, m, n), refined on the true arm, with ``complete`` (N,) set by the criteria above."""
        robot = self.robot
        scalar = self._one_pose_start(world_T_targets, reference)
        if scalar is not None:  # the array solve would give the same slots
            ideal, (ideal_joints, finite, solutions) = scalar
        else:
            ideal = self.inner.solve(world_T_targets, reference)
            ideal_joints, finite, solutions = self._idealised_slots(ideal, world_T_targets)
        joints = ideal_joints.copy()  # refined in place below
        position, orientation = residual_arrays(robot, joints, world_T_targets)
        near_before = finite & (self._size(position, orientation) <= NEAR_MISS * self.deviation)
        # refine the idealised solutions, and every other candidate that comes close (an arm with fewer joints than
        # the target constrains reaches the true arm's targets only within δ, where the idealised family rejects
        # them)
        tried = finite & (ideal.valid | near_before)
        rows, slots = np.nonzero(tried)
        if len(rows):
            refined = self._refined(joints[rows, slots], world_T_targets[rows], REFINE_STEPS)
            joints[rows, slots] = wrap_revolute(robot, refined)
        position, orientation = residual_arrays(robot, joints, world_T_targets)
        accepted = self._accepted(position, orientation) & tried
        # a row with nothing verified: the closed form's decoupling may amplify δ beyond the near-miss margin
        # where one of its steps is poorly conditioned though the arm is not (an under-determined arm's joint 1
        # from a point close to axis 1, which the orientation fixes): every other candidate is refined too, and
        # a row answered only that way is not promised complete (the margins of criterion 2 did not hold). The
        # near misses of criterion 2 stay those of the candidates it speaks of (a refined least-squares answer of
        # an unreachable target says nothing about the margin)
        rescue = finite & ~tried & ~accepted.any(axis=1)[:, None]
        rescued = np.zeros(len(world_T_targets), dtype=bool)
        rows, slots = np.nonzero(rescue)
        if len(rows):  # only the refined slots that reach are kept; the others stay as they were
            refined = wrap_revolute(robot, self._refined(joints[rows, slots], world_T_targets[rows], REFINE_STEPS))
            p, o = residual_arrays(robot, refined[:, None, :], world_T_targets[rows])
            reached = self._accepted(p[:, 0], o[:, 0])
            rows, slots = rows[reached], slots[reached]
            joints[rows, slots] = refined[reached]
            position[rows, slots], orientation[rows, slots] = p[reached, 0], o[reached, 0]
            accepted[rows, slots] = True
            rescued[rows] = True
        # 2. near misses: a candidate that came within NEAR_MISS δ of the target on the true arm, before or after
        # refinement, without reaching it; or, on an arm with as many joints as the target constrains, reaching it
        # though the idealised arm does not (a least-squares answer): a pair of roots appears there, and
        # refinement finds one of them at most (a UR10e moved by 1.2e-6, its elbow 1.9e-3 rad from stretched where
        # the idealised arm's is just beyond: of the true arm's roots ±1.9e-3, one was refined to and listed, the
        # pose's own was left out). An under-determined arm's idealised family reaches no target exactly.
        after = self._size(position, orientation)
        reached = accepted if self.under_determined else accepted & solutions
        missed = (near_before | (tried & (after <= NEAR_MISS * self.deviation))) & ~reached
        if self.under_determined and missed.any():
            missed &= ~self._stalled_apart(joints, world_T_targets, missed, after)
        near_miss = missed.any(axis=1)
        # 1. every idealised solution refined to a verified one, and no two to the same one
        converged = ~(solutions & ~accepted).any(axis=1)
        distinct = _distinct_counts(robot, joints, solutions & accepted) == _distinct_counts(robot, ideal_joints,
                                                                                             solutions)
        # 3. no singular target: none flagged by the family, and every solution clear of the true arm's
        # singularities (where the idealised family's roots may meet or split)
        singular = np.zeros(len(world_T_targets), dtype=bool)
        # (a row without a verified solution is checked at every candidate: at a singularity a downstream step of
        # the closed form is ill-conditioned, e.g. q6 from q5 ≈ 0, so a least-squares answer's residual there
        # does not bound how far the target is from a root pair, and "unreachable" could not be promised; so is
        # every slot the family left empty whose value comes within √δ, the distance a root pair that meets moves:
        # where two singular sets meet, a subproblem's least-squares answer is not the arm's closest approach, and
        # a Stanford arm moved by 1e-8 missed its own poses by 80–350 δ from there, promised unreachable)
        unanswered = ~accepted.any(axis=1)
        close = finite & (after <= np.sqrt(self.deviation))
        rows, slots = np.nonzero(accepted | (finite & (ideal.valid | close) & unanswered[:, None]))
        if len(rows):
            # an arm with fewer joints than the pose constrains is placed by its positioning joints: where their
            # position Jacobian is singular (a joint the position leaves free), the family reads that joint off a
            # radius the deviation turns, though the whole Jacobian keeps its rank
            smallest = self._smallest_singular_value(joints[rows, slots],
                                                     with_position_rows=self.under_determined)
            margin = max(SINGULAR_MARGIN * self.deviation, SINGULAR_FLOOR * np.sqrt(self.deviation))
            singular[rows[smallest <= margin]] = True
        for mask, _ in ideal.singularities.entries:
            singular |= mask
        # the wrist's alignment and axis 2, where the positioning joints' steering of the wrist centre tells
        steered = np.nonzero(finite & (ideal.valid | unanswered[:, None]))
        steering = self.inner.positioning_jacobian(ideal_joints[steered], self.size) \
            if len(steered[0]) and hasattr(self.inner, "positioning_jacobian") else None
        singular |= self._near_wrist_alignment(ideal_joints, finite & ideal.valid, steered, steering)
        singular |= self._near_axis_2(steered, steering, len(world_T_targets))
        # a row where the idealised family gave no candidate at all (not even a least-squares one) has no near miss
        # to measure: its "no solution" is the idealised arm's, which the true one need not share
        complete = converged & distinct & ~near_miss & ~singular & ~rescued & finite.any(axis=1)
        # 4. what the idealised family does not promise on its arm, and a joint it leaves free for every target
        if ideal.complete is not None:
            complete &= ideal.complete
        if self.constrain_orientation and self.inner.free_joints:
            complete[:] = False
        # (no near_singular for the verifier's isolation check: criterion 3 already withdrew every row with an
        # accepted solution whose σ_min is within max(10 δ, 0.01 √δ), a margin far above ISOLATED_BELOW)
        return Candidates(joints, accepted, ideal.singularities, complete=complete)

    def _idealised_slots(self, ideal: Candidates, world_T_targets: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The idealised family's candidates (N, m, n) as the criteria read them: their joints (revolute ones
        wrapped, 0 where a value is not finite), which slots are finite (N, m), and which hold one of the idealised
        arm's own solutions (N, m: valid, finite, and its residual there within :data:`IDEAL_RESIDUAL`, as its
        closed form is exact up to rounding near a singularity)."""
        finite = np.isfinite(ideal.joints).all(axis=-1)
        joints = wrap_revolute(self.robot, np.where(finite[..., None], ideal.joints, 0.0))
        return joints, finite, ideal.valid & finite & (self._ideal_error(joints, world_T_targets) <= IDEAL_RESIDUAL)

    def _one_pose_start(self, world_T_targets: np.ndarray, reference: np.ndarray | None
                        ) -> tuple[Candidates, tuple[np.ndarray, np.ndarray, np.ndarray]] | None:
        """For one target (1, 4, 4), the idealised family's scalar path (``solve_one``) as candidates, with their
        :meth:`_idealised_slots`, where it gives the array solve's slots for a fraction of the time: a clearly
        generic pose whose every slot holds one of the idealised arm's solutions, or any pose it answers when its
        slots are the array solver's (:attr:`~._scalar.OnePose.slots_as_array`: empty where that leaves a slot
        undefined, least-squares where that does). None elsewhere (then the array solve answers)."""
        if len(world_T_targets) != 1 or not hasattr(self.inner, "solve_one"):
            return None
        one_pose = self.inner.solve_one(world_T_targets[0], reference)
        if one_pose is None or not (one_pose.slots_as_array or all(q is not None for q in one_pose.rows)):
            return None
        candidates = Candidates(one_pose.joints, one_pose.valid, one_pose.singularities)
        slots = self._idealised_slots(candidates, world_T_targets)
        if not (one_pose.slots_as_array or slots[2].all()):
            return None
        return candidates, slots

    def _near_wrist_alignment(self, ideal_joints: np.ndarray, valid: np.ndarray,
                              steered: tuple[np.ndarray, np.ndarray], steering: np.ndarray | None) -> np.ndarray:
        """Which targets (N,) have a ``valid`` idealised candidate (N, m, n) whose spherical wrist is within the
        band of :data:`WRIST_ALIGNMENT_BAND` of aligning its outer axes, widened by how poorly the positioning
        joints steer the wrist centre there (all False for a family without a spherical wrist). ``steering``
        (K, 3, 3) is :meth:`~._decoupled.DecoupledPlan.positioning_jacobian` at the candidates ``steered`` (rows
        and slots (K,) each, every valid one among them), or None."""
        volume = self.inner.wrist_volume(ideal_joints) if hasattr(self.inner, "wrist_volume") else None
        if volume is None:
            return np.zeros(len(valid), dtype=bool)
        near = valid & (volume ** 2 <= WRIST_ALIGNMENT_BAND * self.deviation)
        # the others: within √(δ / σ), σ the steering's smallest singular value, where that is the wider band
        if steering is not None:
            rows, slots = steered
            others = (valid & ~near)[rows, slots]
            rows, slots = rows[others], slots[others]
            widened = _smallest_singular_value_at_most(steering[others], self.deviation / volume[rows, slots] ** 2)
            near[rows[widened], slots[widened]] = True
        return near.any(axis=1)

    def _near_axis_2(self, steered: tuple[np.ndarray, np.ndarray], steering: np.ndarray | None,
                     n_targets: int) -> np.ndarray:
        """Which targets (N,) have a candidate among ``steered`` (rows and slots (K,) each, with their ``steering``
        (K, 3, 3) as in :meth:`_near_wrist_alignment`) whose wrist centre is within √(:data:`AXIS_2_BAND` × δ) arm
        sizes of axis 2, where joint 2 turns it about itself: the norm of joint 2's column of the steering."""
        near = np.zeros(n_targets, dtype=bool)
        if steering is not None:
            from_axis_2 = np.linalg.norm(steering[:, :, 1], axis=-1)
            near[steered[0][from_axis_2 ** 2 <= AXIS_2_BAND * self.deviation]] = True
        return near

    def _refined(self, q: np.ndarray, world_T_targets: np.ndarray, steps: int) -> np.ndarray:
        """Gauss–Newton steps on the true arm from joint vectors q (k, n) towards their targets (k, 4, 4)."""
        goal = PoseGoal(world_T_targets, self.constrain_orientation)
        return gauss_newton(self.robot, goal, q, np.arange(len(q)), steps=steps, tolerance=POLISH_FROM).joints

    def _accepted(self, position: np.ndarray, orientation: np.ndarray) -> np.ndarray:
        """Which slots reach the target on the true arm at the acceptance tolerance."""
        accepted = position <= ACCEPT_RESIDUAL * arm_size(self.robot)
        if self.constrain_orientation:
            accepted &= orientation <= ACCEPT_RESIDUAL
        return accepted

    def _stalled_apart(self, joints: np.ndarray, world_T_targets: np.ndarray, missed: np.ndarray,
                       after: np.ndarray) -> np.ndarray:
        """Which ``missed`` slots (N, m) sit at a least-squares point clearly apart from the target.

        An arm with fewer joints than the target constrains reaches a δ-thin neighbourhood of the idealised
        family's targets on several sheets (e.g. a SCARA's two assembly modes); on the true arm a target from one
        sheet is generally missed by the other by about δ. There Gauss–Newton stalls at a positive residual: one
        more step lowers it by less than 1 %, and it is at least 1e-3 δ (far above the acceptance tolerance) and
        within the near-miss band, so no solution lies near that candidate, unless the candidate is near a
        singularity of the true arm, where Gauss–Newton stalls beside a solution: σ_min within √(SINGULAR_MARGIN
        δ), as the roots that meet there move by the square root of the deviation (a five-joint arm rounded by
        1e-6, its wrist 1e-9 from aligned: a stall at σ_min 1.5e-4 of residual 1.5e-6, its own pose 3.5e-3 rad
        away).
        """
        rows, slots = np.nonzero(missed)
        stepped = self._refined(joints[rows, slots], world_T_targets[rows], 1)
        position, orientation = residual_arrays(self.robot, stepped[:, None, :], world_T_targets[rows])
        now, before = self._size(position, orientation)[:, 0], after[rows, slots]
        apart = np.zeros_like(missed)
        # (a refinement that left the near band, its steps thrown off by a near-singular Jacobian, proves nothing;
        # nor does a stall at a singular configuration, where the step cannot move the way the target lies)
        apart[rows, slots] = (before >= 1e-3 * self.deviation) & (now >= 0.99 * before) \
            & (before <= NEAR_MISS * self.deviation) \
            & (self._smallest_singular_value(stepped) > np.sqrt(SINGULAR_MARGIN * self.deviation))
        return apart

    def _smallest_singular_value(self, joints: np.ndarray, *, with_position_rows: bool = False) -> np.ndarray:
        """σ_min of the true arm's Jacobian at joints (k, n), position rows in arm sizes (those rows alone for a
        position target); with ``with_position_rows``, the smaller of that and the σ_min of the position rows
        alone (the same Jacobian); shape (k,).

        From the singular values of J itself, accurate to about 1e-16 σ_max: an arm 1e-10 off its family compares
        σ_min with SINGULAR_MARGIN δ = 1e-9, where the eigenvalues of JᵀJ (σ_min² beside a rounding of
        1e-16 σ_max²) would read a σ_min of 1e-9 as anything up to 1e-8.
        """
        J = geometric_jacobian(self.robot, joints)
        J[:, :3, :] /= self.size
        if not self.constrain_orientation:
            J = J[:, :3, :]
        smallest = np.linalg.svd(J, compute_uv=False)[:, -1]
        if with_position_rows and self.constrain_orientation:
            smallest = np.minimum(smallest, np.linalg.svd(J[:, :3, :], compute_uv=False)[:, -1])
        return smallest

    def _ideal_error(self, joints: np.ndarray, world_T_targets: np.ndarray) -> np.ndarray:
        """The idealised arm's residual at joints (N, m, n): position / size, or the larger with the orientation."""
        return self._size(*PoseGoal(world_T_targets).residuals(self.ideal_robot, joints))

    def _size(self, position: np.ndarray, orientation: np.ndarray) -> np.ndarray:
        size = position / self.size
        return np.maximum(size, orientation) if self.constrain_orientation else size

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """The idealised family's labels of joint vectors (M, n) of the true arm, except where they are not the
        true arm's: a label changes where the idealised arm's branches meet, which is up to a few δ from where
        the true arm's do. So near a singularity of the true arm (σ_min within :data:`SINGULAR_MARGIN` δ), a
        label whose value changes within that margin of the joints (any joint moved by SINGULAR_MARGIN δ) is left
        out (−1), as where two branches meet: the true arm's solution there may carry either value, and a path
        that stays on one branch of the true arm would see it flip (issue 22.11, a Doosan M1013 written with
        1.571 for π/2)."""
        joints = np.asarray(joints, dtype=float)
        codes = self.inner.label_codes(joints, trig)
        if not codes or not len(joints):
            return codes
        near = np.flatnonzero(self._smallest_singular_value(joints) <= SINGULAR_MARGIN * self.deviation)
        if not len(near):
            return codes
        n = joints.shape[-1]
        steps = SINGULAR_MARGIN * self.deviation * np.concatenate([np.eye(n), -np.eye(n)])  # (2n, n)
        moved = (joints[near, None, :] + steps[None]).reshape(-1, n)
        around = self.inner.label_codes(moved)
        out: LabelCodes = {}
        for name, (values, own) in codes.items():
            own = own.copy()
            if name in around:
                other = around[name][1].reshape(len(near), 2 * n)
                flips = ((other != own[near, None]) & (other >= 0)).any(axis=1)
                own[near[flips]] = -1
            out[name] = (values, own)
        return out


def _distinct_counts(robot: Robot, joints: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """How many distinct joint vectors (revolute joints modulo 2π, within 1e-6) each row's ``ok`` slots hold."""
    return first_of_each(robot, joints, ok).sum(axis=1)


def _smallest_singular_value_at_most(matrices: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """Whether each 3 × 3 matrix (K, 3, 3) has its smallest singular value at most ``bound`` (K,). σ₃ ≥ 2 |det| /
    ‖·‖²_F (σ₁ σ₂ ≤ (σ₁² + σ₂²) / 2), so only the matrices that bound does not clear need their singular values:
    a batch's steering is mostly far from singular."""
    at_most = np.zeros(len(matrices), dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        floor = 2.0 * np.abs(np.linalg.det(matrices)) / np.einsum("kij,kij->k", matrices, matrices)
    doubtful = np.flatnonzero(~(floor > bound))  # (a NaN floor, of a zero matrix, is doubtful)
    if len(doubtful):
        at_most[doubtful] = np.linalg.svd(matrices[doubtful], compute_uv=False)[:, -1] <= bound[doubtful]
    return at_most
