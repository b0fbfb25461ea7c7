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

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ._budget import COUNT_CAP
from ._cache import bounded_memo
from ._errors import InvalidInputError
from ._robot import Robot, check_limit_pair
from ._tolerances import LIMIT_TOLERANCE

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Limits:
    """Lower and upper bounds for every joint, shape (n,) each; ±inf where unlimited.

    Radians for revolute joints, the robot's length unit for prismatic ones. The bounds are read as they stand
    when first applied to a robot (:meth:`widened`): change them by making other limits, not in place.
    """

    lower: np.ndarray
    upper: np.ndarray
    #: The :class:`Widened` bounds already applied to a robot: id → (robot, widened). An answer applies the same
    #: limits half a dozen times; looking them up by value each time cost more than the rest of the check.
    _applied: dict = field(default_factory=dict, init=False, repr=False, compare=False)

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
        """Which joints are revolute with no bounds at all, shape (n,) bool, read-only (:class:`Widened`)."""
        return self.widened(robot).continuous

    def multi_valued(self, robot: Robot) -> np.ndarray:
        """Which joints are revolute with both bounds finite: those expanded into their 2π-equivalents. Shape (n,)
        bool, read-only (:class:`Widened`)."""
        return self.widened(robot).multi_valued

    def widened(self, robot: Robot) -> "Widened":
        """The bounds as the checks apply them (:class:`Widened`). Kept on the robot for the last
        :data:`_WIDENED_KEPT` limits asked by value (every answer applies its limits, mostly the same few)."""
        def build() -> Widened:
            tolerance = self.tolerance(robot)
            lower, upper = self.lower - tolerance, self.upper + tolerance
            multi_valued = robot.is_revolute & np.isfinite(self.lower) & np.isfinite(self.upper)
            continuous = robot.is_revolute & np.isneginf(self.lower) & np.isposinf(self.upper)
            # the interval of _one_turn_each, where only multi-valued joints count
            one_turn_low = np.where(multi_valued, np.maximum(lower, upper - _TWO_PI + _INTERIOR_MARGIN), -np.inf)
            one_turn_high = np.where(multi_valued, np.minimum(upper, lower + _TWO_PI - _INTERIOR_MARGIN), np.inf)
            # and the interval where any joint's value has them, and fits (its own bounds, at other joints)
            zero_turn_low = np.where(multi_valued, one_turn_low, lower)
            zero_turn_high = np.where(multi_valued, one_turn_high, upper)
            arrays = (lower, upper, multi_valued, continuous, one_turn_low, one_turn_high, zero_turn_low,
                      zero_turn_high)
            for array in arrays:
                array.flags.writeable = False
            kind = np.where(multi_valued, MULTI_VALUED, np.where(robot.is_revolute & ~continuous, ONE_SIDED,
                                                                   FITS_OR_NOT))
            rules = tuple(zip(kind.tolist(), lower.tolist(), upper.tolist(), one_turn_low.tolist(),
                              one_turn_high.tolist(), self.lower.tolist(), self.upper.tolist()))
            equivalents = 1  # Π_j ceil(span_j / 2π) over the multi-valued joints, capped (a span may overflow)
            for both, low, high in zip(multi_valued.tolist(), self.lower.tolist(), self.upper.tolist()):
                if both:
                    turns = (high - low) / _TWO_PI
                    equivalents = (min(equivalents * max(math.ceil(turns), 1), COUNT_CAP) if turns < COUNT_CAP
                                   else COUNT_CAP)
            return Widened(*arrays, every_multi_valued=bool(multi_valued.all()),
                           any_multi_valued=bool(multi_valued.any()),
                           one_turn_possible=bool((one_turn_low < one_turn_high).all()), rules=rules,
                           equivalents_per_solution=equivalents)
        applied = self._applied.get(id(robot))
        if applied is not None and applied[0] is robot:
            return applied[1]
        key = (self.lower.dtype.str, self.lower.tobytes(), self.upper.dtype.str, self.upper.tobytes())
        widened = bounded_memo(robot, "widened_limits", key, build, _WIDENED_KEPT)
        if len(self._applied) >= _WIDENED_KEPT:  # limits kept long and applied to many robots stay small
            self._applied.clear()
        self._applied[id(robot)] = (robot, widened)
        return widened


