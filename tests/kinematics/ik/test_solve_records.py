"""The library's records (ik/_solve.py): ``solve_ik`` of one pose, which answers from the closed form alone where
it promises every solution, against the record of the whole answer (``answer_ik`` with no limits, then
``results_of``), field by field, on every catalogue arm and on random arms of the closed-form families."""

from unittest import mock

import numpy as np
import pytest

from service.config import Settings
from service.kinematics.ik import (AnswerOptions, IKResult, IKTargets, answer_ik, result_of, results_of, solve_ik,
                                   solve_ik_batch, unlimited)
from service.kinematics.ik import _solve
from service.kinematics.ik._solve import _closed_form_result
from service.robots.catalogue import load_catalogue
from tests.arms import random_family_arm, random_three_parallel_arm
from tests.ik_helpers import mixed_poses

_CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
CATALOGUE_IDS = sorted(entry.description.id for entry in _CATALOGUE.entries())


def _answered(robot, T: np.ndarray) -> IKResult:
    """The record of the whole answer for one pose: answer_ik with no limits and no filter, as solve_ik_batch."""
    answer = answer_ik(robot, IKTargets.poses(T[None]), AnswerOptions(limits=unlimited(robot), filter_limits=False))
    return results_of(answer)[0]


def _assert_same(record: IKResult, expected: IKResult) -> None:
    assert (record.status, record.method, record.structure, record.complete, record.free_joints, record.detail,
            record.search_exhausted_budget) == (expected.status, expected.method, expected.structure,
                                                expected.complete, expected.free_joints, expected.detail,
                                                expected.search_exhausted_budget)
    assert record.singularities == expected.singularities
    assert len(record.solutions) == len(expected.solutions)
    for mine, theirs in zip(record.solutions, expected.solutions):
        assert np.array_equal(mine.joints, theirs.joints)
        assert mine.joints.tobytes() == theirs.joints.tobytes()  # signed zeros too
        assert (mine.branch, mine.position_residual, mine.orientation_residual) == \
            (theirs.branch, theirs.position_residual, theirs.orientation_residual)


def _check(robot, poses: np.ndarray) -> int:
    """Compare every pose; return how many solve_ik answered by its shortcut (the closed form's own record)."""
    shortcut = []

    def counted(*args):
        record = _closed_form_result(*args)
        shortcut.append(record is not None)
        return record

    with mock.patch.object(_solve, "_closed_form_result", counted):
        for T in poses:
            record = solve_ik(robot, T)
            _assert_same(record, _answered(robot, T))
    return sum(shortcut)


@pytest.mark.parametrize("robot_id", CATALOGUE_IDS)
def test_solve_ik_is_the_answers_record_on_the_catalogue(robot_id):
    robot = _CATALOGUE.get(robot_id).robot
    poses = mixed_poses(robot, 24, seed=len(robot_id))
    own = _check(robot, poses)
    if robot.dof <= 6 and robot_id.startswith(("puma", "ur5", "kuka_kr6")):
        assert own >= len(poses) // 2  # the shortcut is taken on these arms: the comparison is not vacuous


@pytest.mark.parametrize("family", ["intersecting_shoulder+spherical_wrist",
                                    "offset_shoulder_parallel_elbow+spherical_wrist", "three_parallel"])
@pytest.mark.parametrize("convention", ["standard", "modified", "khalil"])
def test_solve_ik_is_the_answers_record_on_random_arms(family, convention):
    for seed in range(3):
        robot = random_family_arm(family, convention, seed, wrist_singular=seed == 2)
        assert _check(robot, mixed_poses(robot, 12, seed)) > 0


@pytest.mark.parametrize("case", ["skew_wrist_234", "at_end_456_with_1_2_intersecting", "at_base_123_with_5_6_intersecting"])
def test_solve_ik_is_the_answers_record_on_other_three_parallel_arms(case):
    robot = random_three_parallel_arm(case, "standard", 7)
    assert _check(robot, mixed_poses(robot, 12, 3)) > 0


def test_records_of_a_batch_are_each_targets_record():
    robot = _CATALOGUE.get("puma560_standard").robot
    poses = mixed_poses(robot, 30, 11)
    answer = answer_ik(robot, IKTargets.poses(poses), AnswerOptions(limits=unlimited(robot), filter_limits=False))
    every = results_of(answer)
    assert len(every) == len(poses)
    for row, record in enumerate(every):
        _assert_same(record, result_of(answer, row))
    for record, batch_record in zip(every, solve_ik_batch(robot, poses)):
        _assert_same(record, batch_record)
    assert {record.status for record in every} == {"ok", "unreachable"}


@pytest.mark.parametrize("rows", [1, 7, 256, 257, 500])
def test_branches_word_each_rows_labels_on_both_sides_of_the_few_rows_path(rows):
    """SolutionTable.branches (a few rows, hundreds, the sizes its former few-rows path switched at): each row's
    dict names exactly its labels whose code is not −1; with ``own`` each row's dict is its own object."""
    from service.kinematics.ik._table import SolutionTable
    rng = np.random.default_rng(rows)
    labels = {name: (values, rng.integers(-1, len(values), rows).astype(np.int8))
              for name, values in (("shoulder", ("left", "right")), ("elbow", ("up", "down")),
                                   ("assembly_mode", (1, 2, 3)))}
    table = SolutionTable(np.zeros(rows, dtype=np.int64), np.zeros((rows, 6)), np.ones(rows, dtype=bool),
                          np.zeros(rows), np.zeros(rows), labels)
    expected = [{name: values[codes[k]] for name, (values, codes) in labels.items() if codes[k] >= 0}
                for k in range(rows)]
    assert table.branches() == expected
    own = table.branches(own=True)
    assert own == expected and len({id(branch) for branch in own}) == rows


def test_one_pose_rows_word_every_code_combination_as_the_table_does():
    """OnePoseRows.branches reads each row's dict from the family's combinations (branch_labels): for every
    combination of codes it names what the table would, and each row's dict is its own (changing one changes
    no other row and no later answer)."""
    import itertools
    from service.kinematics.ik._verify import OnePoseRows
    names, values = ("shoulder", "elbow", "wrist"), (("left", "right"), ("up", "down"), ("no_flip", "flip"))
    codes = list(itertools.product(range(2), repeat=3)) * 2
    rows = OnePoseRows([[0.0] * 6] * len(codes), [(0.0, 0.0)] * len(codes), codes, names, values)
    expected = [{name: labels[code] for name, labels, code in zip(names, values, row)} for row in codes]
    branches = rows.branches()
    assert branches == rows.table(6).branches(own=True) == expected
    branches[0]["shoulder"] = "changed"
    assert rows.branches() == expected and len({id(branch) for branch in branches}) == len(codes)
