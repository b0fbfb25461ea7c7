"""Translation between wire models and the core, with units converted once, here.

Inbound: robot descriptions become core robots in :mod:`service.robots.build`; joint values become radians, targets become
4×4 ``world_T_tool`` matrices. Outbound: matrices become :class:`Pose` dicts
and radians go back to the request's unit. Errors raised by the core carry
locations relative to the value passed in; they are prefixed here with the
request path so that the problem document points at the field.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..kinematics import (
    InvalidInputError,
    Limits,
    Violation,
    KinematicsError,
    LimitOrderError,
    Robot,
    check_joint_values,
    check_transform,
    check_transforms,
    frame_quaternion,
    frame_quaternions,
    matrix_from_quaternion,
    quaternions_from_matrices,
)
from ..kinematics.ik import (DIRECTION, POSE, POSITION, IKTargets, NotRedundantError, Ordering, check_ordering,
                             roll_samples)
from ..kinematics.collision import CollisionRequest, Obstacle, clearances, frame_index
from ..robots.build import bounds as _bounds
from ..robots.geometry import shape_from_wire
from ..robots.orientations import rotation_from_orientation
from ..units import radians_per
from .schemas.collisions import CollisionOptions
from .schemas.common import AngleUnit
from .schemas.ik import MatrixRows, Ordering as OrderingOptions
from .schemas.poses import DirectionOrientation, PoseTarget


class located:
    """Prefix the location of any core error raised inside the block, worded for the wire where the core's words
    differ (:func:`wire_worded`). A context manager (``with located("body", "limits"):``) written as a class, as
    :class:`contextlib.suppress` is: a request enters half a dozen, and a generator's set-up costs three times
    as much."""

    __slots__ = ("prefix",)

    def __init__(self, *prefix: str | int) -> None:
        self.prefix = prefix

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind: type | None, error: BaseException | None, traceback: object) -> bool:
        if isinstance(error, KinematicsError):
            raise wire_worded(error).relocated(*self.prefix) from None
        return False


def wire_worded(error: KinematicsError) -> KinematicsError:
    """A core error as the wire words it: the core speaks of free joints, the request of ``free_joints``."""
    if isinstance(error, NotRedundantError):
        worded = error.relocated()
        worded.message = f"free_joints applies to arms with more than 6 joints; this one has {error.dof}"
        worded.args = (worded.message,)
        return worded
    return error


def _unit_scale(robot: Robot, unit: AngleUnit) -> np.ndarray:
    """Per-joint factor from the request's unit to the core's (radians, lengths)."""
    return np.where(robot.is_revolute, radians_per(unit), 1.0)


def joints_to_core(robot: Robot, values: Sequence[float] | Sequence[Sequence[float]], unit: AngleUnit,
                   *, batch: bool = False) -> np.ndarray:
    """Joint values from the request's unit to radians, validated for ``robot``."""
    q = check_joint_values(robot, values, batch=batch)
    return q * _unit_scale(robot, unit)


def joints_from_core(robot: Robot, q: np.ndarray, unit: AngleUnit) -> np.ndarray:
    """Joint values from radians to the request's unit."""
    return np.asarray(q, dtype=float) / _unit_scale(robot, unit)


#: How closely the position and quaternion that accompany a target's matrix must agree with it (an FK pose
#: sent back as it stands agrees to rounding; a hand-edited one that disagrees is refused, not half-used).
POSE_AGREEMENT_TOLERANCE = 1e-6


