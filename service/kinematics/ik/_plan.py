"""Choosing a solver from the arm's geometry.

The plan depends on the joint axes only (read off the screw model), never on
the robot's name or its DH table, so two descriptions of the same arm get the
same plan. Adding a structure class is adding one family module and one line
here.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .._cache import memo
from .._forward import JointTrig, link_frames, screw_model
from .._robot import Robot
from .._tolerances import EXACT_DEVIATION, RECOGNITION_TOLERANCE
from ._coaxial import CoaxialPlan, coaxial_pair, without_joint
from ._decoupled import DecoupledPlan
from ._general_6r import General6RPlan
from ._idealised import IdealisedPlan
from ._positioning import find_positioner
from ._reversed import ReversedPlan, reversed_geometry
from ._screws import apply, chain_motion
from ._slide_after_wrist import SlideAfterSphericalWrist
from ._structure import Geometry, canonical_model, exactly_idealised, idealised
from ._three_parallel import SkewWristThreeParallelPlan, ThreeParallelPlan
from ._three_parallel_end import ThreeParallelAtEndPlan, parallel_elbow_codes
from ._types import Candidates, LabelCodes
from ._wrist import Roll, SphericalWrist, TwoAxisWrist


class Plan(Protocol):
    """A family's solver for one robot. A family with a scalar path for one pose also has
    ``solve_one(world_T_target) -> OnePose | None`` (:mod:`._scalar`: the candidates with their labels); None
    sends the pose to ``solve`` and ``label_codes``. A family may set ``targets_per_chunk``, the most targets a
    batch solves at once (default :data:`~._closed_form.CHUNK`)."""

    structure: str
    generic_count: int
    free_joints: list[int]

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates: ...

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes: ...


def geometry_of(robot: Robot) -> Geometry:
    """The robot's canonical screw model and size (:func:`canonical_model`), up direction (base z) and link x axes
    at q = 0, in the world frame."""
    return memo(robot, "ik_geometry", lambda: _geometry_of(robot))


def _geometry_of(robot: Robot) -> Geometry:
    frames = link_frames(robot, np.zeros(robot.dof))
    model, size = canonical_model(screw_model(robot), robot.world_T_base[:3, 3])  # size: arm_size(robot)
    return Geometry(model, size, up=robot.world_T_base[:3, 2].copy(), link_x=frames[1:, :3, 0].copy())


def plan_for(robot: Robot, *, constrain_orientation: bool, reference: np.ndarray | None) -> Plan | None:
    """The analytic plan for this robot and kind of target, or None when no family applies.

    A closed-form family is looked for in the arm as given (tolerance ``GEOMETRY_TOLERANCE``; an arm that holds its
    relations only to more than ``EXACT_DEVIATION`` is solved with them made exact and refined, as below), then
    in its idealisation (relations within ``RECOGNITION_TOLERANCE`` made exact, :func:`idealised`): that plan solves the
    idealised arm and refines on the true one (:class:`IdealisedPlan`). A 6R pose target that neither finds goes
    to the general 6R solver, last, because a rounded Pieper arm is nearly degenerate for its elimination.
    """
    geometry = geometry_of(robot)
    pair = coaxial_pair(geometry)
    if pair is not None:  # only the pair's sum is fixed: no plan of the whole arm says so
        return _coaxial_plan(geometry, pair, constrain_orientation, reference)
    plan = _family_plan(geometry, constrain_orientation, reference)
    if plan is not None and exactly_idealised(geometry).deviation <= EXACT_DEVIATION:
        return plan
    ideal = idealised(geometry)
    if ideal.deviation > 0.0:
        ideal_plan = _family_plan(ideal.geometry, constrain_orientation, reference)
        if ideal_plan is not None:
            return IdealisedPlan(ideal_plan, ideal.geometry.model, robot, ideal.deviation, geometry.length_scale,
                                 constrain_orientation)
    if plan is not None:
        return plan
    return General6RPlan.match(geometry) if constrain_orientation else None


def plan_for_geometry(geometry: Geometry, *, constrain_orientation: bool, reference: np.ndarray | None) -> Plan | None:
    """:func:`plan_for` on a screw model directly, exact recognition only (the idealised retry needs the robot):
    also for arms that exist only as models, such as a redundant arm with joints locked (see ``_redundant``)."""
    pair = coaxial_pair(geometry)
    if pair is not None:
        return _coaxial_plan(geometry, pair, constrain_orientation, reference)
    plan = _family_plan(geometry, constrain_orientation, reference)
    if plan is None and constrain_orientation:
        plan = General6RPlan.match(geometry)
    return plan


def _coaxial_plan(geometry: Geometry, pair: tuple[int, int, str], constrain_orientation: bool,
                  reference: np.ndarray | None) -> CoaxialPlan | None:
    """Two consecutive coaxial revolute joints (``pair``, :func:`coaxial_pair`): the plan of the arm without the
    second (see :mod:`._coaxial`), or None when no family covers that arm."""
    first, second, relation = pair
    if reference is not None:  # the locked arm's: joint i carries q_i ± q_j
        full = np.asarray(reference, dtype=float)
        reference = np.delete(full, second)
        reference[first] = full[first] + (1.0 if relation == "sum" else -1.0) * full[second]
    inner = plan_for_geometry(without_joint(geometry, second), constrain_orientation=constrain_orientation,
                              reference=reference)
    return None if inner is None else CoaxialPlan(inner, pair, geometry.dof)


def _family_plan(geometry: Geometry, constrain_orientation: bool, reference: np.ndarray | None) -> Plan | None:
    n = geometry.dof
    if constrain_orientation:
        return _pose_plan(geometry, n)
    return _position_plan(geometry, n, reference)


def _pose_plan(geometry: Geometry, n: int) -> Plan | None:
    decoupled = _decoupled_pose_plan(geometry, n)
    if decoupled is not None:
        return decoupled
    three_parallel = _three_parallel_plan(geometry)
    if three_parallel is not None:
        return three_parallel
    slide_after_wrist = SlideAfterSphericalWrist.match(geometry)
    if slide_after_wrist is not None:
        return slide_after_wrist
    # a wrist at the base: the inverse chain decouples
    reverse = reversed_geometry(geometry)
    inverse = _decoupled_pose_plan(reverse, n) or SlideAfterSphericalWrist.match(reverse)
    if inverse is not None:
        return ReversedPlan(inverse, geometry.model.home, n)
    # no closed form: the general 6R elimination (it refuses Pieper arms and anything not 6R)
    return _reversed_three_parallel_plan(geometry, reverse, n)


#: Three consecutive parallel axes: the families as the chain is described, then (name, family, first
#: parallel axis) of the inverse chain: axes 3 ∥ 4 ∥ 5 are axes 2 ∥ 3 ∥ 4 seen from the tool, and axes
#: 1 ∥ 2 ∥ 3 are axes 4 ∥ 5 ∥ 6.
_THREE_PARALLEL = (ThreeParallelPlan, SkewWristThreeParallelPlan, ThreeParallelAtEndPlan)
_THREE_PARALLEL_REVERSED = (("three_parallel_intersecting_shoulder", ThreeParallelPlan, 2),
                            ("three_parallel_skew_shoulder", SkewWristThreeParallelPlan, 2),
                            ("three_parallel_at_base", ThreeParallelAtEndPlan, 0))


def _three_parallel_plan(geometry: Geometry) -> Plan | None:
    for family in _THREE_PARALLEL:
        plan = family.match(geometry)
        if plan is not None:
            return plan
    return None


def _reversed_three_parallel_plan(geometry: Geometry, reverse: Geometry, n: int) -> Plan | None:
    for structure, family, first in _THREE_PARALLEL_REVERSED:
        plan = family.match(reverse)
        if plan is not None:  # the elbow label of the parallel axes as the chain is described
            return ReversedPlan(plan, geometry.model.home, n, structure=structure,
                                label_codes=lambda joints, trig=None: {"elbow": parallel_elbow_codes(geometry, joints, first, trig)})
    return None


def _decoupled_pose_plan(geometry: Geometry, n: int) -> DecoupledPlan | None:
    model = geometry.model
    for k in (n - 3, n - 1, n, n - 2):
        if k < 0:
            continue
        wrist_joints = tuple(range(k, n))
        if len(wrist_joints) == 2:  # one joint fewer than six: two axes meeting place the orientation
            point = geometry.common_point(wrist_joints)
            if n != 5 or point is None:
                continue
            wrist = TwoAxisWrist(geometry, wrist_joints)
        elif len(wrist_joints) == 3:
            point = geometry.common_point(wrist_joints)
            if point is None or geometry.parallel(k, k + 1) or geometry.parallel(k + 1, k + 2):
                continue  # consecutive coincident axes turn the tool about one line: not a 3-DOF wrist
            wrist = SphericalWrist(geometry, wrist_joints)
        elif len(wrist_joints) == 1:
            # a roll: the joints before it place a point of its axis (one joint before it: OneRevolute)
            if not model.is_revolute[k]:
                continue
            point, wrist = _roll_point(geometry, k), Roll(geometry, k)
        elif not wrist_joints:
            point, wrist = model.home[:3, 3], None
        else:
            continue
        positioner = find_positioner(geometry, tuple(range(k)), point) if k else None
        if k and positioner is None:
            continue
        if positioner is not None and positioner.free_joints and not isinstance(wrist, SphericalWrist):
            continue  # a joint the position leaves free turns the tool: only a spherical wrist takes that up
        return DecoupledPlan(positioner, wrist, point, model.home, n)
    return None


def _roll_point(geometry: Geometry, k: int) -> np.ndarray:
    """A point (3,) of the roll's axis k for the joints before it to place: the model's own point of the axis,
    unless it lies on or near an earlier revolute axis (within RECOGNITION_TOLERANCE of the arm's size: that joint
    would not move it, or hardly, and the position would leave the joint free, or ill-conditioned, where the
    orientation fixes it, which a roll cannot take up); then the first of the points a whole number of the arm's
    lengths along the axis that lies near none (k + 1 of them suffice)."""
    base, direction, scale = geometry.point(k), geometry.direction(k), geometry.length_scale
    earlier = [j for j in range(k) if geometry.model.is_revolute[j]]
    for step in range(k + 1):
        offset = (step + 1) // 2 * (1 if step % 2 else -1)  # 0, 1, −1, 2, −2, …
        point = base + offset * scale * direction
        if not any(geometry.axis_distance(j, point) <= RECOGNITION_TOLERANCE * scale for j in earlier):
            return point
    return base


def _position_plan(geometry: Geometry, n: int, reference: np.ndarray | None) -> Plan | None:
    model = geometry.model
    k = min(n, 3)
    free = {i: (0.0 if reference is None else float(reference[i])) for i in range(k, n)}
    q_free = np.array([free[i] for i in range(k, n)])
    tail = chain_motion(model.directions[k:], model.points[k:], model.is_revolute[k:], q_free) if free else np.eye(4)
    # the tool point with the free joints held, expressed at q = 0 of the first k joints
    point = apply(tail @ model.home, np.zeros(3))
    positioner = find_positioner(geometry, tuple(range(k)), point)
    if positioner is None:
        return None
    return DecoupledPlan(positioner, None, point, None, n, fixed=free)
