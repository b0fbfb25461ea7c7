"""Position + tool direction targets of 5-joint arms, as a 6-joint pose problem with a virtual joint.

The target asks that the tool origin reach ``p`` and the tool axis ``a`` (tool
frame) point along ``d`` (world frame), as IKFast's TranslationDirection5D:
five conditions for five joints. Any rotation ``R_t`` with ``R_t a = d`` makes
a pose target; the tool's roll about ``a`` is what the target leaves open.

* The general case: append a virtual revolute joint turning about ``a`` at the
  tool origin. That joint moves neither the origin nor ``a``, so the 6-joint
  arm reaches ``(p, R_t)`` exactly when the real arm reaches ``(p, d)``, and its
  solutions, without the virtual value, are every solution of the direction
  target. The 6-joint pose problem goes to the ordinary plan dispatch
  (:func:`~._plan.plan_for_geometry`), which solves it completely.
* When ``a`` lies along the last joint's axis (the roll of a desktop arm's
  gripper: the usual case), that joint already turns the tool about ``a``: it
  is free, held at the reference (or 0), and the arm's own pose problem at
  ``R_t`` is solved instead, by the same device with the virtual joint about
  an axis perpendicular to ``a``. A pose of the 5-joint arm is reached by the
  6-joint arm with the virtual joint at 0, and those are the solutions kept.

Every solution is checked by the real arm's FK (:func:`~._verify.verify` with a
:class:`~._goals.DirectionGoal`): position within ``ACCEPT_RESIDUAL`` times its
size, direction within ``ACCEPT_RESIDUAL`` rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._cache import bounded_memo
from .._errors import InvalidInputError
from .._robot import Robot
from .._rotations import wrap_angle
from .._tolerances import GEOMETRY_TOLERANCE
from ._goals import DirectionGoal
from ._plan import Plan, geometry_of, plan_for_geometry
from ._structure import Geometry
from ._types import Candidates, SingularFlags, Singularity

#: The virtual joint's value (rad) within which a 6-joint solution is one of the 5-joint arm (the roll case).
VIRTUAL_AT_ZERO = 1e-6
#: Direction plans kept per robot (one per tool axis a request names).
_PLANS_KEPT = 16


def target_kinds(robot: Robot) -> list[str]:
    """The IK target kinds this arm takes (api.md): ``pose`` and ``position`` always, ``position_direction``
    for arms with 5 joints."""
    return ["pose", "position"] + (["position_direction"] if robot.dof == 5 else [])


@dataclass(frozen=True)
class DirectionPlan:
    """How one arm solves direction targets for one tool axis ``tool_axis`` (3,), tool frame."""

    plan: Plan
    tool_axis: np.ndarray
    roll_joint: int | None  # the real joint that turns about the tool axis (free), or None
    structure: str


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perpendicular(a: np.ndarray) -> np.ndarray:
    other = np.eye(3)[int(np.argmin(np.abs(a)))]
    return _unit(np.cross(a, other))


def _with_virtual_roll(geometry: Geometry, axis_world: np.ndarray) -> Geometry:
    """The arm plus a revolute joint about ``axis_world`` (3,) through the tool origin at q = 0."""
    model = geometry.model
    origin = model.home[:3, 3]
    virtual = type(model)(np.vstack([model.directions, axis_world]), np.vstack([model.points, origin]),
                          np.append(model.is_revolute, True), model.home)
    link_x = None if geometry.link_x is None else np.vstack([geometry.link_x, model.home[:3, 0]])
    return Geometry(virtual, geometry.length_scale, up=geometry.up, link_x=link_x)


def direction_plan(robot: Robot, tool_axis: np.ndarray) -> DirectionPlan | None:
    """The plan for direction targets with this tool axis, or None when no family covers the 6-joint problem.

    Raises :class:`InvalidInputError` for an arm without exactly 5 joints.
    """
    if robot.dof != 5:
        raise InvalidInputError(
            f"position + tool direction targets are solved for arms with 5 joints; this one has {robot.dof} "
            f"(give a full pose, or the position only)", location=("target", "orientation"))
    a = _unit(np.asarray(tool_axis, dtype=float))

    def build() -> DirectionPlan | None:
        geometry = geometry_of(robot)
        model = geometry.model
        R_home, origin = model.home[:3, :3], model.home[:3, 3]
        axis_world = R_home @ a
        last = robot.dof - 1
        along_last = (bool(model.is_revolute[last])
                      and np.linalg.norm(np.cross(model.directions[last], axis_world)) <= GEOMETRY_TOLERANCE * 10
                      and geometry.on_axis(last, origin))
        if not along_last:
            plan = plan_for_geometry(_with_virtual_roll(geometry, axis_world), constrain_orientation=True,
                                     reference=None)
            return None if plan is None else DirectionPlan(plan, a, None, f"virtual_roll+{plan.structure}")
        first = _perpendicular(a)
        for axis in (first, np.cross(a, first)):
            plan = plan_for_geometry(_with_virtual_roll(geometry, R_home @ axis), constrain_orientation=True,
                                     reference=None)
            if plan is not None:
                return DirectionPlan(plan, a, last, f"virtual_joint+{plan.structure}")
        return None

    return bounded_memo(robot, "direction_plan", tuple(np.round(a, 12).tolist()), build, _PLANS_KEPT)


def rotations_to(tool_axis: np.ndarray, world_directions: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) taking the unit vector ``tool_axis`` (3,) onto each of ``world_directions`` (N, 3):
    the shortest turn, or a half turn about an axis perpendicular to it when the two are opposite."""
    a = _unit(np.asarray(tool_axis, dtype=float))
    d = world_directions / np.linalg.norm(world_directions, axis=-1, keepdims=True)
    axis = np.cross(a, d)
    sine, cosine = np.linalg.norm(axis, axis=-1), d @ a
    opposite = sine < 1e-12
    axis = np.where(opposite[:, None], _perpendicular(a), axis / np.where(opposite, 1.0, sine)[:, None])
    angle = np.arctan2(sine, cosine)
    angle = np.where(opposite & (cosine < 0), np.pi, angle)
    K = np.zeros((len(d), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * K @ K


def direction_candidates(robot: Robot, plan: DirectionPlan, goal: DirectionGoal, reference: np.ndarray | None
                         ) -> Candidates:
    """Candidates (N, m, n) of the goal's N position + direction targets by the plan, with their labels and the
    arm's singular conditions (those of the virtual joint left out). When the last joint turns about the tool
    axis it is held at the reference value (or 0) in every candidate; :func:`tool_roll` then names it."""
    n = robot.dof
    targets = np.zeros((len(goal), 4, 4))
    targets[:, 3, 3] = 1.0
    targets[:, :3, 3] = goal.positions
    targets[:, :3, :3] = rotations_to(plan.tool_axis, goal.directions)
    extended = None if reference is None else np.append(reference, 0.0)
    candidates = plan.plan.solve(targets, extended)
    full = np.nan_to_num(candidates.joints)  # (N, m, n + 1)
    valid = candidates.valid.copy()
    if plan.roll_joint is not None:  # the arm's own pose problem: the virtual joint must stay at 0
        valid &= np.abs(wrap_angle(full[..., n])) <= VIRTUAL_AT_ZERO
    joints = full[..., :n].copy()
    if plan.roll_joint is not None:
        joints[..., plan.roll_joint] = 0.0 if reference is None else reference[plan.roll_joint]
    labels = candidates.labels if candidates.labels is not None else {
        name: (values, codes.reshape(valid.shape))
        for name, (values, codes) in plan.plan.label_codes(full.reshape(-1, n + 1)).items()}
    singular = SingularFlags(len(goal))
    for mask, flag in candidates.singularities.entries:  # conditions that involve the virtual joint are not the arm's
        if all(j < n for j in flag.joints):
            singular.add(mask, flag)
    return Candidates(joints, valid, singular, labels=labels)


def tool_roll(plan: DirectionPlan) -> Singularity | None:
    """The condition every direction answer of an arm whose last joint turns about the tool axis reports."""
    if plan.roll_joint is None:
        return None
    return Singularity("tool_roll", (plan.roll_joint,), "free",
                       f"q{plan.roll_joint + 1} turns the tool about the tool axis, which the target leaves free: "
                       f"held at the reference value (or 0)")
