"""Cached plans hold no per-call state (issue 23, item 3): one robot's cached plan, answered from 8 threads at once
with different targets, gives every thread exactly the answer the same call gives alone.

A plan that kept a call's intermediate results on itself (the one-pose path's slots, its validity mask, its label
quantities) would hand one thread's values to another: the answers would differ, not merely in their last digits.
Each family that keeps a plan is covered: the spherical wrist (PUMA, with its scalar one-pose path), three
parallel axes (UR5), the offset shoulder (KUKA KR6), the general 6R (xArm 6), and single and batch calls.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, cached_plan, plan_for
from service.kinematics.ik._positioning import POSITIONERS, Positioner
from service.kinematics.ik._types import Sealed
from tests.arms import PUBLISHED_ARMS, published_arm
from tests.conftest import catalogue_robot
from tests.ik_helpers import random_configurations

ARMS = ["puma560_standard", "ur5", "kuka_kr6_r900_2", "ufactory_xarm6"]
THREADS = 8
ROUNDS = 6


def _fingerprint(answer) -> tuple:
    """What an answer says, exactly: every kept and rejected row's target, joints, residuals and labels, each
    target's status and solver (with its promise), and its singular conditions."""
    def table(rows) -> tuple:
        labels = tuple((name, values, codes.tobytes()) for name, (values, codes) in sorted(rows.labels.items()))
        return (rows.target.tobytes(), rows.joints.tobytes(), rows.position.tobytes(), rows.orientation.tobytes(),
                labels)
    return (table(answer.solutions), table(answer.rejected), answer.status.tolist(), answer.solver.tolist(),
            tuple(answer.solvers), repr(answer.singularity_reports))


@pytest.mark.parametrize("robot_id", ARMS)
@pytest.mark.parametrize("batch", [1, 16], ids=["single", "batch"])
def test_one_cached_plan_answers_eight_threads_as_it_answers_each_alone(client, robot_id, batch):
    robot = catalogue_robot(client, robot_id)
    assert cached_plan(robot, constrain_orientation=True, reference=None) is not None  # built, kept, shared
    options = AnswerOptions()
    work = []  # per thread: ROUNDS target sets of ``batch`` poses each, different in every thread and round
    for thread in range(THREADS):
        q = random_configurations(robot, ROUNDS * batch, seed=100 * thread + batch)
        poses = forward_kinematics(robot, q).reshape(ROUNDS, batch, 4, 4)
        work.append([IKTargets.poses(p) for p in poses])
    alone = [[_fingerprint(answer_ik(robot, targets, options)) for targets in rounds] for rounds in work]

    together: list[list] = [[] for _ in range(THREADS)]
    start = threading.Barrier(THREADS)

    def run(thread: int) -> None:
        start.wait()
        for targets in work[thread]:
            together[thread].append(_fingerprint(answer_ik(robot, targets, options)))

    threads = [threading.Thread(target=run, args=(k,)) for k in range(THREADS)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert all(len(results) == ROUNDS for results in together)
    for thread in range(THREADS):
        assert together[thread] == alone[thread], f"thread {thread}: an answer changed when solved concurrently"


@pytest.mark.parametrize("robot_id", ARMS)
def test_a_kept_plan_and_its_parts_refuse_new_state(client, robot_id):
    """The kept plan is sealed with the parts it holds: a call that tried to keep something on it would raise
    instead of leaking into the next call."""
    plan = cached_plan(catalogue_robot(client, robot_id), constrain_orientation=True, reference=None)
    parts = [plan, *(value for value in vars(plan).values() if hasattr(value, "seal"))]
    for part in parts:
        with pytest.raises(AttributeError, match="shared once built"):
            part.last_targets = np.zeros((1, 4, 4))


#: standard-DH rows (a, alpha, d, theta) and joint kinds of small arms whose positioners the catalogue lacks
SMALL_ARMS = {
    "Cartesian": ([(0.2, 0.7, 0.3, 0.4), (0.3, -1.1, 0.2, -0.6), (0.1, 0.9, 0.4, 1.3)], "PPP"),
    "SkewAxes": ([(0.2, 0.7, 0.3, 0.4), (0.3, -1.1, 0.2, -0.6), (0.1, 0.9, 0.4, 1.3)], "RRR"),
    "SkewAxesWithSlide": ([(0.2, 0.7, 0.3, 0.4), (0.3, -1.1, 0.2, -0.6), (0.1, 0.9, 0.4, 1.3)], "RRP"),
    "OffsetShoulderIntersectingElbow": ([(0.2, 0.7, 0.3, 0.4), (0.0, -1.1, 0.2, -0.6), (0.1, 0.9, 0.4, 1.3)],
                                        "RRR"),
    "IntersectingPair": ([(0.0, 0.7, 0.3, 0.4), (0.3, -1.1, 0.2, -0.6)], "RR"),
}


def test_positioners_are_complete_when_their_constructor_returns(client, monkeypatch):
    """A positioning family's fit computes its constants and passes them to the constructor: nothing is set on a
    positioner once its constructor has returned (so a plan's parts are whole before they are sealed). Every
    positioner that the plans of the catalogue's arms, the published redundant and deficient arms and
    :data:`SMALL_ARMS` build, position-only and pose, is watched; every family is built at least once."""
    built: set[str] = set()

    def watched(family):
        construct = family.__init__

        def __init__(self, *args, **kwargs):
            construct(self, *args, **kwargs)
            if type(self) is family:
                object.__setattr__(self, "_constructed", True)
                built.add(family.__name__)
        return __init__

    def refuse_late(self, name, value):
        assert not vars(self).get("_constructed"), f"{type(self).__name__}.{name} set after its constructor"
        Sealed.__setattr__(self, name, value)

    for family in POSITIONERS:
        monkeypatch.setattr(family, "__init__", watched(family))
    monkeypatch.setattr(Positioner, "__setattr__", refuse_late)
    kind_names = {"R": "revolute", "P": "prismatic"}
    robots = [entry.robot for entry in client.app.state.catalogue.entries()]
    robots += [published_arm(name) for name in PUBLISHED_ARMS if not name.startswith("_")]
    robots += [Robot([Joint(f"j{i + 1}", kind_names[kind], *row) for i, (row, kind) in enumerate(zip(rows, kinds))])
               for rows, kinds in SMALL_ARMS.values()]
    for robot in robots:
        for constrain_orientation in (True, False):
            plan_for(robot, constrain_orientation=constrain_orientation, reference=None)
    assert built == {family.__name__ for family in POSITIONERS}
