"""Joint limits: checks with reasons, and every 2π-equivalent that fits.

Bounds are inclusive, with a small tolerance (:data:`LIMIT_TOLERANCE` radians
for revolute joints, the same fraction of the robot's characteristic length
for prismatic ones) so that a value computed to be exactly on a limit is not
rejected by rounding.

How each kind of joint is treated:

* **prismatic**: never wrapped; its value is the value.
* **revolute, both bounds finite**: its 2π-equivalents θ + 2kπ are different
  physical positions. Every one inside the bounds is a solution of its own
  (a ±360° joint has two of most angles, a ±160° joint at most one).
* **revolute, no bounds** (continuous): an angle modulo 2π. It is never
  expanded; distances to it are measured across the 2π wrap.
* **revolute, bounded on one side only**: infinitely many equivalents fit, so
  only the one nearest the given value is used (it is never expanded either).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ._cache import bounded_memo
from ._errors import InvalidInputError
from ._robot import Robot, check_limit_pair
from ._tolerances import LIMIT_TOLERANCE

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Limits:
    """Lower and upper bounds for every joint, shape (n,) each; ±inf where unlimited.

    Radians for revolute joints, the robot's length unit for prismatic ones.
    """

    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def of(cls, robot: Robot) -> "Limits":
        """The robot's own limits."""
        return cls(robot.lower.copy(), robot.upper.copy())

    @classmethod
    def checked(cls, robot: Robot, lower: Sequence[float], upper: Sequence[float]) -> "Limits":
        """Validate overriding limits: one pair per joint, no NaN, lower ≤ upper.

        ±inf is an open side. Raises :class:`InvalidInputError` whose location
        is the joint index and whose message names the joint.
        """
        lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        if lower.shape != (robot.dof,) or upper.shape != (robot.dof,):
            raise InvalidInputError(f"expected limits for {robot.dof} joints, got {lower.size} and {upper.size}")
        for index, name in enumerate(robot.joint_names):
            check_limit_pair(lower[index], upper[index], location=(index,), joint=f"joint {index} ({name}): ")
        return cls(lower, upper)

    def tolerance(self, robot: Robot) -> np.ndarray:
        """Per-joint tolerance on the bounds, shape (n,): radians or length units."""
        return np.where(robot.is_revolute, LIMIT_TOLERANCE, LIMIT_TOLERANCE * robot.characteristic_length)

    def continuous(self, robot: Robot) -> np.ndarray:
        """Which joints are revolute with no bounds at all, shape (n,) bool."""
        return robot.is_revolute & np.isneginf(self.lower) & np.isposinf(self.upper)

    def multi_valued(self, robot: Robot) -> np.ndarray:
        """Which joints are revolute with both bounds finite: those expanded into their 2π-equivalents."""
        return robot.is_revolute & np.isfinite(self.lower) & np.isfinite(self.upper)

    def widened(self, robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The bounds with their tolerance, ``lower − tolerance`` and ``upper + tolerance``, and
        :meth:`multi_valued`: shape (n,) each, read-only. Kept on the robot for the last
        :data:`_WIDENED_KEPT` limits asked by value (every answer applies its limits, mostly the same few)."""
        def build() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            tolerance = self.tolerance(robot)
            arrays = (self.lower - tolerance, self.upper + tolerance, self.multi_valued(robot))
            for array in arrays:
                array.flags.writeable = False
            return arrays
        key = (self.lower.dtype.str, self.lower.tobytes(), self.upper.dtype.str, self.upper.tobytes())
        return bounded_memo(robot, "widened_limits", key, build, _WIDENED_KEPT)


#: How many limits :meth:`Limits.widened` keeps per robot.
_WIDENED_KEPT = 8


@dataclass(frozen=True)
class Violation:
    """One joint outside its bounds: index, value and the bounds (core units)."""

    joint: int
    value: float
    lower: float
    upper: float


def within(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray:
    """Whether each row of q (shape (..., n)) is inside every bound, tolerance included."""
    lower, upper, _ = limits.widened(robot)
    return np.all((q >= lower) & (q <= upper), axis=-1)


def violations(robot: Robot, limits: Limits, q: np.ndarray) -> list[Violation]:
    """Every joint of q (shape (n,)) outside its bounds, with the bounds it breaks.

    Examples
    --------
    A PUMA 560 wrist (q5 in [−100°, 100°]) at 120° gives one violation,
    ``Violation(4, 2.094…, −1.745…, 1.745…)``.
    """
    lower, upper, _ = limits.widened(robot)
    outside = (q < lower) | (q > upper)
    return [Violation(int(i), float(q[i]), float(limits.lower[i]), float(limits.upper[i]))
            for i in np.flatnonzero(outside)]


def turn_ranges(robot: Robot, limits: Limits, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The whole turns k that bring each joint of q (shape (..., n)) within its bounds: (first, last), (..., n) each.

    Joint i may take q_i + 2kπ for every k in [first, last] (none when last < first); the turns are floats, so
    a joint limited to ±1e6 rad counts its 318,310 equivalents as ``last − first + 1`` without generating them.

    * revolute with both bounds finite: every k inside the bounds (the end values are checked, as the ceil and
      floor of a rounded quotient can admit a value a few ulps outside);
    * revolute bounded on one side: the one k inside nearest q_i (0 when q_i fits);
    * continuous revolute, or prismatic: k = 0 if q_i fits, else none.

    Examples
    --------
    A joint limited to ±270° at 100° has turns [−1, 0]: −260° and 100°.
    """
    q = np.asarray(q, dtype=float)
    lower, upper, both = limits.widened(robot)
    low = high = None  # the both-bounded columns' turns, None where every one is 0
    if both.any():  # every both-bounded column at once (whole rows: a column alone strides through them all)
        value, low_bound, high_bound = (q, lower, upper) if both.all() else (q[..., both], lower[both], upper[both])
        if not (value.size >= _CHECKED_FROM and _one_turn_each(value, low_bound, high_bound)):
            # in place, a few (..., n) arrays in all: a batch's table has tens of thousands of rows
            low = np.subtract(low_bound, value)
            low /= _TWO_PI
            np.ceil(low, out=low)
            high = np.subtract(high_bound, value)
            high /= _TWO_PI
            np.floor(high, out=high)
            end = np.multiply(low, _TWO_PI)  # the end values q + 2kπ, checked against the bounds
            end += value
            low += end < low_bound
            np.multiply(high, _TWO_PI, out=end)
            end += value
            high -= end > high_bound
            if both.all():
                return low, high
    first, last = np.zeros_like(q), np.zeros_like(q)
    if low is not None:
        first[..., both], last[..., both] = low, high
    continuous = limits.continuous(robot)
    for j in np.flatnonzero(~both).tolist():  # one kind of joint per column
        value = q[..., j]
        if robot.is_revolute[j] and not continuous[j]:
            below = value < lower[j]
            above = value > upper[j]
            turn = np.where(below, np.ceil((lower[j] - value) / _TWO_PI) if np.isfinite(lower[j]) else 0.0,
                            np.where(above, np.floor((upper[j] - value) / _TWO_PI) if np.isfinite(upper[j]) else 0.0,
                                     0.0))
            first[..., j] = last[..., j] = turn
        else:
            last[..., j] = np.where((value >= lower[j]) & (value <= upper[j]), 0.0, -1.0)
    return first, last


#: How far inside the values :func:`_one_turn_each` takes are from where a turn's quotient may round to a whole one.
_INTERIOR_MARGIN = 1e-6
#: The fewest values :func:`turn_ranges` checks with :func:`_one_turn_each` first: below, its few calls cost more
#: than the quotients (one target's rows).
_CHECKED_FROM = 1024


def _one_turn_each(q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Whether every value of q (..., n) lies inside its bounds (n,) and so far from the bounds moved by a whole
    turn either way that :func:`turn_ranges` would give it the turns [0, 0] alone (as +0.0): three comparisons
    instead of the quotients, for the usual batch under limits of about one turn."""
    inside_low = np.maximum(lower, upper - _TWO_PI + _INTERIOR_MARGIN)
    inside_high = np.minimum(upper, lower + _TWO_PI - _INTERIOR_MARGIN)
    return bool(((q > inside_low) & (q < inside_high)).all())  # an empty interval fails every value


def closest_equivalent(robot: Robot, limits: Limits, q: np.ndarray,
                       turns: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """The 2π-equivalent of each row of q (shape (..., n)) that is as close to the limits as whole turns bring it.

    Each revolute joint that has an equivalent inside its bounds takes the one
    nearest its value; one that has none takes the equivalent nearest its
    range (the smallest violation). Prismatic joints keep their values. The
    joints that still violate a bound are exactly those no whole turn can fix. ``turns`` are q's
    :func:`turn_ranges`, when the caller has them.
    """
    q = np.asarray(q, dtype=float)
    first, last = turn_ranges(robot, limits, q) if turns is None else turns
    return q + _TWO_PI * closest_turns(robot, limits, q, first, last)


def closest_turns(robot: Robot, limits: Limits, q: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """The whole turns k (shape (..., n)) of :func:`closest_equivalent`: q + 2kπ, from q's :func:`turn_ranges`.

    A joint with turns inside its bounds takes the one nearest 0. A both-bounded revolute joint without one
    has ``last = first − 1``: q + 2π·last is the largest equivalent below the range and q + 2π·first the
    smallest above it, and the nearer to its bound is taken (the upper one on a tie). Every other joint
    without one (continuous or prismatic, out of range) keeps its value (``first`` is 0 there).

    Examples
    --------
    A joint limited to [10°, 20°] at 200°: turns [0, −1], so 200° (180° above) and −160° (170° below):
    −1 turn, to −160°.
    """
    turns = np.minimum(np.maximum(first, 0.0), last)
    outside = np.flatnonzero(last < first)  # usually few joints: only these need the nearer side worked out
    if len(outside):
        joint = outside % q.shape[-1]
        value, below, above = (np.take(a, outside) for a in (q, last, first))
        with np.errstate(invalid="ignore"):
            below_by = limits.lower[joint] - (value + _TWO_PI * below)
            above_by = (value + _TWO_PI * above) - limits.upper[joint]
        np.put(turns, outside, np.where(limits.multi_valued(robot)[joint] & (below_by < above_by), below, above))
    return turns


def nearest_fitting_equivalent(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray | None:
    """The 2π-equivalent of q (shape (n,)) that fits the limits and moves each joint least; None if none fits.

    The joints are independent, so the vector nearest under any per-joint
    norm is the per-joint nearest.

    Examples
    --------
    A UR5 (±360° on every joint) at q1 = 7 rad: 0.717 rad and −5.566 rad both
    fit; the nearest, 0.717 rad, is returned.
    """
    closest = closest_equivalent(robot, limits, q)
    return closest if within(robot, limits, closest) else None
