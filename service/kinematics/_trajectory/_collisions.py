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

from ..collision import CollisionRequest, clearances, colliding


@dataclass(frozen=True)
class CollisionChoice:
    """A sample's candidates after the collision rule: ``pool`` (indices into the candidates), ``blocked`` when
    every candidate the labels allow collides (the pool is then theirs, unfiltered), and ``colliding`` (m,) bool
    per candidate (None when the request has no filter)."""

    pool: list[int]
    blocked: bool
    colliding: np.ndarray | None


def listed_collisions(robot, request: CollisionRequest | None, results) -> list[np.ndarray] | None:
    """Which of each sample's listed IK solutions collide, (m_k,) bool per sample, in one check of them all; None
    without a filtering ``request``."""
    if request is None or not request.filter:
        return None
    listed = [np.array([s.joints for s in result.solutions], dtype=float).reshape(-1, robot.dof)
              for result in results]
    hits = colliding(robot, request, np.concatenate(listed))
    return np.split(hits, np.cumsum([len(joints) for joints in listed])[:-1])


def collision_free_pool(robot, request: CollisionRequest | None, joints: np.ndarray, allowed: list[int],
                        known: np.ndarray | None = None) -> CollisionChoice:
    """The candidates (m, n) of one sample that the path may continue on: of ``allowed`` (the held labels'
    choice), those that do not collide under a filtering ``request``; all of ``allowed`` without one, or when
    each of them collides. ``known``: whether the first candidates collide, already checked
    (:func:`listed_collisions`); only the others are checked here."""
    if request is None or not request.filter or not allowed:
        return CollisionChoice(allowed, False, None)
    known = np.zeros(0, dtype=bool) if known is None else known
    rest = joints[len(known):]
    hits = np.concatenate([known, colliding(robot, request, rest) if len(rest) else np.zeros(0, dtype=bool)])
    free = [i for i in allowed if not hits[i]]
    return CollisionChoice(free or allowed, not free, hits)


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
