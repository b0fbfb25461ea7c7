"""answer_ik: one columnar IK answer for a batch of targets of every kind, tested on the core directly."""

from __future__ import annotations

import numpy as np

from service.config import Settings
from service.kinematics import Limits, forward_kinematics
from service.kinematics.ik import DIRECTION, POSE, POSITION, AnswerOptions, IKTargets, answer_ik
from service.robots.catalogue import load_catalogue
from tests.arms import published_arm

PUMA = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get("puma560_standard").robot
TOOL_AXIS = np.array([0.0, 1.0, 0.0])


def _targets(robot, q: np.ndarray, kinds: list[int]) -> IKTargets:
    """Targets made by FK from joint vectors q (N, n): a direction row asks for the tool's y axis."""
    T = forward_kinematics(robot, q)
    axes = np.tile(TOOL_AXIS, (len(q), 1))
    return IKTargets(T, np.array(kinds), axes, T[:, :3, :3] @ TOOL_AXIS)


def _row(targets: IKTargets, i: int) -> IKTargets:
    return IKTargets(targets.matrices[i:i + 1], targets.kinds[i:i + 1], targets.tool_axes[i:i + 1],
                     targets.world_directions[i:i + 1])


def _branches(table) -> list[dict]:
    return [{name: values[codes[k]] for name, (values, codes) in table.labels.items() if codes[k] >= 0}
            for k in range(len(table.target))]


def _assert_same_target(batch, single) -> None:
    """Two :class:`TargetAnswer` views agree in every field and every row."""
    for name in ("status", "detail", "solver", "singularities", "truncated", "trimmed", "available"):
        assert getattr(batch, name) == getattr(single, name), name
    for kind in ("solutions", "rejected"):
        a, b = getattr(batch, kind), getattr(single, kind)
        np.testing.assert_array_equal(a.joints, b.joints)
        np.testing.assert_array_equal(a.within_limits, b.within_limits)
        np.testing.assert_array_equal(a.position, b.position)
        np.testing.assert_array_equal(a.orientation, b.orientation)
        assert _branches(a) == _branches(b)


def test_mixed_kinds_in_one_batch_each_row_as_if_alone():
    robot = published_arm("widowx250_like")
    q = np.random.default_rng(7).uniform(-np.pi, np.pi, (6, robot.dof))
    targets = _targets(robot, q, [POSE, POSITION, DIRECTION, POSE, DIRECTION, POSITION])
    answer = answer_ik(robot, targets, AnswerOptions(filter_limits=False))
    assert np.all(np.diff(answer.solutions.target) >= 0)  # rows grouped by target
    for i, kind in enumerate(targets.kinds.tolist()):
        view = answer.target(i)
        _assert_same_target(view, answer_ik(robot, _row(targets, i), AnswerOptions(filter_limits=False)).target(0))
        assert view.status == "ok" and len(view.solutions.target) > 0
        reached = forward_kinematics(robot, view.solutions.joints)
        np.testing.assert_allclose(reached[:, :3, 3], np.broadcast_to(targets.matrices[i, :3, 3], (len(reached), 3)),
                                   atol=1e-6)
        if kind == POSE:
            np.testing.assert_allclose(reached, np.broadcast_to(targets.matrices[i], reached.shape), atol=1e-6)
        if kind == DIRECTION:
            np.testing.assert_allclose(reached[:, :3, :3] @ TOOL_AXIS,
                                       np.broadcast_to(targets.world_directions[i], (len(reached), 3)), atol=1e-6)
        # a position-only row's orientation residual means nothing: NaN; the other kinds give one
        assert np.isnan(view.solutions.orientation).all() == (kind == POSITION)


def test_numeric_rows_enter_the_same_tables_as_the_analytic_ones():
    robot = published_arm("iiwa14")
    q = np.array([[0.3, 0.5, -0.7, 1.1, 0.2, -0.4, 0.9]] * 2)
    targets = _targets(robot, q, [POSITION, POSE])
    # q4 locked leaves no closed-form family: the full pose goes to the numeric search; the position alone is
    # solved in closed form with the extra joints held at the reference
    options = AnswerOptions(reference=q[0], filter_limits=False, free_joints=[(3, [float(q[0, 3])], None)])
    answer = answer_ik(robot, targets, options)
    methods = [answer.solvers[i].method for i in answer.solver.tolist()]
    assert methods == ["analytic", "numeric"]
    assert "q4 locked" in answer.detail[1]
    assert set(answer.solutions.target.tolist()) == {0, 1}
    numeric = answer.target(1).solutions
    reached = forward_kinematics(robot, numeric.joints)
    np.testing.assert_allclose(reached, np.broadcast_to(targets.matrices[1], reached.shape), atol=1e-6)
    assert np.all(np.isfinite(numeric.orientation))


def test_a_position_the_held_joints_miss_is_searched_over_every_joint_in_the_same_tables():
    robot = published_arm("iiwa14")
    q = np.array([[0.3, 0.5, -0.7, 1.1, 0.2, -0.4, 0.9], [0.0] * 7])
    targets = _targets(robot, q, [POSITION, POSE])
    answer = answer_ik(robot, targets, AnswerOptions(filter_limits=False))  # held at 0: q[0]'s point is missed
    searched = answer.target(0)
    assert searched.solver.method == "numeric" and "held at the reference values" in searched.detail
    assert searched.status == "ok" and answer.target(1).solver.method == "analytic"
    reached = forward_kinematics(robot, searched.solutions.joints)[:, :3, 3]
    np.testing.assert_allclose(reached, np.broadcast_to(targets.matrices[0, :3, 3], reached.shape), atol=1e-6)
    assert set(answer.solutions.target.tolist()) == {0, 1}


