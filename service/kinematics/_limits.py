"""Joint limits: checks with reasons, and every 2π-equivalent that fits.

Bounds are inclusive, with a small tolerance (:data:`LIMIT_TOLERANCE` radians
for revolute joints, the same fraction of the robot's characteristic length
for prismatic ones) so that a value computed to be exactly on a limit is not
rejected by rounding. A revolute joint with infinite bounds is continuous.
Prismatic joints are never wrapped.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ._errors import InvalidInputError
from ._robot import Robot

#: Inclusive-bound tolerance: radians for revolute joints; times the robot's
#: characteristic length for prismatic joints.
LIMIT_TOLERANCE = 1e-9

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Limits:
    """Lower and upper bounds for every joint, shape (n,) each; ±inf where unlimited."""

    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def of(cls, robot: Robot) -> "Limits":
        return cls(robot.lower.copy(), robot.upper.copy())

    @classmethod
    def checked(cls, robot: Robot, lower: np.ndarray, upper: np.ndarray) -> "Limits":
        """Validate overriding limits: one pair per joint, no NaN, lower ≤ upper; location is the joint index."""
        lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        if lower.shape != (robot.dof,) or upper.shape != (robot.dof,):
            raise InvalidInputError(f"expected limits for {robot.dof} joints, got {lower.shape[0]}")
        for index in range(robot.dof):
            if np.isnan(lower[index]) or np.isnan(upper[index]):
                raise InvalidInputError("limits must be numbers, not NaN", location=(index,))
            if lower[index] > upper[index]:
                raise InvalidInputError(
                    f"lower limit {lower[index]:g} is greater than upper limit {upper[index]:g}", location=(index,))
        return cls(lower, upper)

    def tolerance(self, robot: Robot) -> np.ndarray:
        return np.where(robot.is_revolute, LIMIT_TOLERANCE, LIMIT_TOLERANCE * robot.characteristic_length)


@dataclass(frozen=True)
class Violation:
    joint: int
    value: float
    lower: float
    upper: float


def violations(robot: Robot, limits: Limits, q: np.ndarray) -> list[Violation]:
    """Every joint of q (shape (n,)) outside its bounds, with the bounds it breaks."""
    tolerance = limits.tolerance(robot)
    outside = (q < limits.lower - tolerance) | (q > limits.upper + tolerance)
    return [Violation(int(i), float(q[i]), float(limits.lower[i]), float(limits.upper[i]))
            for i in np.flatnonzero(outside)]


def within(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray:
    """Whether each row of q (shape (..., n)) is inside every bound."""
    tolerance = limits.tolerance(robot)
    return np.all((q >= limits.lower - tolerance) & (q <= limits.upper + tolerance), axis=-1)


def turn_offsets(robot: Robot, limits: Limits, q: np.ndarray) -> list[np.ndarray]:
    """For each joint, the values q_i + 2kπ that fit its bounds (revolute joints with finite bounds).

    A prismatic joint keeps its own value only, if it is within its bounds
    (an empty array otherwise): there is nothing to expand into. A revolute
    joint bounded on one side only keeps its value if it fits, or else takes
    the first equivalent past that bound; a continuous one keeps its value.
    """
    tolerance = limits.tolerance(robot)
    options = []
    for i in range(robot.dof):
        lower, upper = limits.lower[i] - tolerance[i], limits.upper[i] + tolerance[i]
        if not robot.is_revolute[i]:
            options.append(np.array([q[i]]) if lower <= q[i] <= upper else np.array([]))
            continue
        if not (np.isfinite(lower) and np.isfinite(upper)):
            value = q[i]
            if value < lower:
                value += _TWO_PI * np.ceil((lower - value) / _TWO_PI)
            elif value > upper:
                value -= _TWO_PI * np.ceil((value - upper) / _TWO_PI)
            options.append(np.array([value]))
            continue
        first = np.ceil((lower - q[i]) / _TWO_PI)
        last = np.floor((upper - q[i]) / _TWO_PI)
        turns = np.arange(first, last + 1) if last >= first else np.array([])
        options.append(q[i] + _TWO_PI * turns)
    return options


def fitting_equivalents(robot: Robot, limits: Limits, q: np.ndarray, cap: int) -> tuple[np.ndarray, bool]:
    """Every 2π-equivalent of q (shape (n,)) that is inside the limits, at most ``cap`` of them.

    Returns
    -------
    equivalents : ndarray, shape (m, n)
        Empty when no equivalent fits.
    truncated : bool
        True when more than ``cap`` equivalents fit and the list was cut.

    Examples
    --------
    A joint limited to ±270° has two equivalents of 100°: 100° and −260°.
    """
    options = turn_offsets(robot, limits, q)
    total = int(np.prod([len(o) for o in options]))
    if total == 0:
        return np.zeros((0, robot.dof)), False
    combos = itertools.islice(itertools.product(*options), cap)
    return np.array(list(combos), dtype=float), total > cap


def nearest_fitting_equivalent(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray | None:
    """The 2π-equivalent of q (shape (n,)) that fits the limits and moves each joint least; None if none fits."""
    options = turn_offsets(robot, limits, q)
    if any(len(o) == 0 for o in options):
        return None
    nearest = np.array([o[np.argmin(np.abs(o - value))] for o, value in zip(options, q)])
    return nearest if within(robot, limits, nearest) else None
