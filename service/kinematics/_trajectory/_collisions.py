"""Collision-free branches along a trajectory: which of a sample's solutions may continue the path, and the
clearance each reached sample reports.

With a collision check whose ``filter`` is on, a sample continues on the solution nearest the prediction among
those that do not collide (after the held labels have chosen theirs). When the branch's own continuation
collides and another solution does not, the sample takes that one: a branch change forced by a collision,
reported as such. When every candidate collides, the sample keeps the nearest one and says so
(``no_collision_free_solution``). Only the samples are checked, not the motion between them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..collision import CollisionRequest, clearances


@dataclass(frozen=True)
class CollisionChoice:
    """A sample's candidates after the collision rule: ``pool`` (indices into the candidates), ``blocked`` when
    every candidate the labels allow collides (the pool is then theirs, unfiltered), and ``colliding`` (m,) bool
    per candidate (None when the request has no filter)."""

    pool: list[int]
    blocked: bool
    colliding: np.ndarray | None


def collision_free_pool(robot, request: CollisionRequest | None, joints: np.ndarray,
                        allowed: list[int]) -> CollisionChoice:
    """The candidates (m, n) of one sample that the path may continue on: of ``allowed`` (the held labels'
    choice), those that do not collide under a filtering ``request``; all of ``allowed`` without one, or when
    each of them collides."""
    if request is None or not request.filter or not allowed:
        return CollisionChoice(allowed, False, None)
    colliding = clearances(robot, request, joints).colliding
    free = [i for i in allowed if not colliding[i]]
    return CollisionChoice(free or allowed, not free, colliding)


def forced_by_collision(choice: CollisionChoice, allowed: list[int], to_prediction: np.ndarray | None) -> bool:
    """Whether the collision rule moved the sample off its branch: the candidate nearest the prediction among
    ``allowed`` collides, and another one was taken instead. ``to_prediction`` (m,) per candidate."""
    if choice.colliding is None or choice.blocked or to_prediction is None or not allowed:
        return False
    continuation = allowed[int(np.argmin(to_prediction[allowed]))]
    return bool(choice.colliding[continuation])


@dataclass(frozen=True)
class SampleClearance:
    """The collision check of one reached sample's joints: the smallest signed distance (length unit, None when
    nothing is checked), the pairs closer than the margin, as (a, b, distance), and whether there is one."""

    clearance: float | None
    contacts: tuple[tuple[str, str, float], ...]
    colliding: bool


def sample_clearances(robot, request: CollisionRequest, joints: np.ndarray) -> list[SampleClearance]:
    """The check of the reached samples' joints (R, n), all at once."""
    if not len(joints):
        return []
    checked = clearances(robot, request, joints)
    return [SampleClearance(None if math.isinf(value) else float(value), tuple(contacts), bool(colliding))
            for value, contacts, colliding in zip(checked.clearance.tolist(), checked.contacts,
                                                  checked.colliding.tolist())]