@dataclass(frozen=True)
class Widened:
    """Limits as the checks apply them, per joint (n,) each, read-only.

    ``lower − tolerance`` and ``upper + tolerance``; ``multi_valued`` (revolute, both bounds finite) and
    ``continuous`` (revolute, no bounds); and the open interval (``one_turn_low``, ``one_turn_high``) inside
    which a multi-valued joint's value has the turns [0, 0] alone (:func:`_one_turn_each`; ±∞ at the other
    joints); (``zero_turn_low``, ``zero_turn_high``) is that interval at the multi-valued joints and the bounds at
    the others: a value inside has the turns [0, 0] alone, whatever its joint. The flags say whether every joint,
    and any, is multi-valued, and whether every one-turn interval is non-empty (limits of at most about one turn).
    ``rules`` holds the same per joint on Python floats, for one target's few rows (:func:`turns_of_row`):
    (kind, lower, upper, one_turn_low, one_turn_high, and the bounds without their tolerance), the kind one of
    :data:`MULTI_VALUED`, :data:`ONE_SIDED`, :data:`FITS_OR_NOT`. ``equivalents_per_solution``: see
    :func:`.ik.equivalents_per_solution`.
    """

    lower: np.ndarray
    upper: np.ndarray
    multi_valued: np.ndarray
    continuous: np.ndarray
    one_turn_low: np.ndarray
    one_turn_high: np.ndarray
    zero_turn_low: np.ndarray
    zero_turn_high: np.ndarray
    every_multi_valued: bool
    any_multi_valued: bool
    one_turn_possible: bool
    rules: tuple[tuple[int, float, float, float, float, float, float], ...]
    equivalents_per_solution: int


#: How a joint's turns are found (:attr:`Widened.rules`): revolute with both bounds finite (every turn inside);
#: revolute bounded on one side (the one turn inside nearest its value); continuous revolute or prismatic (its
#: value fits or it does not).
MULTI_VALUED, ONE_SIDED, FITS_OR_NOT = 0, 1, 2


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
    bounds = limits.widened(robot)
    return np.all((q >= bounds.lower) & (q <= bounds.upper), axis=-1)


