"""A promise audit on arms with a coaxial pair anywhere (issue 22 item 1): FK-made targets are never
``unreachable``, and a ``complete`` answer holds the generating configuration.

Random planar (3 and 4 joints), spatial (5 and 6 joints) and redundant (7 joints) arms, stated in standard and
in modified DH, with joints i and i + 1 on one line (same or opposite sense) for every i, and the tool on the
last axis or off it. Targets are the arm's own FK at random joint vectors q, full poses and positions. With q as
the reference, a complete answer must list q itself (revolute joints modulo 2π): the joint a coaxial pair or a
position target leaves free takes the reference value. Without a reference a complete full-pose answer must
still hold q up to the split of the pair (``q_i ± q_j`` the same, every other joint equal). Every listed
solution must reproduce its target through the arm's FK.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik
from tests.ik_helpers import find, wrapped


def coaxial_arm(rng: np.random.Generator, dof: int, pair: int, convention: str, *, planar: bool,
                reversed_axes: bool, tool_on_last_axis: bool) -> Robot:
    """A random revolute arm whose joints ``pair`` and ``pair + 1`` (0-based) are coaxial.

    Standard DH puts the common normal from axis i to axis i + 1 in row i, modified DH in row i + 1: that row
    gets a = 0 and α = 0 (π for axes of opposite sense). A planar arm has every α = 0 (π at the pair when
    reversed), so every axis is ±z. ``tool_on_last_axis``: the tool point on the last joint's axis (standard:
    a_n = 0; modified: no tool offset) or 0.2–0.5 off it.
    """
    rows = []
    for _ in range(dof):
        alpha = 0.0 if planar else rng.uniform(-np.pi, np.pi)
        d = rng.uniform(-0.2, 0.2) if planar else rng.uniform(-0.5, 0.5)
        rows.append([rng.uniform(0.3, 1.0), alpha, d, rng.uniform(-np.pi, np.pi)])
    row = pair if convention == "standard" else pair + 1
    rows[row][:2] = [0.0, np.pi if reversed_axes else 0.0]
    tool = np.eye(4)
    if convention == "standard":
        rows[-1][0] = 0.0 if tool_on_last_axis else rows[-1][0]
    elif not tool_on_last_axis:
        tool[0, 3] = rng.uniform(0.2, 0.5)
    joints = [Joint(f"q{k + 1}", "revolute", *values) for k, values in enumerate(rows)]
    return Robot(joints, convention=convention, flange_T_tool=tool)


def _fk_residuals(robot: Robot, solutions: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """Largest position (length units) and rotation-matrix entry errors of the solutions' FK against target."""
    if not len(solutions):
        return 0.0, 0.0
    reached = forward_kinematics(robot, solutions)
    return (float(np.abs(reached[:, :3, 3] - target[:3, 3]).max()),
            float(np.abs(reached[:, :3, :3] - target[:3, :3]).max()))


def _split_free_match(robot: Robot, solutions: np.ndarray, q: np.ndarray, first: int, second: int,
                      sign: float) -> bool:
    """Whether a solution equals q up to the split of the coaxial pair: ``q_i ± q_j`` equal (mod 2π), every
    other joint equal (mod 2π)."""
    if not len(solutions):
        return False
    d = joint_difference(robot, solutions, q)
    combined = np.abs(wrapped(d[:, first] + sign * d[:, second]))
    others = np.abs(np.delete(d, [first, second], axis=1)).max(axis=1)
    return bool(np.any((combined <= 1e-7) & (others <= 1e-7)))


def audit(robot: Robot, q: np.ndarray, pair: int, reversed_axes: bool, constrain_orientation: bool) -> list[str]:
    """The broken promises of the answers for FK(q), with q and without a reference (empty when none)."""
    target = forward_kinematics(robot, q)
    broken = []
    for reference in (q, None):
        result = solve_ik(robot, target, constrain_orientation=constrain_orientation, reference=reference)
        where = (f"{'pose' if constrain_orientation else 'position'}, reference {'q' if reference is not None else 'none'}"
                 f": {result.status}, complete {result.complete}, {result.structure!r}")
        solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
        position, rotation = _fk_residuals(robot, solutions, target)
        if result.status == "unreachable":
            broken.append(f"unreachable ({where})")
        if position > 1e-9 * robot.characteristic_length or (constrain_orientation and rotation > 1e-9):
            broken.append(f"a solution misses the target by {position:.1e}, {rotation:.1e} ({where})")
        if not result.complete:
            continue
        if reference is not None and find(robot, solutions, q) is None:
            broken.append(f"complete without the generating configuration ({where})")
        sign = -1.0 if reversed_axes else 1.0
        if reference is None and constrain_orientation and not _split_free_match(robot, solutions, q, pair,
                                                                                   pair + 1, sign):
            broken.append(f"complete without the generating configuration up to the pair's split ({where})")
    return broken


