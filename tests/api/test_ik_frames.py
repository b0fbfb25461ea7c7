"""The same arm described a second way gives the same solution set, with the same branch labels.

Spong §3.2.2: frame choices are not unique. The solver works from the joint axes, so a second description of the
same physical arm must give the same solutions (after mapping the joint variables) and labels that keep their
meaning:

* PUMA 560 in Craig's, Khalil's and Corke's (standard) tables, related by ``tests/data/puma_frame_alignment.json``;
* a base and a tool transform added (the target transformed accordingly);
* a revolute axis reversed through the DH twist and angle (that joint's solutions are negated);
* an offset moved along parallel axes (a different point on each axis, the same arm).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import catalogue_robot
from tests.ik_helpers import find, fk_inline, fk_matrix, joints_of, random_configurations

DATA = Path(__file__).resolve().parents[1] / "data"
ALIGNMENT = {(r["from"], r["to"]): r for r in json.loads((DATA / "puma_frame_alignment.json").read_text())["relations"]}
TARGETS = 16


def _ik(client, target: np.ndarray, *, robot_id: str | None = None, robot: dict | None = None,
        kind: str = "pose") -> dict:
    """IK of a catalogue robot (``robot_id``) or an inline one (``robot``), without limits (the mathematical set)."""
    dof = len(robot["joints"]) if robot is not None else catalogue_robot(client, robot_id).dof
    body = {"target": {"matrix": target.tolist()} if kind == "pose" else {"position": target[:3, 3].tolist()},
            "limits": [None] * dof}
    if robot is not None:
        response = client.post("/v1/ik", json={**body, "robot": robot})
    else:
        response = client.post(f"/v1/robots/{robot_id}/ik", json=body)
    assert response.status_code == 200, response.text
    return response.json()


def assert_same_solutions(robot, first: dict, second: dict, mapping=lambda q: q) -> int:
    """``second``'s solutions, mapped into ``first``'s joint variables, are ``first``'s, with the same labels.

    Returns the number of solutions compared.
    """
    assert first["status"] == second["status"] == "ok"
    assert first["solver"]["structure"] == second["solver"]["structure"]
    a = joints_of(first)
    b = np.array([mapping(q) for q in joints_of(second)])
    assert len(a) == len(b), (a, b)
    for index, q in enumerate(b):
        match = find(robot, a, q)
        assert match is not None, (q, a)
        assert second["solutions"][index]["branch"] == first["solutions"][match]["branch"], (q, a[match])
    return len(a)


def description(client, robot_id: str) -> dict:
    robot = client.get(f"/v1/robots/{robot_id}").json()
    for joint in robot["joints"]:
        joint["limits"] = None
    return robot


# --------------------------------------------------------------------------
# PUMA 560: Craig vs Khalil vs Corke
# --------------------------------------------------------------------------


@pytest.mark.parametrize("other", ["puma560_khalil", "puma560_standard"])
def test_puma_tables_give_the_same_solutions_and_labels(client, other):
    relation = ALIGNMENT[("puma560_modified", other)]
    offset = np.radians(relation["joint_offset_deg"])
    base = np.array(relation["to_base_T_from_base"], dtype=float)
    tool = np.array(relation["from_flange_T_to_flange"], dtype=float)
    craig = catalogue_robot(client, "puma560_modified")
    q = random_configurations(craig, TARGETS, seed=31)
    compared = 0
    for row in q:
        T = fk_matrix(client, "puma560_modified", row)
        first = _ik(client, T, robot_id="puma560_modified")
        second = _ik(client, base @ T @ tool, robot_id=other)
        compared += assert_same_solutions(craig, first, second, mapping=lambda q_other: q_other - offset)
        assert find(craig, joints_of(first), row) is not None
    assert compared == 8 * TARGETS


# --------------------------------------------------------------------------
# A base and a tool transform
# --------------------------------------------------------------------------


def _rigid(axis, angle: float, translation) -> np.ndarray:
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    T = np.eye(4)
    T[:3, :3] = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    T[:3, 3] = translation
    return T


#: a tilted mount (so world z is no longer the robot's up), an upside-down mount, and a tool with an offset
BASES = {"tilted": _rigid([1, 2, 0.5], 2.1, [0.3, -0.2, 0.7]), "ceiling": _rigid([1, 0, 0], np.pi, [0, 0, 2.5])}
TOOL = _rigid([0.2, -1, 0.4], 0.8, [0.05, 0.02, 0.11])

BASE_AND_TOOL_ROBOTS = [
    ("puma560_modified", "pose"),
    ("puma560_standard", "pose"),
    ("spong_ex4_3_elbow_with_wrist", "pose"),
    ("spong_sec4_3_elbow_shoulder_offset_with_wrist", "pose"),
    ("spong_ex3_5_stanford", "pose"),
    ("spong_ex3_6_scara_rrpr", "pose"),
    ("ur5", "pose"),
    ("spong_sec4_3_spherical_arm_rrp", "position"),
    ("ex004_4_polar_offset_rrp", "position"),
    ("assur001_scara_rrp", "position"),
]


@pytest.mark.parametrize("mount", sorted(BASES))
@pytest.mark.parametrize("robot_id, kind", BASE_AND_TOOL_ROBOTS)
def test_a_base_and_a_tool_transform_keep_the_solutions_and_labels(client, robot_id, kind, mount):
    """world_T_tool' = B · world_T_tool · T: the target B·T·Tt has the same solutions. Position-only targets get
    the base only (a tool offset would change which point is placed)."""
    robot = catalogue_robot(client, robot_id)
    moved = description(client, robot_id)
    base = BASES[mount].copy()
    if robot_id == "assur001_scara_rrp":  # millimetres
        base[:3, 3] *= 100
    moved["base"] = base.tolist()
    tool = np.eye(4)
    if kind == "pose":
        tool = TOOL.copy()
        moved["tool"] = tool.tolist()
    q = random_configurations(robot, TARGETS, seed=41)
    for row in q:
        T = fk_matrix(client, robot_id, row)
        moved_T = base @ T @ tool
        assert np.abs(fk_inline(client, moved, row) - moved_T).max() < 1e-9 * max(1.0, np.abs(moved_T).max())
        first = _ik(client, T, robot_id=robot_id, kind=kind)
        second = _ik(client, moved_T, robot=moved, kind=kind)
        assert_same_solutions(robot, first, second)


# --------------------------------------------------------------------------
# A revolute axis reversed through the DH twist and angle
# --------------------------------------------------------------------------


def reversed_axis(robot: dict, joint: int) -> dict:
    """A standard-DH description whose joint ``joint`` (0-based, ≥ 1) turns about the opposite direction.

    Frame joint−1 is turned half a turn about its x axis: z_{joint−1}, the axis of the joint, reverses. In the
    table that is α_{joint−1} + π and, in the joint's own row, θ → −θ, d → −d, α → α + π
    (Rx(π)·Rz(θ)·Tz(d) = Rz(−θ)·Tz(−d)·Rx(π)). The joint variable is negated: q' = −q.
    """
    assert robot["convention"] == "standard" and joint >= 1
    half = 180.0 if robot["angle_unit"] == "deg" else np.pi
    out = copy.deepcopy(robot)
    rows = out["joints"]
    rows[joint - 1]["alpha"] += half
    rows[joint]["theta"] = -rows[joint]["theta"]
    rows[joint]["d"] = -rows[joint]["d"]
    rows[joint]["alpha"] += half
    return out


REVERSALS = [
    ("spong_ex4_3_elbow_with_wrist", 1, "pose"),
    ("spong_ex4_3_elbow_with_wrist", 2, "pose"),
    ("spong_ex4_3_elbow_with_wrist", 3, "pose"),
    ("spong_sec4_3_elbow_shoulder_offset_with_wrist", 1, "pose"),
    ("spong_sec4_3_elbow_shoulder_offset_with_wrist", 5, "pose"),
    ("puma560_standard", 1, "pose"),
    ("puma560_standard", 2, "pose"),
    ("spong_ex3_5_stanford", 1, "pose"),
    ("spong_ex3_6_scara_rrpr", 1, "pose"),
    ("ur5", 1, "pose"),
    ("ur5", 2, "pose"),
    ("ur5", 5, "pose"),
    ("spong_sec4_3_spherical_arm_rrp", 1, "position"),
    ("ex004_2_polar_rrp", 1, "position"),
    ("assur001_scara_rrp", 1, "position"),
]


@pytest.mark.parametrize("robot_id, joint, kind", REVERSALS)
def test_a_reversed_axis_negates_that_joint_and_keeps_the_labels(client, robot_id, joint, kind):
    robot = catalogue_robot(client, robot_id)
    flipped = reversed_axis(description(client, robot_id), joint)
    sign = np.ones(robot.dof)
    sign[joint] = -1.0
    for row in random_configurations(robot, TARGETS, seed=51):
        T = fk_matrix(client, robot_id, row)
        assert np.abs(fk_inline(client, flipped, sign * row) - T).max() < 1e-9 * max(1.0, np.abs(T).max())
        first = _ik(client, T, robot_id=robot_id, kind=kind)
        second = _ik(client, T, robot=flipped, kind=kind)
        assert_same_solutions(robot, first, second, mapping=lambda q: sign * q)


def test_reversing_the_middle_wrist_axis_swaps_flip_and_no_flip(client):
    """The wrist label is defined on the joint variable (no_flip ⇔ sin θ5 > 0, textbook §2.3), so reversing
    axis 5 swaps it, and only it."""
    robot_id = "spong_ex4_3_elbow_with_wrist"
    robot = catalogue_robot(client, robot_id)
    flipped = reversed_axis(description(client, robot_id), 4)
    swap = {"flip": "no_flip", "no_flip": "flip"}
    for row in random_configurations(robot, 10, seed=61):
        T = fk_matrix(client, robot_id, row)
        first, second = _ik(client, T, robot_id=robot_id), _ik(client, T, robot=flipped)
        a = joints_of(first)
        assert len(a) == len(joints_of(second)) == 8
        for solution in second["solutions"]:
            q = np.array(solution["joints"]) * np.array([1, 1, 1, 1, -1, 1])
            match = first["solutions"][find(robot, a, q)]["branch"]
            assert solution["branch"] == {**match, "wrist": swap[match["wrist"]]}


# --------------------------------------------------------------------------
# An offset moved along parallel axes: another point on each axis, the same arm
# --------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id, moves", [
    ("puma560_standard", {2: (1, 1.0)}),  # d3 -> d2 (axes 2 and 3 are parallel)
    ("ur5", {3: (1, 0.7), 4: (2, 0.0)}),  # part of d4 -> d2, ... (axes 2, 3 and 4 are parallel)
    ("spong_sec4_3_elbow_shoulder_offset_with_wrist", {1: (2, 1.0)}),  # d2 -> d3
])
def test_an_offset_moved_along_parallel_axes_changes_nothing(client, robot_id, moves):
    """Standard DH: Tz commutes with Tx and with Rz about the same z, so between parallel axes a d can move from one
    row to another; the frame origins (the points on the axes the solver reads) move, the arm does not."""
    robot = catalogue_robot(client, robot_id)
    moved = description(client, robot_id)
    for source, (destination, fraction) in moves.items():
        amount = moved["joints"][source]["d"] * fraction
        moved["joints"][source]["d"] -= amount
        moved["joints"][destination]["d"] += amount
    for row in random_configurations(robot, TARGETS, seed=71):
        T = fk_matrix(client, robot_id, row)
        assert np.abs(fk_inline(client, moved, row) - T).max() < 1e-12
        assert_same_solutions(robot, _ik(client, T, robot_id=robot_id), _ik(client, T, robot=moved))