def outside_limits(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray:
    """Which joints of each row of q (shape (..., n)) break a bound, tolerance included: shape (..., n)."""
    bounds = limits.widened(robot)
    return (q < bounds.lower) | (q > bounds.upper)


def violations(robot: Robot, limits: Limits, q: np.ndarray) -> list[Violation]:
    """Every joint of q (shape (n,)) outside its bounds, with the bounds it breaks.

    Examples
    --------
    A PUMA 560 wrist (q5 in [−100°, 100°]) at 120° gives one violation,
    ``Violation(4, 2.094…, −1.745…, 1.745…)``.
    """
    return _violations_of(limits, q, outside_limits(robot, limits, q))


def _violations_of(limits: Limits, q: np.ndarray, outside: np.ndarray) -> list[Violation]:
    """The :class:`Violation` of each joint of q (n,) that ``outside`` (n,) marks."""
    return [Violation(int(i), float(q[i]), float(limits.lower[i]), float(limits.upper[i]))
            for i in np.flatnonzero(outside)]


@dataclass(frozen=True)
class LimitsCheck:
    """Joint vectors q (N, n) checked against limits, every row at once (:func:`check_limits`).

    ``inside`` (N,) says which rows are within every bound; ``outside`` (N, n) which joints break one;
    ``equivalent`` (N, n) holds, for each row outside, its 2π-equivalent that fits and moves each joint least
    (:func:`nearest_fitting_equivalent`), where ``fits`` (N,); NaN elsewhere (no equivalent fits, or the row is
    inside).
    """

    q: np.ndarray
    limits: Limits
    inside: np.ndarray
    outside: np.ndarray
    equivalent: np.ndarray
    fits: np.ndarray

    def violations(self, row: int) -> list[Violation]:
        """Row ``row``'s :func:`violations`."""
        return _violations_of(self.limits, self.q[row], self.outside[row])


def check_limits(robot: Robot, limits: Limits, q: np.ndarray) -> LimitsCheck:
    """:func:`within`, :func:`violations` and :func:`nearest_fitting_equivalent` of every row of q (N, n) at
    once: a few array operations for the batch, where a row at a time cost ~100 µs each."""
    q = np.asarray(q, dtype=float)
    outside = outside_limits(robot, limits, q)
    inside = ~outside.any(axis=-1)
    equivalent = np.full(q.shape, np.nan)
    fits = np.zeros(len(q), dtype=bool)
    rows = np.flatnonzero(~inside)
    if len(rows):
        closest = closest_equivalent(robot, limits, q[rows])
        fits[rows] = within(robot, limits, closest)
        equivalent[fits] = closest[fits[rows]]
    return LimitsCheck(q, limits, inside, outside, equivalent, fits)


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
    bounds = limits.widened(robot)
    lower, upper, both = bounds.lower, bounds.upper, bounds.multi_valued
    low = high = None  # the both-bounded columns' turns, None where every one is 0
    if bounds.any_multi_valued and not (q.size >= _CHECKED_FROM and bounds.one_turn_possible
                                        and _one_turn_each(q, bounds)):
        # every both-bounded column at once (whole rows: a column alone strides through them all)
        every = bounds.every_multi_valued
        value, low_bound, high_bound = (q, lower, upper) if every else (q[..., both], lower[both], upper[both])
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
        if every:
            return low, high
    first, last = np.zeros(q.shape), np.zeros(q.shape)
    if low is not None:
        first[..., both], last[..., both] = low, high
    if bounds.every_multi_valued:
        return first, last
    continuous = bounds.continuous
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
#: The fewest values :func:`turn_ranges` checks with :func:`_one_turn_each` first. Its intervals are kept with the
#: limits (:class:`Widened`), so the check is three comparisons at any size: one target's rows take it too.
_CHECKED_FROM = 0


def _one_turn_each(q: np.ndarray, bounds: Widened) -> bool:
    """Whether every multi-valued joint's value in q (..., n) lies so far inside its bounds, and from the bounds
    moved by a whole turn either way, that :func:`turn_ranges` would give it the turns [0, 0] alone (as +0.0):
    three comparisons instead of the quotients, for the usual answer under limits of about one turn. (A NaN
    fails, and takes the quotients.)"""
    inside = (q > bounds.one_turn_low) & (q < bounds.one_turn_high)
    return np.count_nonzero(inside) == inside.size


def turns_of_row(bounds: Widened, row: list[float]) -> tuple[list[float], list[float], bool] | None:
    """One row of joint values (n floats) against the limits on Python floats, where one target's answer would
    spend more on the arrays' fixed costs than on the arithmetic: its :func:`turn_ranges` (first, last) and True
    when it fits; when it does not, its :func:`closest_turns` twice and False. The same turns as the arrays', in
    the same arithmetic. None where a value is not finite and its joint takes a quotient (the arrays' rules for NaN
    and infinities then apply)."""
    first, last, fits = [], [], True
    for value, (kind, lower, upper, one_turn_low, one_turn_high, _, _) in zip(row, bounds.rules):
        if kind == FITS_OR_NOT:
            first.append(0.0)
            if lower <= value <= upper:
                last.append(0.0)
            else:
                last.append(-1.0)
                fits = False
            continue
        if kind == MULTI_VALUED and one_turn_low < value < one_turn_high:  # the usual case: this turn alone
            first.append(0.0)
            last.append(0.0)
            continue
        if not -math.inf < value < math.inf:
            return None
        if kind == MULTI_VALUED:  # the end values q + 2kπ checked against the bounds, as the arrays do
            low = float(math.ceil((lower - value) / _TWO_PI))
            high = float(math.floor((upper - value) / _TWO_PI))
            if low * _TWO_PI + value < lower:
                low += 1.0
            if high * _TWO_PI + value > upper:
                high -= 1.0
            first.append(low)
            last.append(high)
            if high < low:
                fits = False
            continue
        turn = 0.0  # one-sided: the turn inside nearest the value
        if value < lower and lower > -math.inf:
            turn = float(math.ceil((lower - value) / _TWO_PI))
        elif value > upper and upper < math.inf:
            turn = float(math.floor((upper - value) / _TWO_PI))
        first.append(turn)
        last.append(turn)
    if fits:
        return first, last, True
    closest = []  # closest_turns: the turn nearest 0 where one fits; else the nearer side's
    for value, low, high, (kind, _, _, _, _, lower, upper) in zip(row, first, last, bounds.rules):
        if high >= low:
            closest.append(min(max(low, 0.0), high))
        elif kind == MULTI_VALUED and lower - (value + _TWO_PI * high) < (value + _TWO_PI * low) - upper:
            closest.append(high)  # the equivalent below the range is the nearer
        else:
            closest.append(low)
    return closest, closest, False


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
    outside = (last < first).ravel().nonzero()[0]  # usually few joints: only these need the nearer side worked out
    if len(outside):
        joint = outside % q.shape[-1]
        value, below, above = (a.take(outside) for a in (q, last, first))
        with np.errstate(invalid="ignore"):
            below_by = limits.lower[joint] - (value + _TWO_PI * below)
            above_by = (value + _TWO_PI * above) - limits.upper[joint]
        turns.put(outside, np.where(limits.multi_valued(robot)[joint] & (below_by < above_by), below, above))
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
