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

from service.kinematics import forward_kinematics
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, cached_plan
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