#: (planar, dof): planar 3R and 4R, spatial 5R and 6R, a redundant 7R.
ARMS = [(True, 3), (True, 4), (False, 5), (False, 6), (False, 7)]


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize(("planar", "dof"), ARMS, ids=[f"{'planar' if p else 'spatial'}-{n}R" for p, n in ARMS])
def test_fk_targets_of_coaxial_arms_are_never_unreachable_and_complete_answers_hold_them(planar, dof, convention):
    rng = np.random.default_rng(1000 * dof + 10 * planar + (convention == "modified"))
    # the arms whose answers fall to the numeric search (a 5-joint arm left without a closed form) take longer
    configurations = 2 if dof in (3, 7) else 1
    broken, answered = [], 0
    for pair in range(dof - 1):
        for reversed_axes, tool_on_last_axis in ((False, True), (True, True), (False, False), (True, False)):
            robot = coaxial_arm(rng, dof, pair, convention, planar=planar, reversed_axes=reversed_axes,
                                tool_on_last_axis=tool_on_last_axis)
            for q in rng.uniform(-np.pi, np.pi, (configurations, dof)):
                for constrain_orientation in (True, False):
                    answered += 2
                    broken += [f"pair {pair}, reversed {reversed_axes}, tool on axis {tool_on_last_axis}: {words}"
                               for words in audit(robot, q, pair, reversed_axes, constrain_orientation)]
    assert answered == (dof - 1) * 4 * configurations * 4
    assert not broken, f"{len(broken)} of {answered} answers broke a promise:\n" + "\n".join(broken[:20])


def test_the_issue_arm_returns_its_generating_configuration():
    """Issue 22's planar arm (a = 0, 1, 0: joints 1 and 2 coaxial, the tool on axis 3): one solution, at the
    reference split, complete; it was "unreachable" with complete: true."""
    robot = Robot([Joint("q1", "revolute", 0.0, 0.0, 0.0, 0.0), Joint("q2", "revolute", 1.0, 0.0, 0.0, 0.0),
                   Joint("q3", "revolute", 0.0, 0.0, 0.0, 0.0)], convention="standard")
    q = np.array([0.7, -1.1, 0.4])
    target = forward_kinematics(robot, q)
    np.testing.assert_allclose(target[:2, 3], [0.9210609940028851, -0.3894183423086507], atol=1e-15)
    result = solve_ik(robot, target, reference=q)
    assert (result.status, result.complete, result.method) == ("ok", True, "analytic")
    assert result.free_joints == [1]
    assert [(s.kind, s.joints, s.relation) for s in result.singularities] == [("coaxial", (0, 1), "sum")]
    np.testing.assert_allclose([s.joints for s in result.solutions], [q], atol=1e-12)
    held_at_zero = solve_ik(robot, target)  # no reference: q2 at 0, q1 carries q1 + q2
    np.testing.assert_allclose([s.joints for s in held_at_zero.solutions], [[q[0] + q[1], 0.0, q[2]]], atol=1e-12)


def test_a_planar_two_link_arm_with_the_tool_on_its_second_axis():
    """The arm the coaxial planar arms reduce to: a = 1, 0, the tool point on axis 2. A full pose fixes both
    joints (one solution); a position leaves joint 2 free: it is listed free and takes the reference value."""
    robot = Robot([Joint("q1", "revolute", 1.0, 0.0, 0.0, 0.0), Joint("q2", "revolute", 0.0, 0.0, 0.0, 0.0)],
                  convention="standard")
    rng = np.random.default_rng(5)
    for q in rng.uniform(-np.pi, np.pi, (5, 2)):
        target = forward_kinematics(robot, q)
        pose = solve_ik(robot, target)
        assert (pose.status, pose.complete) == ("ok", True)
        np.testing.assert_allclose(joint_difference(robot, np.array([s.joints for s in pose.solutions]), q), 0,
                                   atol=1e-12)
        position = solve_ik(robot, target, constrain_orientation=False, reference=q)
        assert (position.status, position.complete, position.free_joints) == ("ok", True, [1])
        assert len(position.solutions) == 1
        np.testing.assert_allclose(joint_difference(robot, position.solutions[0].joints[None], q), 0, atol=1e-12)
