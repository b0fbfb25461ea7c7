"""A redundant arm along a path: each sample answered over its free joint, held continuous from the previous
sample's value."""

from __future__ import annotations

import numpy as np

from .._robot import Robot
from ..ik import AnswerOptions, IKOptions, IKResult, IKTargets, answer_ik, free_joints_for, result_of, unlimited

#: Along a path, how far (rad or length units) and at how many values a redundant arm's free joint is searched
#: around the previous sample's value before its whole family is.
TRACK_WINDOW = 0.25
TRACK_SAMPLES = 9


def follow_free_joints(robot: Robot, world_T_targets: np.ndarray, reference: np.ndarray | None,
                       ik: IKOptions, requested: list | None = None) -> tuple[list[IKResult], list[int]] | None:
    """Per-sample IK results of a redundant arm along a path, with the free joint held continuous.

    ``requested``: the request's free joints, ``(joint, values or None, samples or None)`` entries in radians /
    length units, with the meaning they have in single IK (:func:`~.ik.free_joints_for`): each sample is
    answered over those joints at those values (:func:`~.ik.answer_ik`), nearest the previous sample first.
    Raises :class:`InvalidInputError` (located in the list) for entries single IK refuses.

    The first sample takes the family's solution nearest the reference (over the whole family: sampled, then
    searched continuously) or, without one, the family's first. Each later sample searches the free joint within
    :data:`TRACK_WINDOW` of the previous sample's value (sampled, then continuously) for the solution nearest the
    previous sample's joints, so the free parameter moves only as far as the path needs; where that window cannot
    reach the pose, the whole family is searched. Every sample is answered by :func:`~.ik.answer_ik`, as single IK
    is. Returns (results, free joints), one :class:`IKResult` per sample (nearest first), or None when the arm has
    no single free joint a family covers.
    """
    if requested is not None:
        joints = sorted(f.joint for f in free_joints_for(robot, requested))
        results, previous = [], reference
        for target in np.asarray(world_T_targets, dtype=float):
            ik.budget.check("the trajectory")
            result = _family_result(robot, target, requested, previous, ik)
            if result.solutions:
                previous = np.asarray(result.solutions[0].joints, dtype=float)
            results.append(result)
        return results, joints
    free = free_joints_for(robot, None)
    if free is None or len(free) != 1:
        return None
    joint = free[0].joint
    results = []
    previous = reference
    for target in np.asarray(world_T_targets, dtype=float):
        ik.budget.check("the trajectory")
        result = None
        if previous is not None and results:
            window = np.unique(np.clip(previous[joint] + np.linspace(-TRACK_WINDOW, TRACK_WINDOW, TRACK_SAMPLES),
                                       robot.lower[joint], robot.upper[joint]))
            result = _family_result(robot, target, [(joint, window.tolist(), None)], previous, ik)
        if result is None or not result.solutions:
            result = _family_result(robot, target, None, previous, ik)
        if result.solutions:
            previous = np.asarray(result.solutions[0].joints, dtype=float)
        results.append(result)
    return results, [joint]


def _family_result(robot: Robot, target: np.ndarray, free_joints: list | None, reference: np.ndarray | None,
                   ik: IKOptions) -> IKResult:
    """One pose of a redundant arm answered over its free joint (``free_joints`` as a request gives them, None
    for the default sampling), nearest the reference first."""
    answer = answer_ik(robot, IKTargets.poses(target[None]),
                       AnswerOptions(reference=reference, limits=unlimited(robot), filter_limits=False, search=ik,
                                     free_joints=free_joints, budget=ik.budget))
    return result_of(answer, 0)