def target_matrix(target: PoseTarget, unit: AngleUnit) -> tuple[np.ndarray, bool]:
    """The 4×4 ``world_T_tool`` a target asks for, and whether it constrains orientation.

    A position-only target returns the identity rotation and ``False``. A matrix that comes with ``position``
    and ``quaternion_wxyz`` (a forward-kinematics pose sent back as it stands) must agree with them. A position +
    direction target is not a pose: it is read by :func:`target_direction`, and refused here.
    """
    if isinstance(target.orientation, DirectionOrientation):
        raise InvalidInputError("a position + tool direction target is accepted by the IK endpoints only",
                                location=("orientation",))
    if target.matrix is not None:
        with located("matrix"):
            T = check_transform(np.asarray(target.matrix, dtype=float))
        _check_pose_agrees(T, target.position, target.quaternion_wxyz)
        return T, True
    T = np.eye(4)
    T[:3, 3] = target.position
    orientation = target.orientation
    if orientation is None and target.quaternion_wxyz is not None:
        with located("quaternion_wxyz"):
            T[:3, :3] = matrix_from_quaternion(target.quaternion_wxyz)  # checked there
        return T, True
    if orientation is None:
        return T, False
    with located("orientation"):
        T[:3, :3] = rotation_from_orientation(orientation, radians_per(unit))
    return T, True


def _check_pose_agrees(T: np.ndarray, position: Sequence[float] | None, wxyz: Sequence[float] | None) -> None:
    """Refuse a position or quaternion that disagrees with the target's matrix ``T``, shape (4, 4)."""
    if position is not None:
        gap = float(np.max(np.abs(np.asarray(position) - T[:3, 3])))
        scale = max(1.0, float(np.max(np.abs(T[:3, 3]))))
        if gap > POSE_AGREEMENT_TOLERANCE * scale:
            raise InvalidInputError(f"position {list(position)} disagrees with the matrix's last column "
                                    f"{T[:3, 3].tolist()} (by {gap:.3g}); send one of them, or both equal",
                                    location=("position",))
    if wxyz is not None:
        q = np.asarray(wxyz, dtype=float)
        expected = quaternions_from_matrices(T[None, :3, :3])[0]
        gap = float(min(np.max(np.abs(q - expected)), np.max(np.abs(q + expected))))  # q and -q are one turn
        if gap > POSE_AGREEMENT_TOLERANCE:
            raise InvalidInputError(f"quaternion_wxyz {list(wxyz)} disagrees with the matrix's rotation, whose "
                                    f"quaternion (w, x, y, z) is {np.round(expected, 9).tolist()}; send one of "
                                    f"them, or both equal", location=("quaternion_wxyz",))
def target_direction(target: PoseTarget, unit: AngleUnit
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None] | None:
    """(position, tool axis, world direction), each (3,), and the rolls to solve at (radians (S,), None for the
    default samples) of a position + direction target, or None for another kind. Zero vectors are refused."""
    orientation = target.orientation
    if not isinstance(orientation, DirectionOrientation):
        return None
    vectors = []
    for name in ("tool_axis", "world_direction"):
        vector = np.asarray(getattr(orientation, name), dtype=float)
        if not np.linalg.norm(vector) > 1e-9:
            raise InvalidInputError(f"{name} must be a non-zero vector", location=("orientation", name))
        vectors.append(vector / np.linalg.norm(vector))
    rolls = None
    if orientation.roll_values is not None:
        rolls = np.asarray(orientation.roll_values, dtype=float) * radians_per(unit)
    elif orientation.roll_samples is not None:
        rolls = roll_samples(orientation.roll_samples)
    return np.asarray(target.position, dtype=float), vectors[0], vectors[1], rolls


