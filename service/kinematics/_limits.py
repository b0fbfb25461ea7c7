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

import heapq
import itertools
import math
from dataclasses import dataclass
from typing import Callable, Iterator, Sequence

import numpy as np

from ._budget import capped_product
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


@dataclass(frozen=True)
class Violation:
    """One joint outside its bounds: index, value and the bounds (core units)."""

    joint: int
    value: float
    lower: float
    upper: float


def within(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray:
    """Whether each row of q (shape (..., n)) is inside every bound, tolerance included."""
    tolerance = limits.tolerance(robot)
    return np.all((q >= limits.lower - tolerance) & (q <= limits.upper + tolerance), axis=-1)


def violations(robot: Robot, limits: Limits, q: np.ndarray) -> list[Violation]:
    """Every joint of q (shape (n,)) outside its bounds, with the bounds it breaks.

    Examples
    --------
    A PUMA 560 wrist (q5 in [−100°, 100°]) at 120° gives one violation,
    ``Violation(4, 2.094…, −1.745…, 1.745…)``.
    """
    tolerance = limits.tolerance(robot)
    outside = (q < limits.lower - tolerance) | (q > limits.upper + tolerance)
    return [Violation(int(i), float(q[i]), float(limits.lower[i]), float(limits.upper[i]))
            for i in np.flatnonzero(outside)]


def _turn_range(lower: float, upper: float, value: float) -> tuple[int, int]:
    """The whole turns k with ``value + 2kπ`` in [lower, upper] (bounds finite): (first, last), empty if last < first.

    ceil/floor of a rounded quotient can admit a value a few ulps outside: the end values themselves are checked.
    """
    first = math.ceil((lower - value) / _TWO_PI)
    last = math.floor((upper - value) / _TWO_PI)
    if last >= first and value + _TWO_PI * first < lower:
        first += 1
    if last >= first and value + _TWO_PI * last > upper:
        last -= 1
    return first, last


def turn_counts(robot: Robot, limits: Limits, q: np.ndarray) -> list[int]:
    """How many values :func:`turn_offsets` gives each joint of q (shape (n,)), computed without generating them.

    Examples
    --------
    A joint limited to ±1e6 rad has 318,310 equivalents of 0.5 rad; this counts them in constant time.
    """
    tolerance = limits.tolerance(robot)
    counts = []
    for i in range(robot.dof):
        lower, upper, value = limits.lower[i] - tolerance[i], limits.upper[i] + tolerance[i], float(q[i])
        if robot.is_revolute[i] and np.isfinite(lower) and np.isfinite(upper):
            first, last = _turn_range(lower, upper, value)
            counts.append(max(0, last - first + 1))
        elif robot.is_revolute[i] and (value < lower or value > upper):
            counts.append(1)
        else:
            counts.append(1 if lower <= value <= upper else 0)
    return counts


def turn_offsets(robot: Robot, limits: Limits, q: np.ndarray, *, keep: int | None = None,
                 around: np.ndarray | None = None) -> list[np.ndarray]:
    """For each joint, the values of q_i that are usable within its bounds, ascending.

    * revolute with both bounds finite: every q_i + 2kπ inside the bounds
      (empty when none is); with ``keep``, only the ``keep`` of them nearest
      ``around[i]`` (default q_i), so that a joint limited to ±1e6 rad costs
      what is kept, not its 318,310 equivalents (:func:`turn_counts` counts
      them all);
    * revolute bounded on one side: the one q_i + 2kπ inside, nearest q_i;
    * continuous revolute, or prismatic: q_i itself, if it fits (a prismatic
      value outside its bounds gives an empty list).

    Examples
    --------
    A joint limited to ±270° has two equivalents of 100°: −260° and 100°.
    """
    tolerance = limits.tolerance(robot)
    options = []
    for i in range(robot.dof):
        lower, upper, value = limits.lower[i] - tolerance[i], limits.upper[i] + tolerance[i], float(q[i])
        if robot.is_revolute[i] and np.isfinite(lower) and np.isfinite(upper):
            first, last = _turn_range(lower, upper, value)
            if keep is not None and last - first + 1 > keep + 2:
                # the keep values nearest the centre are consecutive turns: a window of keep + 2 around it holds
                # them (one spare turn each side), slid inwards where it meets a bound
                centre = value if around is None else float(around[i])
                nearest = min(max(round((centre - value) / _TWO_PI), first), last)
                low = min(max(first, nearest - keep // 2 - 1), last - keep - 1)
                first, last = low, low + keep + 1
            turns = np.arange(first, last + 1, dtype=float) if last >= first else np.zeros(0)
            candidates = value + _TWO_PI * turns
            options.append(candidates[(candidates >= lower) & (candidates <= upper)])
        elif robot.is_revolute[i] and value < lower:
            options.append(np.array([value + _TWO_PI * np.ceil((lower - value) / _TWO_PI)]))
        elif robot.is_revolute[i] and value > upper:
            options.append(np.array([value - _TWO_PI * np.ceil((value - upper) / _TWO_PI)]))
        else:
            options.append(np.array([value]) if lower <= value <= upper else np.zeros(0))
    return options


def closest_equivalent(robot: Robot, limits: Limits, q: np.ndarray) -> np.ndarray:
    """The 2π-equivalent of q (shape (n,)) that is as close to the limits as whole turns can bring it.

    Each revolute joint that has an equivalent inside its bounds takes the one
    nearest its value; one that has none takes the equivalent nearest its
    range (the smallest violation). Prismatic joints keep their values. The
    joints that still violate a bound are exactly those no whole turn can fix.
    """
    q = np.asarray(q, dtype=float)
    closest = q.copy()
    for i, options in enumerate(turn_offsets(robot, limits, q, keep=1)):
        if len(options):
            closest[i] = options[np.argmin(np.abs(options - q[i]))]
        elif robot.is_revolute[i]:
            lower, upper = limits.lower[i], limits.upper[i]
            below = lower - np.mod(lower - q[i], _TWO_PI)  # largest equivalent ≤ lower
            above = upper + np.mod(q[i] - upper, _TWO_PI)  # smallest equivalent ≥ upper
            closest[i] = below if lower - below < above - upper else above
    return closest


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


def count_combinations(options: Sequence[np.ndarray]) -> int:
    """Number of vectors in the product of per-joint options, at most :data:`._budget.COUNT_CAP`."""
    return capped_product(len(o) for o in options)


def combinations_by_cost(costs: Sequence[np.ndarray],
                         combine: Callable[[list[float]], float]) -> Iterator[tuple[float, tuple[int, ...]]]:
    """Every combination of per-joint options, cheapest first, generated lazily.

    Parameters
    ----------
    costs : sequence of ndarray
        For each joint, the cost of each of its options, sorted ascending.
    combine : callable
        Total cost of one per-joint cost list; must not decrease when any one
        cost increases (max, a sum, the square root of a sum of squares).

    Yields
    ------
    (cost, indices) in ascending (cost, indices) order, where ``indices`` picks
    one option per joint. Stopping early costs only what was generated, so a
    product with billions of combinations can be cut at the cheapest thousand.

    Each combination other than all-zeros has exactly one parent (its last
    non-zero index decremented), which costs no more; a heap over (cost,
    indices) therefore pops in order without a visited set.
    """
    if any(len(c) == 0 for c in costs):
        return
    n = len(costs)
    start = (0,) * n
    heap = [(combine([c[0] for c in costs]), start, 0)]
    while heap:
        cost, indices, last = heapq.heappop(heap)
        yield cost, indices
        for j in range(last, n):
            if indices[j] + 1 < len(costs[j]):
                child = indices[:j] + (indices[j] + 1,) + indices[j + 1:]
                heapq.heappush(heap, (combine([costs[k][child[k]] for k in range(n)]), child, j))


def fitting_equivalents(robot: Robot, limits: Limits, q: np.ndarray, cap: int) -> tuple[np.ndarray, bool]:
    """Every 2π-equivalent of q (shape (n,)) that is inside the limits, fewest turns first, at most ``cap``.

    Returns
    -------
    equivalents : ndarray, shape (m, n)
        Ordered by the total turning Σ|q'_i − q_i|; empty when none fits.
    truncated : bool
        True when more than ``cap`` equivalents fit and the list was cut.

    Examples
    --------
    A joint limited to ±270° has two equivalents of 100°: 100° and −260°, in
    that order.
    """
    q = np.asarray(q, dtype=float)
    # the cap cheapest combinations use at most the cap cheapest values of each joint
    options = [o[np.argsort(np.abs(o - value), kind="stable")]
               for o, value in zip(turn_offsets(robot, limits, q, keep=cap), q)]
    costs = [np.abs(o - value) for o, value in zip(options, q)]
    picked = [indices for _, indices in itertools.islice(combinations_by_cost(costs, math.fsum), cap)]
    if not picked:
        return np.zeros((0, robot.dof)), False
    equivalents = np.array([[options[j][k] for j, k in enumerate(indices)] for indices in picked])
    return equivalents, capped_product(turn_counts(robot, limits, q)) > cap