def _fits(robot, limits: Limits, q: np.ndarray) -> np.ndarray:
    """Whether each joint of q (S, n) has a value q + 2kπ (revolute) or q itself (prismatic) within its limits,
    tolerance included, by trying every whole turn that could matter."""
    tolerance = limits.tolerance(robot)
    turns = np.arange(-6, 7)[:, None, None] * 2 * np.pi * robot.is_revolute
    shifted = q[None] + turns
    return np.any((shifted >= limits.lower - tolerance) & (shifted <= limits.upper + tolerance), axis=0)


def test_rejected_rows_name_exactly_the_joints_no_turn_brings_within_the_limits():
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (120, 6))
    targets = IKTargets.poses(forward_kinematics(PUMA, q))
    limits = Limits.of(PUMA)
    answer = answer_ik(PUMA, targets, AnswerOptions(limits=limits))
    rejected = answer.rejected
    assert len(rejected.target) > 0 and not rejected.within_limits.any()
    fits = _fits(PUMA, limits, rejected.joints)
    np.testing.assert_array_equal(answer.rejected_violations, ~fits)
    assert answer.rejected_violations.any(axis=1).all()
    assert _fits(PUMA, limits, answer.solutions.joints).all() and not answer.solution_violations.any()
    # with filter_limits false the same rows stay among the solutions, flagged with the same violations
    unfiltered = answer_ik(PUMA, targets, AnswerOptions(limits=limits, filter_limits=False))
    outside = ~unfiltered.solutions.within_limits
    assert outside.sum() == len(rejected.target) and len(unfiltered.rejected.target) == 0
    np.testing.assert_array_equal(unfiltered.solution_violations[outside], ~_fits(PUMA, limits,
                                                                                  unfiltered.solutions.joints[outside]))
    assert not unfiltered.solution_violations[~outside].any()


def _first_appearance(numbers: list[int]) -> bool:
    """Whether each number is at most one more than every number before it (0, 0, 1, 0, 2, …)."""
    seen = -1
    for number in numbers:
        if number > seen + 1:
            return False
        seen = max(seen, number)
    return True


def test_solvers_and_singularity_reports_are_numbered_by_first_appearance():
    rng = np.random.default_rng(11)
    q = rng.uniform(-np.pi, np.pi, (8, 6))
    q[[2, 5], 4] = 0.0  # wrist singular: q4 and q6 turn about one axis
    kinds = [POSITION, POSE, POSE, POSITION, POSE, POSE, POSITION, POSE]
    targets = IKTargets(forward_kinematics(PUMA, q), np.array(kinds))
    answer = answer_ik(PUMA, targets, AnswerOptions(filter_limits=False))
    assert len(answer.solvers) == 2 and _first_appearance(answer.solver.tolist())
    assert answer.solvers[0].structure != answer.solvers[1].structure  # position only, then full pose
    flat = [index for indices in answer.singularities for index in indices]
    assert answer.singularity_reports and _first_appearance(flat)
    assert sorted(set(flat)) == list(range(len(answer.singularity_reports)))
    for i in (2, 5):
        single = answer_ik(PUMA, IKTargets(targets.matrices[i:i + 1], targets.kinds[i:i + 1]),
                           AnswerOptions(filter_limits=False)).target(0)
        assert answer.target(i).singularities == single.singularities
        assert any(s.joints == (3, 5) and s.relation == "sum" for s in single.singularities)  # only q4 + q6 is fixed


def test_a_redundant_arms_family_stops_at_the_requests_budget():
    """The free-joint family solved every target without the request's budget, so a deadline was first seen at the
    selection, after all of them (200 xArm 7 targets: a 503 at 8.6 s on a 5 s deadline). A cancelled budget
    now stops it before its first target."""
    import pytest

    from service.kinematics import Budget, BudgetExhausted

    robot = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get("kuka_iiwa14").robot
    targets = _targets(robot, np.full((3, 7), 0.3), [POSE] * 3)
    budget = Budget(None)
    budget.cancel()
    with pytest.raises(BudgetExhausted) as stopped:
        answer_ik(robot, targets, AnswerOptions(budget=budget))
    assert stopped.value.stage == "the free-joint family"


def test_every_detail_at_once_is_each_detail_read_alone():
    """detail_list (what the batch encoders read) words every target as details() does one by one: with limits
    that reject some targets' solutions, flagged rows, capped equivalents and targets out of reach."""
    from service.api.boundary import WIRE_NOTES

    worded = set()
    q = np.random.default_rng(11).uniform(-np.pi, np.pi, (60, PUMA.dof))
    T = forward_kinematics(PUMA, q)
    T[::7, :3, 3] *= 5.0  # out of reach
    for options in (AnswerOptions(), AnswerOptions(filter_limits=False), AnswerOptions(max_equivalents=1),
                    AnswerOptions(limits=Limits(np.full(6, -2 * np.pi), np.full(6, 2 * np.pi)), max_equivalents=3)):
        answer = answer_ik(PUMA, IKTargets.poses(T), options)
        for wording in ({}, WIRE_NOTES):
            alone = list(answer.details(wording)) if wording else list(answer.details())
            at_once = answer.detail_list(wording) if wording else answer.detail_list()
            assert at_once == alone
        worded.update(detail is not None for detail in alone)
    assert worded == {True, False}
