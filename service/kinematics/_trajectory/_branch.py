"""Branch choice, sample by sample (the rules of :mod:`service.kinematics._trajectory`): held labels, the labels
a singularity makes ambiguous, the solution nearest the prediction, when the choice is open and when the branch
was left."""

from __future__ import annotations

import numpy as np

from .._limits import Limits, nearest_fitting_equivalent, within
from .._robot import Robot
from .._tolerances import ACCEPT_RESIDUAL, DUPLICATE_TOLERANCE
from ..ik import IKOptions, IKResult, Singularity, solve_ik
from ._continuation import (
    TRACK_NEWTON_STEPS,
    Tracking,
    _continued,
    _distance,
    _listed_rates,
    _newton,
    _polish,
    _prediction,
    _rates_at,
    _Reached,
)
from ..collision import CollisionRequest
from ._collisions import collision_free_pool, forced_by_collision, listed_collisions
from ._records import SampleResult

#: The branch labels that a singularity of each kind makes ambiguous (their two values meet there). With the
#: point on the first axis (shoulder "free") the line from the shoulder to the point is that axis, so the
#: elbow's side of it is undefined as well.
LABEL_OF_SINGULARITY = {"shoulder": ("shoulder",), "elbow": ("elbow",), "wrist": ("wrist",),
                        "assur_group": ("assembly_mode",)}
_FREE_SHOULDER_LABELS = ("shoulder", "elbow")


def ambiguous_labels(singularities: list[Singularity]) -> set[str]:
    """The branch labels that do not tell the branches apart at a sample with these singular conditions."""
    labels: set[str] = set()
    for s in singularities:
        labels.update(_FREE_SHOULDER_LABELS if (s.kind, s.relation) == ("shoulder", "free")
                      else LABEL_OF_SINGULARITY.get(s.kind, ()))
    return labels


#: Singularity relations under which the IK sets a free joint (to the reference, here the previous sample).
_FREE_RELATIONS = frozenset({"free", "sum", "difference", "signed_sum", "coincident"})


def _has_free_joint(result: IKResult) -> bool:
    return any(s.relation in _FREE_RELATIONS for s in result.singularities)


#: A second solution within this factor of the chosen one's distance to the prediction leaves the choice open.
AMBIGUITY_FACTOR = 2.0
#: The chosen solution is off the branch when it is farther from the prediction than this many joint steps.
JUMP_FACTOR = 4.0
#: The prediction is carried onto the pose by Newton steps when no solution of the IK is within this many joint
#: steps of it (or the choice is ambiguous).
TRACK_FACTOR = 0.5
#: Two solutions closer than this (Euclidean, radians or fractions of the robot's size) are one: at a fold
#: (two solutions meeting) the residual grows with the square of the distance, so the FK check accepts a band
#: of about √ACCEPT_RESIDUAL around the solution.
SAME_SOLUTION = float(np.sqrt(ACCEPT_RESIDUAL))


def _labels_of(label_codes, q: np.ndarray) -> dict:
    """The IK's branch labels of one joint vector (n,) (a label whose branches meet there is left out)."""
    if label_codes is None:
        return {}
    return {name: values[int(codes[0])] for name, (values, codes) in label_codes(q[None]).items() if codes[0] >= 0}