def target_matrices(targets: Sequence[PoseTarget], unit: AngleUnit, *prefix: str | int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`target_matrix` for many targets: (N, 4, 4) matrices and which constrain orientation (N,).

    Matrix targets are stacked and checked in one vectorised pass; on any
    error, and for other target forms, each target is converted on its own so
    that the problem names the offending target exactly as before.
    """
    if all(target.matrix is not None for target in targets):
        stacked = np.array([target.matrix for target in targets], dtype=float)
        try:
            matrices = check_transforms(stacked)
            for index, target in enumerate(targets):  # FK poses sent back as they stand
                if target.position is not None or target.quaternion_wxyz is not None:
                    with located(*prefix, index):
                        _check_pose_agrees(matrices[index], target.position, target.quaternion_wxyz)
            return matrices, np.ones(len(targets), dtype=bool)
        except KinematicsError:
            pass  # the per-target pass below reports it with its full location
    matrices = np.empty((len(targets), 4, 4))
    constrained = np.empty(len(targets), dtype=bool)
    for index, target in enumerate(targets):
        with located(*prefix, index):
            matrices[index], constrained[index] = target_matrix(target, unit)
    return matrices, constrained


def _matrices_of_rows(rows: Sequence[Sequence[float]], *prefix: str | int) -> np.ndarray:
    """(N, 4, 4) rigid transforms from rows of 16 numbers (row-major), checked in one pass; on an error each row is
    checked on its own, so that the problem names the row."""
    stacked = np.asarray(rows, dtype=float).reshape(-1, 4, 4)
    try:
        return check_transforms(stacked)
    except KinematicsError:
        for index, matrix in enumerate(stacked):
            with located(*prefix, index):
                check_transform(matrix)
        raise


def ik_targets_to_core(targets: Sequence[PoseTarget] | MatrixRows, unit: AngleUnit, *prefix: str | int,
                       indexed: bool = True) -> IKTargets:
    """The core's :class:`IKTargets` from an IK request's targets (target objects, or a batch's flat matrix rows);
    errors are located at ``prefix`` (followed by the target's index when ``indexed``). A direction target's
    matrix holds its position."""
    if isinstance(targets, MatrixRows):
        return IKTargets.poses(_matrices_of_rows(targets.matrices, *prefix, "matrices"))
    def at(index: int):
        return located(*prefix, index) if indexed else located(*prefix)
    if len(targets) == 1 and not isinstance(targets[0].orientation, DirectionOrientation):  # a single IK's pose
        with at(0):
            matrix, constrained = target_matrix(targets[0], unit)
        return IKTargets(matrix[None], np.array([POSE if constrained else POSITION]), indexed=indexed)
    directions = {}
    for index, target in enumerate(targets):
        with at(index):
            direction = target_direction(target, unit)
        if direction is not None:
            directions[index] = direction
    if not directions and indexed:
        matrices, constrained = target_matrices(targets, unit, *prefix)
        return IKTargets(matrices, np.where(constrained, POSE, POSITION))
    matrices, kinds = np.tile(np.eye(4), (len(targets), 1, 1)), np.full(len(targets), DIRECTION)
    tool_axes, world_directions = np.zeros((len(targets), 3)), np.zeros((len(targets), 3))
    rolls: list[np.ndarray | None] = [None] * len(targets)
    for index, target in enumerate(targets):
        if index in directions:
            matrices[index, :3, 3], tool_axes[index], world_directions[index], rolls[index] = directions[index]
            continue
        with at(index):
            matrices[index], constrained = target_matrix(target, unit)
        kinds[index] = POSE if constrained else POSITION
    return IKTargets(matrices, kinds, tool_axes, world_directions, rolls, indexed)


def free_joints_to_core(robot: Robot, choices: Sequence | None, unit: AngleUnit
                        ) -> list[tuple[int, list[float] | None, int | None]] | None:
    """An IK request's free-joint choices as the core's ``(joint, values, samples)`` entries, values in radians /
    length units (a joint index out of range is left for the core to refuse)."""
    if choices is None:
        return None
    requested = []
    for choice in choices:
        values = choice.values
        if values is not None and 0 <= choice.joint < robot.dof:
            values = (np.asarray(values, dtype=float) * _unit_scale(robot, unit)[choice.joint]).tolist()
        requested.append((choice.joint, values, choice.samples))
    return requested


def poses_from_matrices(matrices: np.ndarray) -> list[dict]:
    """Wire poses for a stack of transforms the core computed (FK), shape (N, 4, 4)."""
    matrices = np.asarray(matrices, dtype=float)
    quaternions = frame_quaternions(matrices[:, :3, :3]).tolist()
    return [_wire_pose(T, quaternion) for T, quaternion in zip(matrices.tolist(), quaternions)]


def pose_from_matrix(matrix: np.ndarray) -> dict:
    """The wire pose of one transform the core computed, shape (4, 4): :func:`poses_from_matrices` of one, on
    floats (a single FK's whole encoding)."""
    rows = np.asarray(matrix, dtype=float).tolist()
    (r00, r01, r02, _), (r10, r11, r12, _), (r20, r21, r22, _), _ = rows
    return _wire_pose(rows, frame_quaternion([r00, r01, r02, r10, r11, r12, r20, r21, r22]))


def _wire_pose(rows: list[list[float]], quaternion: list[float]) -> dict:
    """The wire pose of a transform given as its rows (4 lists of 4) and its rotation's quaternion."""
    return {"matrix": rows, "position": [rows[0][3], rows[1][3], rows[2][3]], "quaternion_wxyz": quaternion}


def limits_to_core(robot: Robot, overrides: Sequence | None, unit: AngleUnit) -> Limits:
    """The limits a request works with: the robot's, or the request's overrides converted to radians.

    Errors are located at the joint index and name the joint; bounds are quoted in the request's units.
    """
    if overrides is None:
        return Limits.of(robot)
    if len(overrides) != robot.dof:
        raise InvalidInputError(f"expected limits for {robot.dof} joints, one entry (or null) per joint, "
                                f"got {len(overrides)}")
    scale = _unit_scale(robot, unit)
    bounds = [_bounds(o, factor) for o, factor in zip(overrides, scale)]
    try:
        return Limits.checked(robot, [b[0] for b in bounds], [b[1] for b in bounds])
    except LimitOrderError as error:  # the core checks the order; quote its bounds in the request's unit
        index = error.location[0]
        raise InvalidInputError(f"joint {index} ({robot.joint_names[index]}): lower limit "
                                f"{error.lower / scale[index]:g} is greater than upper limit "
                                f"{error.upper / scale[index]:g}", location=error.location) from None


def ordering_to_core(robot: Robot, ordering: OrderingOptions, max_solutions: int | None,
                     max_joint_move: float | Sequence[float | None] | None, reference: np.ndarray | None,
                     unit: AngleUnit) -> Ordering:
    """The core's :class:`Ordering` from an IK request's options, validated.

    ``max_joint_move`` is in the request's units: one number bounds every joint in its own unit (angle unit for
    revolute joints, length unit for prismatic ones); a list bounds each joint, null meaning unbounded. Weights
    multiply moves in radians / length units and need no conversion. Error locations are relative to the request
    body: ``ordering.weights``, ``max_solutions``, ``max_joint_move``.
    """
    if reference is None and ordering.model_fields_set:
        name = sorted(ordering.model_fields_set)[0]
        raise InvalidInputError(f"ordering.{name} needs a reference: distances are measured from it",
                                location=("ordering", name))
    move = None
    if max_joint_move is not None:
        if isinstance(max_joint_move, (int, float)):
            move = np.full(robot.dof, float(max_joint_move))
        elif len(max_joint_move) != robot.dof:
            raise InvalidInputError(f"expected {robot.dof} values of max_joint_move, one per joint (or one number "
                                    f"for every joint), got {len(max_joint_move)}", location=("max_joint_move",))
        else:
            move = np.array([math.inf if v is None else v for v in max_joint_move], dtype=float)
        move = move * _unit_scale(robot, unit)
    weights = None if ordering.weights is None else np.array(ordering.weights, dtype=float)
    core = Ordering(ordering.norm, weights, max_solutions, move)
    try:
        check_ordering(robot, core, reference)
    except KinematicsError as error:
        nested = error.location[:1] in (("weights",), ("norm",))
        raise error.relocated(*(("ordering",) if nested else ())) from None
    return core


def ik_selection_to_core(robot: Robot, body) -> tuple[np.ndarray | None, Limits, Ordering]:
    """An IK request's reference, limits and ordering in core units, errors located in the body."""
    reference = None
    if body.reference is not None:
        with located("body", "reference"):
            reference = joints_to_core(robot, body.reference, body.angle_unit)
    with located("body", "limits"):
        limits = limits_to_core(robot, body.limits, body.angle_unit)
    with located("body"):
        ordering = ordering_to_core(robot, body.ordering, body.max_solutions, body.max_joint_move, reference,
                                    body.angle_unit)
    return reference, limits, ordering


#: The selection's notes as the wire words them, naming the request's options (the core's
#: :data:`~service.kinematics.ik.NOTE_WORDING`, same keys and fields).
WIRE_NOTES = {
    "no_fit": "All {rejected} solutions violate a joint limit, whatever whole turns the revolute joints make; they "
              "are listed in 'rejected'.",
    "flagged": "{outside} of the solutions violate a joint limit (filter_limits is false); each is flagged with its "
               "violations.",
    "capped": "{fit} solutions fit; max_equivalents = {cap} kept the {which} {kept}.",
    "none_near": "{fit} solutions fit the limits, but none is within max_joint_move / max_solutions of the "
                 "reference.",
    "lowered": "At most {limit} are listed for a {dof}-joint arm whatever max_equivalents asks: ranking more of so "
               "many equivalents would take more work than one answer may.",
    "collide": "{collided} solutions collide (a pair closer than collisions.margin); they are listed in 'rejected' "
               "with their collisions.",
}


def violations_to_wire(limits: Limits, scale: np.ndarray, outside: np.ndarray, q: np.ndarray
                       ) -> dict[int, list[dict]]:
    """The violations of S joint vectors q (S, n, the core's units), keyed by row (rows without one are absent):
    each joint that ``outside`` (S, n) marks, with its value and the bounds it breaks in the request's unit
    (``scale`` (n,): its factor to the core's, :func:`_unit_scale`), an open side null. What
    :func:`violation_to_wire` gives each, with the bounds converted once and only the violating values divided."""
    violations: dict[int, list[dict]] = {}
    rows, columns = np.nonzero(outside)
    if not len(rows):
        return violations
    lower, upper = ([None if math.isinf(bound) else bound for bound in (side / scale).tolist()]
                    for side in (limits.lower, limits.upper))
    values = (q[rows, columns] / scale[columns]).tolist()
    for k, j, value in zip(rows.tolist(), columns.tolist(), values):
        violations.setdefault(k, []).append({"joint": j, "value": value, "lower": lower[j], "upper": upper[j]})
    return violations


def violation_to_wire(robot: Robot, violation: Violation, unit: AngleUnit) -> dict:
    """A violation in the request's units; an open side of the range is null."""
    scale = float(_unit_scale(robot, unit)[violation.joint])
    lower = None if math.isinf(violation.lower) else violation.lower / scale
    upper = None if math.isinf(violation.upper) else violation.upper / scale
    return {"joint": violation.joint, "value": violation.value / scale, "lower": lower, "upper": upper}


def collisions_to_core(robot: Robot, options: CollisionOptions | None, unit: AngleUnit) -> CollisionRequest | None:
    """A request's ``collisions`` in core terms: obstacles as shapes (lengths in the robot's unit, a box's
    orientation angles in the request's angle unit), ignored pairs as frame indices; None without it. Errors are
    located at ``("body", "collisions", …)``."""
    if options is None:
        return None
    radians_per_unit = radians_per(unit)
    obstacles = []
    for index, entry in enumerate(options.obstacles):
        with located("body", "collisions", "obstacles", index):
            obstacles.append(Obstacle(entry.name, shape_from_wire(entry, radians_per_unit)))
    ignore = []
    for index, pair in enumerate(options.ignore):
        frames = []
        for side, link in enumerate(pair):
            with located("body", "collisions", "ignore", index, side):
                frames.append(frame_index(robot, link))
        ignore.append(tuple(frames))
    return CollisionRequest(tuple(obstacles), options.self_collision, float(options.margin), options.filter,
                            tuple(ignore))


def clearance_to_wire(robot: Robot, request: CollisionRequest, q: np.ndarray) -> dict:
    """One joint vector's collision check as the wire gives it: ``clearance`` (null when nothing is checked) and
    ``collisions``."""
    with located("body", "collisions"):
        checked = clearances(robot, request, q[None])
    clearance = float(checked.clearance[0])
    return {"clearance": None if math.isinf(clearance) else clearance,
            "collisions": [{"a": a, "b": b, "distance": distance} for a, b, distance in checked.contacts[0]]}
