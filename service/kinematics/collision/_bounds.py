"""Cheap single-precision bounds on the distances of a collision model's pairs, so that a block of
configurations measures only the pairs that can be its clearance or closer than its margin.

Each bound replaces one shape by the ball about its middle: a capsule of half length h and radius r holds the
ball of radius r about its middle and lies inside the ball of radius r + h. The distance from the other shape's
core to that middle, less the radii, is then an upper bound of the pair's distance, and less h as well a lower
bound. Shapes and sizes are those of :mod:`._model`'s kernels: rows (3, m, P, B) of reference points and
directions, sizes (P, 1) or (3, P, 1) in single precision.
"""

from __future__ import annotations

import numpy as np

from ._distances import _box_point_local, _dot, _nearest_on_segment

#: Slack of the single-precision bounds, relative to the largest coordinate of a block (length unit): far above
#: their rounding (a few dozen ulps of 6e-8), far below any clearance a request states.
BOUND_SLACK = 1e-5

#: Coordinates at or past this (length unit) skip the bounds: their squares would leave single precision's range.
BOUND_RANGE = 1e15


def block_bounds(groups, placed: np.ndarray, margin: float, clearance: np.ndarray) -> tuple[list, np.ndarray, float]:
    """Each group's bounds for a block (``bounds_of`` of the model's pair groups), every configuration's cutoff (B,) and the slack;
    ``clearance`` (B,): the smallest distance of the pairs already measured, which bounds the clearance too.

    Single precision, kept conservative by a slack far above its rounding (a few dozen ulps of the largest
    coordinate); coordinates it cannot hold have no bounds, so every pair is measured."""
    placed32 = placed.astype(np.float32)
    largest = float(np.abs(placed32).max())
    slack = BOUND_SLACK * (1.0 + largest)
    bounds = [group.bounds_of(placed32) if largest < BOUND_RANGE else None for group in groups]
    upper = clearance.astype(np.float32)
    for bound in bounds:
        if bound is not None:
            np.fmin(upper, bound[1].min(axis=0), out=upper)
    return bounds, np.maximum(upper + slack, margin) + slack, slack


def _round_round_bounds(rows, radii, reach, inverse_square_length):
    """Lower and upper bounds (P, B) of two capsules' distance from the distance of one's core (rows 0, 1: the
    longer segment, 1 / its squared length given) to the other's middle (rows 2, 3: the shorter one's ends):
    the other shape holds the ball of radius r about its middle and lies inside the ball of radius r + half its
    length (``reach``); ``radii`` (P, 1) their sum."""
    middle = rows[:, 2] + rows[:, 3]
    middle *= 0.5
    return _round_middle_bounds(rows, middle, radii, reach, inverse_square_length)


def _round_point_bounds(rows, radii, reach, inverse_square_length):
    """:func:`_round_round_bounds` of a capsule or sphere (rows 0, 1) and a sphere (row 2, its centre: the
    middle, ``reach`` 0), whose lower and upper bounds are the distance, in single precision."""
    return _round_middle_bounds(rows, rows[:, 2], radii, reach, inverse_square_length)


def _round_middle_bounds(rows, middle, radii, reach, inverse_square_length):
    gap = middle - rows[:, 0]  # the middle, from the segment's start
    _nearest_on_segment(gap, rows[:, 1] - rows[:, 0], inverse_square_length)
    upper = np.sqrt(_dot(gap, gap))
    upper -= radii
    return upper - reach, upper


def _box_round_bounds(rows, half_size_a, radius_b, reach):
    """Lower and upper bounds (P, B) of a box's distance to a capsule from the box's signed distance at the
    capsule's middle (the same balls as :func:`_round_round_bounds`; the box's half sizes (3, P, 1), the
    capsule's radius (P, 1))."""
    middle = rows[:, 4] + rows[:, 5]
    middle *= 0.5
    return _box_middle_bounds(rows, middle, half_size_a, radius_b, reach)


def _box_point_bounds(rows, half_size_a, radius_b, reach):
    """:func:`_box_round_bounds` of a box and a sphere (row 4, its centre: the middle, ``reach`` 0)."""
    return _box_middle_bounds(rows, rows[:, 4], half_size_a, radius_b, reach)


def _box_middle_bounds(rows, middle, half_size_a, radius_b, reach):
    local = np.einsum("ij...,i...->j...", rows[:, 1:4], middle - rows[:, 0])  # R^T (middle - centre)
    upper = _box_point_local(local, half_size_a)
    upper -= radius_b
    return upper - reach, upper


#: The cheap bounds of each pair of families (two boxes have none: they are always measured).
FAMILY_BOUNDS = {("round", "point"): _round_point_bounds, ("box", "point"): _box_point_bounds,
                 ("round", "round"): _round_round_bounds, ("box", "round"): _box_round_bounds}


def bound_constants(family: tuple[str, str], first_half_sizes: np.ndarray | None, first_radii: np.ndarray | None,
                    second_radii: np.ndarray | None, first_halves: list[float], second_halves: list[float]) -> tuple:
    """The sizes a family's bounds take, in the order its bound function takes them, single precision, (P, 1)
    each (a box's half sizes (3, P, 1)): from the pairs' first shapes' half sizes (boxes) or radii, the second
    shapes' radii, and the shapes' half lengths (0 for a sphere)."""
    if family == ("box", "box"):
        return ()
    reach = np.array([[min(a, b)] for a, b in zip(first_halves, second_halves)], dtype=np.float32)
    if family[0] == "round":
        longer = [max(2.0 * a, 2.0 * b) for a, b in zip(first_halves, second_halves)]
        inverse = np.array([[1.0 / length ** 2 if length > 0.0 else 0.0] for length in longer])
        return (first_radii + second_radii).astype(np.float32), reach, inverse.astype(np.float32)
    return first_half_sizes.astype(np.float32), second_radii.astype(np.float32), reach
