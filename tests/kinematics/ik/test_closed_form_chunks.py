"""A batch larger than a chunk is split into chunks of one size, as many as a multiple of the threads, and its
answer does not depend on the split: the same table, bit for bit, on 1, 2 or 3 threads."""

from __future__ import annotations

import numpy as np
import pytest

from service.config import Settings
from service.kinematics import forward_kinematics
from service.kinematics.ik import _closed_form
from service.kinematics.ik._closed_form import cached_plan, chunk_edges, solve_closed_form
from service.kinematics.ik._goals import PoseGoal
from service.robots.catalogue import load_catalogue

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


@pytest.mark.parametrize("n_targets, threads", [(10_000, 2), (10_000, 1), (10_000, 4), (4_097, 2), (8_192, 2),
                                                (123_457, 3), (40_000, 16)])
def test_chunks_are_even_and_a_multiple_of_the_threads(n_targets, threads):
    edges = chunk_edges(n_targets, threads)
    sizes = np.diff(edges)
    assert edges[0] == 0 and edges[-1] == n_targets
    assert sizes.max() <= _closed_form.CHUNK and sizes.max() - sizes.min() <= 1
    fewest = -(-n_targets // _closed_form.CHUNK)
    assert len(sizes) >= fewest
    assert len(sizes) % min(threads, fewest) == 0  # each thread gets as many chunks


def test_ten_thousand_poses_on_two_threads_are_four_chunks_of_2500():
    assert chunk_edges(10_000, 2) == [0, 2_500, 5_000, 7_500, 10_000]


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "kuka_kr6_r900_2"])
def test_the_answer_does_not_depend_on_the_split(robot_id, monkeypatch):
    robot = CATALOGUE.get(robot_id).robot
    q = np.random.default_rng(21).uniform(-np.pi, np.pi, (1_000, robot.dof))
    goal = PoseGoal(forward_kinematics(robot, q))
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    whole = solve_closed_form(robot, plan, goal, None)  # one chunk
    monkeypatch.setattr(_closed_form, "CHUNK", 96)
    monkeypatch.setattr(type(plan), "targets_per_chunk", 96, raising=False)  # these families' own chunk
    for threads in (1, 2, 3):
        split = solve_closed_form(robot, plan, goal, None, threads=threads)
        for name in ("target", "joints", "within_limits", "position", "orientation"):
            assert getattr(split.table, name).tobytes() == getattr(whole.table, name).tobytes(), (threads, name)
        assert {k: (v, c.tobytes()) for k, (v, c) in split.table.labels.items()} == {
            k: (v, c.tobytes()) for k, (v, c) in whole.table.labels.items()}
        np.testing.assert_array_equal(split.complete, whole.complete)
        np.testing.assert_array_equal(split.nearest, whole.nearest)


@pytest.mark.parametrize("robot_id, chunk", [("puma560_standard", 8_192), ("ur5", 8_192), ("kuka_kr6_r900_2", 8_192),
                                             ("ufactory_xarm6", 256)])
def test_a_family_solves_its_own_chunk_of_targets(robot_id, chunk, monkeypatch):
    """The lean families (a few dozen numbers per target) solve twice the default at once, the general 6R 256 (a
    fraction of a millisecond each: chunks the budget can stop between); a batch is cut into chunks of at most the
    plan's size, on as many threads as the default would keep busy."""
    robot = CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    assert getattr(plan, "targets_per_chunk", _closed_form.CHUNK) == chunk
    sizes = []
    solved = _closed_form._solved
    monkeypatch.setattr(_closed_form, "_solved", lambda robot, plan, goal, reference: (
        sizes.append(len(goal)), solved(robot, plan, goal, reference))[1])
    monkeypatch.setattr(_closed_form, "CHUNK", 96)
    monkeypatch.setattr(type(plan), "targets_per_chunk", 300, raising=False)
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, (1_000, robot.dof))
    answer = solve_closed_form(robot, plan, PoseGoal(forward_kinematics(robot, q)), None, threads=2)
    assert sorted(sizes) == [250] * 4 and len(answer.complete) == 1_000


def test_a_larger_chunk_keeps_the_threads_busy():
    """A lean family's larger chunk makes fewer chunks, never fewer threads than the default chunk would use."""
    chunk = 2 * _closed_form.CHUNK
    assert chunk_edges(10_000, 2, chunk) == [0, 5_000, 10_000]
    assert len(chunk_edges(6_000, 2, chunk)) - 1 == 2  # one call of 6,000 would leave a core idle
    assert len(chunk_edges(50_000, 16, chunk)) - 1 == len(chunk_edges(50_000, 16)) - 1 == 13


def test_a_batch_of_several_chunks_runs_them_on_threads(monkeypatch):
    """The chunks of a batch go to a pool of as many threads as chunks can keep busy (two here)."""
    robot = CATALOGUE.get("puma560_standard").robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    pools = []
    pool = _closed_form.ThreadPoolExecutor
    monkeypatch.setattr(_closed_form, "ThreadPoolExecutor", lambda workers: (pools.append(workers), pool(workers))[1])
    monkeypatch.setattr(_closed_form, "CHUNK", 96)
    monkeypatch.setattr(type(plan), "targets_per_chunk", 300)
    q = np.random.default_rng(6).uniform(-np.pi, np.pi, (1_000, robot.dof))
    solve_closed_form(robot, plan, PoseGoal(forward_kinematics(robot, q)), None, threads=2)
    assert pools == [2]


def test_a_general_6r_batch_is_checked_against_its_budget_every_few_hundred_targets():
    """1,000 targets of the xArm 6 (~0.3–0.6 ms each) were one chunk, one budget check before ~0.5 s of work: a
    request whose deadline a client lowered to 100 ms answered its 503 at 0.75 s. Its chunks of 256 are checked
    each, and the answer is the one chunk's."""
    from service.kinematics._budget import Budget

    class Counting(Budget):
        checks = 0

        def check(self, stage: str) -> None:
            Counting.checks += 1
            super().check(stage)

    robot = CATALOGUE.get("ufactory_xarm6").robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    q = np.random.default_rng(6).uniform(-np.pi, np.pi, (1_000, robot.dof))
    goal = PoseGoal(forward_kinematics(robot, q))
    answer = solve_closed_form(robot, plan, goal, None, threads=2, budget=Counting())
    assert Counting.checks == len(chunk_edges(1_000, 2, 256)) - 1 >= 4
    assert len(answer.complete) == 1_000 and answer.table.target.max() == 999