def _follow(robot: Robot, times: np.ndarray, targets: np.ndarray, results: list[IKResult], held: dict,
            reference: np.ndarray | None, limits: Limits, constrain_orientation: bool,
            ik_options: IKOptions, tracking: Tracking | None = None,
            collisions: CollisionRequest | None = None) -> list[SampleResult]:
    """Choose one solution per sample (the branch rules of the module docstring).

    Each sample after the first takes the solution nearest to the previous sample's joints carried forward
    (:func:`_prediction`): the continuous branch, whatever its labels. With ``tracking`` the prediction is also
    carried onto the pose by Newton steps, which adds the branch's solution where the IK's answer lacks it, and
    the chosen solution is polished by Newton steps to the end of its digits (near a singularity a closed form
    or a search stops at a residual that leaves the joints off by residual / σmin). A sample whose solution is
    not clearly the continuation (another solution about as near the prediction, or none within a few joint
    steps of it) reports ``branch_changed``, as one whose labels differ from the previous sample's does.
    ``collisions`` with its filter keeps the path on collision-free solutions (:mod:`._collisions`).
    """
    weights = np.where(robot.is_revolute, 1.0, 1.0 / robot.characteristic_length)
    moving = np.ones(robot.dof, dtype=bool)
    if tracking is not None:
        moving = np.zeros(robot.dof, dtype=bool)
        moving[tracking.task.columns] = True
    floor = DUPLICATE_TOLERANCE
    history: list[_Reached] = []  # the continuous stretch of reached samples that the next one continues
    to_polish: list[tuple[int, int, list[np.ndarray], np.ndarray]] = []
    listed_rates = _listed_rates(robot, results, tracking)
    listed_hits = listed_collisions(robot, collisions, results)
    previous_branch: dict | None = None
    samples: list[SampleResult] = []
    for k, result in enumerate(results):
        if k % 64 == 0:
            ik_options.budget.check("the trajectory")
        previous = history[-1] if history else None
        predicted, scale = (reference, None) if previous is None else _prediction(history, float(times[k]),
                                                                                  weights)
        rates_of = None if listed_rates is None else listed_rates[k]
        known_hits = None if listed_hits is None else listed_hits[k]
        if previous is not None and _has_free_joint(result):
            # the joint the pose leaves free keeps the previous sample's value
            result = solve_ik(robot, targets[k], constrain_orientation=constrain_orientation, reference=previous.q,
                              options=ik_options)
            rates_of = known_hits = None
        joints = np.array([s.joints for s in result.solutions], dtype=float).reshape(-1, robot.dof)
        branches = [dict(s.branch) for s in result.solutions]
        ambiguous = ambiguous_labels(result.singularities)
        to_prediction = None if predicted is None else _distance(robot, joints, predicted, weights)
        tracked = None
        if tracking is not None and previous is not None and not _has_free_joint(result) and _unclear(
                to_prediction[_matching(branches, held, ambiguous)] if held else to_prediction, scale):
            q_tracked, error = _newton(robot, targets[k], constrain_orientation, predicted, moving,
                                       TRACK_NEWTON_STEPS, ik_options.budget)
            if error <= ACCEPT_RESIDUAL:
                tracked = q_tracked
                if _distance(robot, joints, tracked, weights).min(initial=np.inf) > SAME_SOLUTION:
                    # the branch's solution, which the IK's answer lacks (a search near a singularity can miss it)
                    joints = np.vstack([joints, tracked])
                    branches.append(_labels_of(tracking.label_codes, tracked))
                    to_prediction = np.append(to_prediction, _distance(robot, tracked, predicted, weights))
        if not len(joints):
            # unreachable only where the solver proves it; a search that found nothing says not_found
            samples.append(SampleResult(float(times[k]), "unreachable" if result.complete else "not_found"))
            continue
        matching = _matching(branches, held, ambiguous)
        allowed = matching or list(range(len(joints)))
        collision = collision_free_pool(robot, collisions, joints, allowed, known_hits)
        pool = collision.pool
        forced = previous is not None and forced_by_collision(collision, allowed, to_prediction)
        distances = None
        choice = pool[0]
        if predicted is not None:
            distances = to_prediction[pool]
            choice = pool[int(np.argmin(distances))]
        q = joints[choice]
        if previous is not None:
            q = _continued(robot, limits, q, previous.q)
        elif reference is not None:
            q = _continued(robot, limits, q, reference)
        elif not within(robot, limits, q):
            fitting = nearest_fitting_equivalent(robot, limits, q)
            q = q if fitting is None else fitting
        if tracking is not None:
            # a joint the IK set free at this sample keeps its value: the polish moves only the determined ones
            polished = moving.copy()
            polished[[x.joints[0] for x in result.singularities if x.relation in _FREE_RELATIONS and x.joints]] = False
            starts = [q]
            if tracked is not None and _distance(robot, tracked, q, weights) <= SAME_SOLUTION:
                # the same solution carried along the path: near a fold it may be the more accurate of the two
                starts.append(_continued(robot, limits, tracked, q))
            to_polish.append((len(samples), k, starts, polished))
        branch = dict(branches[choice])
        # Where two branches meet, IK leaves their label out (or the singularity makes it ambiguous): the
        # trajectory carries the held label, or the previous sample's, through that sample.
        undefined = (ambiguous & branch.keys()) | ({*held, *(previous_branch or {})} - branch.keys())
        for key in undefined:
            if key in held:
                branch[key] = held[key]
            elif previous_branch is not None and key in previous_branch:
                branch[key] = previous_branch[key]
        left_branch = jumped = False
        if previous is not None and distances is not None:
            nearest = float(distances.min())
            apart = _distance(robot, joints[pool], joints[choice], weights) > SAME_SOLUTION
            if result.free_joints:  # members of a family over free joints: only another branch makes it unsure
                apart &= np.array([branches[i] != branches[choice] for i in pool], dtype=bool)
            others = distances[apart].tolist()
            # another solution about as near the prediction: which one continues the branch is not known
            unsure = any(d <= AMBIGUITY_FACTOR * nearest and d > SAME_SOLUTION for d in others)
            # no solution within a few joint steps of the prediction: the branch does not continue here (unless
            # the held labels chose the jump, which the summary's largest step shows)
            jumped = scale is not None and nearest > max(JUMP_FACTOR * scale, floor)
            left_branch = (jumped and not (held and matching)) or (unsure and not jumped)
        status = ("branch_unavailable" if held and not matching
                  else "no_collision_free_solution" if collision.blocked else "ok")
        samples.append(SampleResult(
            float(times[k]), status, q, branch=branch,
            branch_changed=previous is not None and (branch != previous_branch or left_branch or forced),
            singularities=list(result.singularities), collision_forced=forced))
        rates = (None, None)
        if rates_of is not None and choice < len(rates_of[0]):  # a listed solution: rates known (2π-invariant)
            rates = (rates_of[0][choice], rates_of[1][choice])
        elif tracking is not None and tracking.twists is not None and not np.isnan(tracking.twists[k]).all():
            rates = _rates_at(robot, q, tracking.twists[k], None if tracking.accelerations is None or np.isnan(
                tracking.accelerations[k]).all() else tracking.accelerations[k], tracking.task)
        if left_branch or jumped or forced:  # a jump is no base for extrapolating the next step
            history = []
        history = [*history[-2:], _Reached(q, float(times[k]), *rates)]
        previous_branch = branch
    if to_polish:
        _polish(robot, targets, samples, to_polish, constrain_orientation, ik_options)
    return samples


def _matching(branches: list[dict], held: dict, ambiguous: set[str]) -> list[int]:
    """Which solutions' labels agree with the held ones: a label the solution does not carry (its branches meet
    there) or that the sample's singularity makes ambiguous does not rule it out."""
    return [i for i, branch in enumerate(branches)
            if all(branch.get(key, value) == value or key in ambiguous for key, value in held.items())]


def _unclear(distances: np.ndarray, scale: float | None) -> bool:
    """Whether the IK's solutions leave the continuation open, from their distances (m,) to the prediction:
    none, none within half a joint step (the prediction is off the branch by O(dt²) at most), or a second one
    about as near. Then the prediction is carried onto the pose."""
    if not len(distances):
        return True
    distances = np.sort(distances)
    if scale is None or distances[0] > max(TRACK_FACTOR * scale, DUPLICATE_TOLERANCE):
        return True
    return len(distances) > 1 and distances[1] <= AMBIGUITY_FACTOR * distances[0] + SAME_SOLUTION
