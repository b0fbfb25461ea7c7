"""A decoupled plan labels each run of rows that share the positioning joints once (the wrist's slots of one arm
branch) from a batch's size on: its labels must equal the positioner's and the wrist's labellers run on every row
alone, below that size and above it (the bound lowered), whatever the rows' order, with or without the cos and sin the FK check shares (a JointTrig, taken for the runs), on random arms
of both decoupled families in every convention and on catalogue arms of both."""

from __future__ import annotations

import numpy as np
import pytest

from service.config import Settings
from service.kinematics import CONVENTIONS, forward_kinematics
from service.kinematics._forward import JointTrig
from service.kinematics.ik import _decoupled, cached_plan
from service.robots.catalogue import load_catalogue
from tests.arms import random_family_arm
from tests.ik_helpers import random_configurations

FAMILIES = ("intersecting_shoulder+spherical_wrist", "offset_shoulder_parallel_elbow+spherical_wrist")
CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


def _row_by_row(plan, rows: np.ndarray) -> dict:
    """The positioner's and the wrist's labels of each row on its own (no runs, no shared trig)."""
    codes = {}
    for part in (plan.positioner, plan.wrist):
        for row in rows:
            for name, (values, code) in part.label_codes(row[None]).items():
                codes.setdefault(name, (values, []))[1].append(int(code[0]))
    return {name: (values, np.array(column)) for name, (values, column) in codes.items()}


def _assert_same(got: dict, expected: dict) -> None:
    assert set(got) == set(expected)
    for name, (values, codes) in expected.items():
        assert tuple(got[name][0]) == tuple(values)
        np.testing.assert_array_equal(got[name][1], codes)


def _assert_runs_labelled_alone(robot, plan, rng, monkeypatch) -> None:
    for runs_from in (_decoupled._RUNS_FROM, 2):  # a batch's few rows labelled each, and as runs
        monkeypatch.setattr(_decoupled, "_RUNS_FROM", runs_from)
        _assert_labelled_alone(robot, plan, rng)


def _assert_labelled_alone(robot, plan, rng) -> None:
    targets = forward_kinematics(robot, random_configurations(robot, 6, seed=3))
    candidates = plan.solve(targets, None)
    rows = np.nan_to_num(candidates.joints.reshape(-1, robot.dof))
    k = len(plan.positioner.joints)
    assert (rows[1::2, :k] == rows[::2, :k]).all()  # the runs the shortcut relies on are there
    rows[5, 1] += np.pi  # a row that left its run (a joint its labels read changed)
    rows[7, 0] = np.nan
    for order in (np.arange(len(rows)), rng.permutation(len(rows))):
        expected = _row_by_row(plan, rows[order])
        _assert_same(plan.label_codes(rows[order]), expected)
        trig = JointTrig(rows[order])
        for joint in range(robot.dof):  # as after the FK check: every pair computed
            trig[joint]
        _assert_same(plan.label_codes(rows[order], trig), expected)


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("convention", CONVENTIONS)
def test_runs_are_labelled_as_each_row_alone(family, convention, monkeypatch):
    seed = 100 * FAMILIES.index(family) + CONVENTIONS.index(convention)
    robot = random_family_arm(family, convention, seed)
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    assert plan.structure == family
    _assert_runs_labelled_alone(robot, plan, np.random.default_rng(seed), monkeypatch)


@pytest.mark.parametrize("robot_id", ["puma560_khalil", "kuka_kr6_r900_2", "abb_irb120"])
def test_runs_are_labelled_as_each_row_alone_on_catalogue_arms(robot_id, monkeypatch):
    robot = CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    assert plan.structure in FAMILIES
    _assert_runs_labelled_alone(robot, plan, np.random.default_rng(1), monkeypatch)
