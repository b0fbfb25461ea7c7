"""The kinematic model of a serial robot: joints, DH rows, base and tool.

All angles are radians and all lengths are in the robot's own length unit.
Unit conversion happens once, at the API boundary, before a :class:`Robot` is
built.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Sequence

import numpy as np

from ._cache import memo
from ._conventions import CONVENTIONS, Convention
from ._errors import InvalidInputError

JointKind = Literal["revolute", "prismatic"]
JOINT_KINDS: tuple[JointKind, ...] = ("revolute", "prismatic")


@dataclass(frozen=True)
class Joint:
    """One joint and its link row.

    ``a``, ``alpha``, ``d`` and ``theta`` follow the robot's convention (for
    Khalil–Kleinfinger they hold the renamed Craig row, see
    :mod:`._conventions`). The table value of the joint's variable parameter
    (``theta`` for a revolute joint, ``d`` for a prismatic one) is an offset:
    the joint variable q is added to it.

    ``lower`` and ``upper`` bound q itself, in radians or length units;
    infinite bounds mean no limit.
    """

    name: str
    kind: JointKind
    a: float
    alpha: float
    d: float
    theta: float
    lower: float = -math.inf
    upper: float = math.inf

    @property
    def is_revolute(self) -> bool:
        return self.kind == "revolute"


class Robot:
    """A serial chain of joints with fixed ``world_T_base`` and ``flange_T_tool``.

    The pose of the tool is
    ``world_T_tool(q) = world_T_base · T_1(q_1) ⋯ T_n(q_n) · flange_T_tool``,
    with each ``T_i`` the link transform of the robot's convention.

    Parameters
    ----------
    joints : sequence of Joint
        At least one joint.
    convention : {"standard", "modified", "khalil"}
    world_T_base, flange_T_tool : array_like, shape (4, 4), optional
        Fixed transforms; identity when omitted. Validated as rigid transforms.
    name : str, optional
        For messages only.

    Raises
    ------
    InvalidInputError
        With the location of the offending joint or field.
    """

    def __init__(
        self,
        joints: Sequence[Joint],
        *,
        convention: Convention = "standard",
        world_T_base: np.ndarray | None = None,
        flange_T_tool: np.ndarray | None = None,
        name: str = "",
    ) -> None:
        if convention not in CONVENTIONS:
            raise InvalidInputError(
                f"unknown convention {convention!r}; expected one of {', '.join(CONVENTIONS)}",
                location=("convention",),
            )
        joints = tuple(joints)
        if not joints:
            raise InvalidInputError("a robot needs at least one joint", location=("joints",))
        for index, joint in enumerate(joints):
            _check_joint(joint, index)
        self.name = name
        self.convention: Convention = convention
        self.joints: tuple[Joint, ...] = joints
        self.world_T_base = _checked_transform(world_T_base, "base")
        self.flange_T_tool = _checked_transform(flange_T_tool, "tool")

        self.a = np.array([j.a for j in joints], dtype=float)
        self.alpha = np.array([j.alpha for j in joints], dtype=float)
        self.d = np.array([j.d for j in joints], dtype=float)
        self.theta = np.array([j.theta for j in joints], dtype=float)
        self.is_revolute = np.array([j.is_revolute for j in joints], dtype=bool)
        self.lower = np.array([j.lower for j in joints], dtype=float)
        self.upper = np.array([j.upper for j in joints], dtype=float)
        for array in (self.a, self.alpha, self.d, self.theta, self.is_revolute, self.lower, self.upper):
            array.setflags(write=False)

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    @property
    def characteristic_length(self) -> float:
        """A length that sets the scale of this robot, for relative tolerances.

        The sum of the constant link lengths and offsets, plus the tool
        offset; 1 for a robot with no lengths at all (a pure wrist). Computed once: the robot does not change.
        """
        return memo(self, "characteristic_length", self._characteristic_length)

    def _characteristic_length(self) -> float:
        total = float(np.sum(np.abs(self.a)) + np.sum(np.abs(self.d)))
        total += float(np.linalg.norm(self.flange_T_tool[:3, 3]))
        return total if total > 0.0 else 1.0

    def __repr__(self) -> str:
        kinds = "".join("R" if r else "P" for r in self.is_revolute)
        return f"Robot({self.name or 'unnamed'!r}, {self.convention}, {kinds})"


def _check_joint(joint: Joint, index: int) -> None:
    where = ("joints", index)
    if joint.kind not in JOINT_KINDS:
        raise InvalidInputError(
            f"joint type must be one of {', '.join(JOINT_KINDS)}, not {joint.kind!r}", location=(*where, "type")
        )
    for field in ("a", "alpha", "d", "theta"):
        value = getattr(joint, field)
        if not math.isfinite(value):
            raise InvalidInputError(f"{field} must be a finite number, not {value}", location=(*where, field))
    if math.isnan(joint.lower) or math.isnan(joint.upper):
        raise InvalidInputError("joint limits must be numbers, not NaN", location=(*where, "limits"))
    if joint.lower > joint.upper:
        raise InvalidInputError(
            f"lower limit {joint.lower:g} is greater than upper limit {joint.upper:g}", location=(*where, "limits")
        )


def _checked_transform(T: np.ndarray | None, field: str) -> np.ndarray:
    if T is None:
        return np.eye(4)
    from ._rotations import check_transform

    try:
        checked = check_transform(T)
    except InvalidInputError as error:
        raise error.relocated(field) from None
    checked = checked.copy()
    checked.setflags(write=False)
    return checked


def check_joint_values(robot: Robot, q: np.ndarray | Sequence[float], *, batch: bool = False) -> np.ndarray:
    """Validate joint values for ``robot``.

    Parameters
    ----------
    q : array_like, shape (n,), or (N, n) when ``batch`` is true
        Radians for revolute joints, length units for prismatic ones.

    Returns
    -------
    ndarray of float64 with the same shape.

    Raises
    ------
    InvalidInputError
        Wrong shape or a non-finite value; the location is the joint index
        (and the row index for a batch).
    """
    if batch and not isinstance(q, np.ndarray):
        for row_index, row in enumerate(q):
            if len(row) != robot.dof:
                raise InvalidInputError(
                    f"expected {robot.dof} joint values in every row, row {row_index} has {len(row)}",
                    location=(row_index,),
                )
    try:
        values = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError("joint values must be numbers") from None
    expected_ndim = 2 if batch else 1
    if values.ndim != expected_ndim or values.shape[-1] != robot.dof:
        shape = f"(N, {robot.dof})" if batch else f"({robot.dof},)"
        raise InvalidInputError(
            f"expected joint values of shape {shape} for a robot with {robot.dof} joints, got shape {values.shape}"
        )
    bad = ~np.isfinite(values)
    if bad.any():
        location = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InvalidInputError(f"joint value must be finite, not {values[location]}", location=location)
    return values
