"""Every spherical-wrist 6-DOF class in closed form: random arms of each class, published industrial arms.

Each class is drawn as seeded random standard DH tables (link lengths 0.1–0.5, twists away from 0 and π,
random joint offsets), some joint axes reversed, stated again in Craig's modified and in Khalil's convention
(the same arm: the same FK), with random base and tool transforms. For every statement 400 random joint vectors
(1,200 per class) go through FK and back through :func:`solve_ik_arrays`: the generating vector must be among
the solutions (revolute joints modulo 2π), every solution must reproduce its target by an FK computed here, no
target may come back unreachable, and the three statements must give the same solution sets. Singular and
stretched poses are built per class and must report their singularity.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from service.kinematics import Joint, Robot, forward_kinematics, link_frames, screw_model
from service.kinematics.ik import _numeric, joint_difference, solve_ik, solve_ik_arrays
from service.kinematics.ik import cached_plan
from service.kinematics.ik.subproblems import subproblem_1
from tests.arms import RandomDHRows, stated_three_ways
from tests.ik_helpers import (aligning_value, assert_every_solution, centred_configurations,
                              positioner_singular_configurations)

DEG = np.pi / 180
POSES = 400  # per statement; three statements (conventions) per class
DATA = json.loads((Path(__file__).parents[2] / "data" / "opw_arms.json").read_text())


# --- building arms -------------------------------------------------------------------------------------------


def _rows(kind: str, rng: np.random.Generator) -> tuple[list[tuple[float, float, float, float]], str]:
    """Standard DH rows (a, alpha, d, theta offset) of a random arm of the class, and its joint kinds."""
    draw = RandomDHRows(rng)
    length, twist, offset, free = draw.length, draw.twist, draw.offset, draw.free
    wrist, base_wrist = draw.spherical_wrists()
    tables = {
        # axis 1, axis 2 offset from it, axes 2 ∥ 3 (alpha_2 = 0), then the wrist: KUKA/ABB/Fanuc type
        "offset_shoulder_parallel_elbow": ([free(), (length(), 0.0, length(), offset()), free()] + wrist, "RRRRRR"),
        # the same with a slide normal to axis 2 as joint 3 (alpha_2 = ±90°)
        "offset_shoulder_parallel_elbow_slide": (
            [free(), (length(), 90 * DEG * rng.choice([-1, 1]), length(), offset()), free()] + wrist, "RRPRRR"),
        # a slide first (not normal to axis 2), then axes 2 ∥ 3
        "offset_shoulder_parallel_elbow_first_slide": (
            [free(), (length(), 0.0, length(), offset()), free()] + wrist, "PRRRRR"),
        # axes 2 and 3 meet (a_2 = 0), axis 1 skew to axis 2
        "offset_shoulder_intersecting_elbow": ([free(), (0.0, twist(), length(), offset()), free()] + wrist,
                                               "RRRRRR"),
        # a slide first, then axes 2 and 3 meeting
        "offset_shoulder_intersecting_elbow_slide": (
            [free(), (0.0, twist(), length(), offset()), free()] + wrist, "PRRRRR"),
        # no special positioner geometry: Pieper's quartic
        "skew_axes": ([free(), free(), free()] + wrist, "RRRRRR"),
        # the wrist at the base (axes 1, 2, 3 meet), then each positioner in reverse
        "wrist_at_base_skew_axes": (base_wrist + [free(), free(), free(), free()], "RRRRRR"),
        "wrist_at_base_parallel_elbow": (base_wrist + [free(), (length(), 0.0, length(), offset()), free(), free()],
                                         "RRRRRR"),
        "wrist_at_base_intersecting_shoulder": (base_wrist + [free(), (0.0, twist(), length(), offset()),
                                                              (0.0, twist(), length(), offset()), free()], "RRRRRR"),
    }
    return tables[kind]


#: class → the solver structure it must get and the generic number of solutions
CLASSES = {
    "offset_shoulder_parallel_elbow": ("offset_shoulder_parallel_elbow+spherical_wrist", 8),
    "offset_shoulder_parallel_elbow_slide": ("offset_shoulder_parallel_elbow+spherical_wrist", 8),
    "offset_shoulder_parallel_elbow_first_slide": ("offset_shoulder_parallel_elbow+spherical_wrist", 4),
    "offset_shoulder_intersecting_elbow": ("offset_shoulder_intersecting_elbow+spherical_wrist", 8),
    "offset_shoulder_intersecting_elbow_slide": ("offset_shoulder_intersecting_elbow+spherical_wrist", 8),
    "skew_axes": ("skew_axes+spherical_wrist", 8),
    "wrist_at_base_skew_axes": ("spherical_wrist+skew_axes", 8),
    "wrist_at_base_parallel_elbow": ("spherical_wrist+offset_shoulder_parallel_elbow", 8),
    "wrist_at_base_intersecting_shoulder": ("spherical_wrist+intersecting_shoulder", 8),
}


def statements(kind: str, seed: int) -> list[Robot]:
    """One random arm of the class in the standard, modified and Khalil conventions (same base, tool, FK)."""
    rng = np.random.default_rng(seed)
    return stated_three_ways(rng, *_rows(kind, rng))


# --- random arms of every class --------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", sorted(CLASSES))
def test_random_arms_of_every_class_in_every_convention(kind):
    structure, generic = CLASSES[kind]
    robots = statements(kind, seed=sorted(CLASSES).index(kind))
    answers = []
    for index, robot in enumerate(robots):
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        assert plan is not None and plan.structure == structure
        assert plan.generic_count == generic
        q = centred_configurations(robot, POSES, seed=index)
        targets = forward_kinematics(robot, q)
        answer = solve_ik_arrays(robot, targets)
        assert answer.count.max() <= generic
        assert_every_solution(robot, q, targets, answer)
        answers.append((q, targets, answer))
    # the three statements are one arm: the same targets get the same solution sets
    q, targets, _ = answers[0]
    for robot in robots[1:]:
        assert np.allclose(forward_kinematics(robot, q), targets, atol=1e-12)
    first = solve_ik_arrays(robots[0], targets)
    for robot in robots[1:]:
        other = solve_ik_arrays(robot, targets)
        assert (other.count == first.count).all()
        for row in range(0, POSES, 7):
            a, b = first.joints[row, :first.count[row]], other.joints[row, :other.count[row]]
            gaps = np.abs(joint_difference(robots[0], a[:, None, :], b[None, :, :])).max(axis=-1)
            assert (gaps.min(axis=1) < 1e-7).all()


@pytest.mark.parametrize("kind", sorted(CLASSES))
def test_wrist_singular_poses_report_the_wrist_and_keep_a_solution(kind):
    robot = statements(kind, seed=sorted(CLASSES).index(kind))[0]
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    middle = plan.inner.wrist.joints[1] if hasattr(plan, "inner") else plan.wrist.joints[1]
    middle = robot.dof - 1 - middle if hasattr(plan, "inner") else middle
    wrist = (3, 4, 5) if not hasattr(plan, "inner") else (0, 1, 2)
    q = centred_configurations(robot, 50, seed=7)
    q[:, middle] = aligning_value(robot, q[0], wrist)
    targets = forward_kinematics(robot, q)
    answer = solve_ik_arrays(robot, targets)
    assert (answer.count >= 1).all()
    for row in range(len(q)):
        kinds = {(s.kind, s.joints) for s in answer.singularities[row]}
        assert ("wrist", (wrist[0], wrist[2])) in kinds, (row, kinds)
    rows, slots = np.nonzero(answer.valid)
    assert (answer.position[rows, slots] <= 1e-9 * robot.characteristic_length).all()
    # near-singular sweep down to 1e-12: never unreachable, never wrong; the generating vector is found (the outer
    # wrist joints, determined only to rounding / distance, compared while that is below the recall tolerance)
    determined = [j for j in range(robot.dof) if j not in (wrist[0], wrist[2])]
    for exponent in range(3, 13):
        near = q.copy()
        near[:, middle] += 10.0 ** -exponent
        near_targets = forward_kinematics(robot, near)
        near_answer = solve_ik_arrays(robot, near_targets)
        assert_every_solution(robot, near, near_targets, near_answer,
                              joints=None if exponent <= 4 else determined)


def _stretched_configurations(robot: Robot, plan, count: int, seed: int) -> np.ndarray:
    """Joint vectors with the positioner's third joint where the point is farthest from axis 2 (stretched)."""
    positioner = plan.positioner
    j, k = positioner.joints[1], positioner.joints[2]
    g = positioner.geometry
    u = g.direction(j)
    in_plane = np.eye(3) - np.outer(u, u)
    # farthest from axis 2 when joint 3 turns the point's offset from axis 3 onto the direction from axis 2 to
    # axis 3 (in the plane normal to them): subproblem 1's angle (an independent Rodrigues check follows)
    best = float(subproblem_1(g.direction(k), in_plane @ (positioner.point - g.point(k)),
                              in_plane @ (g.point(k) - g.point(j))).theta[0])
    q = centred_configurations(robot, count, seed)
    q[:, k] = best
    return q


@pytest.mark.parametrize("kind", ["offset_shoulder_parallel_elbow"])
def test_stretched_elbow_of_the_parallel_elbow_class_is_reported(kind):
    robot = statements(kind, seed=sorted(CLASSES).index(kind))[0]
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    q = _stretched_configurations(robot, plan, 80, seed=11)
    # away from the shoulder's own boundary (where front and back meet, d/dq1 of the height u·y vanishes): there
    # the shoulder angle carries rounding times 1/distance into the reach, and a tangent elbow root splits
    g = plan.positioner.geometry
    k1, u, o = g.direction(0), g.direction(1), g.point(0)
    unturned = q.copy()
    unturned[:, 0] = 0.0
    y = (forward_kinematics(robot, unturned) @ plan.home_inverse @ np.append(plan.point, 1.0))[:, :3] - o
    q = q[np.abs(np.cross(k1, y) @ u) > 0.05 * np.linalg.norm(y, axis=-1)][:50]
    assert len(q) == 50
    targets = forward_kinematics(robot, q)
    answer = solve_ik_arrays(robot, targets)
    assert_every_solution(robot, q, targets, answer, tolerance=1e-5)
    for row in range(len(q)):
        assert any(s.kind == "elbow" and s.relation == "stretched" for s in answer.singularities[row])
    rows, slots = np.nonzero(answer.valid)
    assert (answer.position[rows, slots] <= 1e-9 * robot.characteristic_length).all()


@pytest.mark.parametrize("kind", sorted(CLASSES))
def test_positioner_singular_poses_report_a_singularity(kind):
    """Stretched, folded and boundary poses of each class: flagged, never unreachable, never wrong.

    A double root is found to about √ε, so the generating vector is compared to 1e-5 here.
    """
    robot = statements(kind, seed=sorted(CLASSES).index(kind))[0]
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    q = positioner_singular_configurations(robot, plan, 20, seed=13)
    targets = forward_kinematics(robot, q)
    answer = solve_ik_arrays(robot, targets)
    assert_every_solution(robot, q, targets, answer, tolerance=1e-5)
    for row in range(len(q)):
        assert answer.singularities[row], (row, q[row])


# --- published arms ------------------------------------------------------------------------------------------


def published_arm(name: str) -> Robot:
    p = DATA["arms"][name]["opw"]
    rows = [(p["a1"], -90, p["c1"], 0), (p["c2"], 0, p["b"], -90), (-p["a2"], -90, 0, 0), (0, 90, p["c3"], 0),
            (0, -90, 0, 0), (0, 0, p["c4"], 0)]
    return Robot([Joint(f"a{i + 1}", "revolute", a, alpha * DEG, d, theta * DEG)
                  for i, (a, alpha, d, theta) in enumerate(rows)], name=name)


@pytest.mark.parametrize("name", sorted(DATA["arms"]))
def test_published_industrial_arms_are_solved_in_closed_form(name):
    robot = published_arm(name)
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    assert plan is not None and plan.structure == DATA["arms"][name]["structure"]
    q = centred_configurations(robot, 1000, seed=5)
    targets = forward_kinematics(robot, q)
    answer = solve_ik_arrays(robot, targets)
    assert_every_solution(robot, q, targets, answer)
    assert answer.count.max() == 8 and np.mean(answer.count == 8) > 0.5
    # the shoulder/elbow/wrist labels tell the 8 solutions of a generic pose apart
    row = int(np.flatnonzero(answer.count == 8)[0])
    labels = {tuple(codes[row, slot] for _, (_, codes) in sorted(answer.labels.items())) for slot in range(8)}
    assert sorted(answer.labels) == ["elbow", "shoulder", "wrist"] and len(labels) == 8


@pytest.mark.parametrize("name", sorted(DATA["arms"]))
def test_published_arms_never_reach_the_numeric_fallback(name, monkeypatch):
    robot = published_arm(name)

    def refuse(*args, **kwargs):
        raise AssertionError("the numeric fallback was called")

    monkeypatch.setattr(_numeric, "search", refuse)
    monkeypatch.setattr("service.kinematics.ik._answer.search", refuse)
    for q in centred_configurations(robot, 20, seed=9):
        result = solve_ik(robot, forward_kinematics(robot, q))
        assert (result.method, result.complete, result.status) == ("analytic", True, "ok")
        assert result.structure == DATA["arms"][name]["structure"]


def test_kuka_front_and_back_labels_follow_the_shoulder_offset():
    """The KR 6's front (left) solutions put the wrist centre ahead of axis 1 along the a1 offset."""
    robot = published_arm("kuka_kr6_r900_2")
    q = np.array([0.3, -1.2, 0.4, 0.5, 0.7, -0.2])
    answer = solve_ik_arrays(robot, forward_kinematics(robot, q)[None])
    values, codes = answer.labels["shoulder"]
    for slot in range(answer.count[0]):
        joints = answer.joints[0, slot]
        frames = forward_kinematics(robot, joints)
        centre = frames[:3, 3] - frames[:3, 2] * 0.090  # the wrist centre, c4 back along the flange z
        heading = np.array([np.cos(joints[0]), np.sin(joints[0])])  # link 1's x axis: the a1 offset
        assert values[codes[0, slot]] == ("left" if centre[:2] @ heading > 0 else "right")


def test_kuka_elbow_labels_are_the_side_of_the_shoulder_wrist_line():
    """Elbow up: axis 3 lies above the line from axis 2 to the wrist centre, in the arm's vertical plane."""
    robot = published_arm("kuka_kr6_r900_2")
    q = centred_configurations(robot, 200, seed=21)
    answer = solve_ik_arrays(robot, forward_kinematics(robot, q))
    values, codes = answer.labels["elbow"]
    rows, slots = np.nonzero(answer.valid)
    frames = link_frames(robot, answer.joints[rows, slots])
    shoulder, elbow, centre = frames[:, 1, :3, 3], frames[:, 2, :3, 3], frames[:, 4, :3, 3]  # on axes 2, 3; wrist
    line = (centre - shoulder) / np.linalg.norm(centre - shoulder, axis=-1, keepdims=True)
    offset = elbow - shoulder
    above = (offset - np.einsum("mi,mi->m", offset, line)[:, None] * line)[:, 2]
    expected = np.where(above > 0, "up", "down")
    assert [values[c] for c in codes[rows, slots]] == expected.tolist()


def test_kuka_wrist_centre_on_axis_1_frees_joint_1():
    """The shoulder singularity: the wrist centre on axis 1 (reachable thanks to the bent-back arm)."""
    robot = published_arm("kuka_kr6_r900_2")
    centre_on_axis = None
    for q3 in np.linspace(-2.5, 2.5, 11):  # find q2 putting the wrist centre on axis 1 (x = 0 at q1 = 0)
        def reach(q2):
            frames = link_frames(robot, np.array([0.0, q2, q3, 0.0, 0.5, 0.0]))
            return frames[4, 0, 3]
        grid = np.linspace(-np.pi, np.pi, 361)
        values = np.array([reach(v) for v in grid])
        change = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))
        if len(change):
            low, high = grid[change[0]], grid[change[0] + 1]
            for _ in range(60):
                mid = 0.5 * (low + high)
                low, high = (mid, high) if np.sign(reach(mid)) == np.sign(reach(low)) else (low, mid)
            centre_on_axis = np.array([0.4, 0.5 * (low + high), q3, 0.3, 0.5, -0.2])
            break
    assert centre_on_axis is not None
    reference = np.array([1.1, 0, 0, 0, 0, 0])
    result = solve_ik(robot, forward_kinematics(robot, centre_on_axis), reference=reference)
    assert result.status == "ok" and result.complete and result.solutions
    assert any(s.kind == "shoulder" and s.relation == "free" and s.joints == (0,) for s in result.singularities)
    # joint 1 is free: each solution takes the reference value for it and still reaches the target
    assert all(abs(s.joints[0] - 1.1) < 1e-9 for s in result.solutions)


@pytest.mark.parametrize("name", sorted(DATA["arms"]))
def test_published_tables_have_the_published_opw_geometry(name):
    """The DH tables built from the OPW parameters have them as convention-free distances of the screw model."""
    p = DATA["arms"][name]["opw"]
    robot = published_arm(name)
    model = screw_model(robot)
    k, o = model.directions, model.points

    def line_distance(i, j):
        normal = np.cross(k[i], k[j])
        if np.linalg.norm(normal) < 1e-12:
            offset = o[j] - o[i]
            return np.linalg.norm(offset - (offset @ k[i]) * k[i])
        return abs((o[j] - o[i]) @ normal) / np.linalg.norm(normal)

    assert np.isclose(line_distance(0, 1), p["a1"], atol=1e-12)  # the shoulder offset
    assert np.isclose(line_distance(1, 2), p["c2"], atol=1e-12)  # the upper arm, between parallel axes 2 and 3
    centre = o[4]  # axes 4, 5, 6 meet at the wrist centre; joint 5's point is on it
    assert all(np.linalg.norm(np.cross(k[j], centre - o[j])) < 1e-12 for j in (3, 4, 5))
    offset = centre - o[2]
    assert np.isclose(np.linalg.norm(offset - (offset @ k[2]) * k[2]), np.hypot(p["a2"], p["c3"]), atol=1e-12)
    assert np.isclose(np.linalg.norm(model.home[:3, 3] - centre), p["c4"], atol=1e-12)  # the flange
    # axis 1 is the base z axis, and axis 2 is horizontal, c1 above the base plane
    assert np.allclose(np.abs(k[0]), [0, 0, 1]) and np.allclose(np.cross(k[0], o[0]), 0)
    assert abs(k[1][2]) < 1e-12 and np.isclose(o[1][2], p["c1"], atol=1e-12)


def test_kuka_stated_in_khalil_columns_through_the_api_is_solved_in_closed_form(client):
    """The KR 6 R900-2 sent inline in Khalil–Kleinfinger columns (renamed Craig rows) reaches the same family."""
    standard = published_arm("kuka_kr6_r900_2")
    rows = list(zip(standard.a, standard.alpha, standard.d, standard.theta))
    joints = []
    for i in range(6):  # Craig row i: (a_{i-1}, alpha_{i-1}, d_i, theta_i); Khalil: alpha_j, d_j = a, theta_j, r_j = d
        a, alpha = (0.0, 0.0) if i == 0 else rows[i - 1][:2]
        joints.append({"name": f"a{i + 1}", "type": "revolute", "alpha": float(np.degrees(alpha)), "d": float(a),
                       "theta": float(np.degrees(rows[i][3])), "r": float(rows[i][2])})
    robot = {"name": "KR 6 R900-2 (Khalil)", "convention": "khalil", "angle_unit": "deg", "length_unit": "m",
             "joints": joints}  # the last row has a_6 = alpha_6 = 0: no tool transform needed
    for q in centred_configurations(standard, 10, seed=17):
        target = forward_kinematics(standard, q)
        response = client.post("/v1/ik", json={"robot": robot, "target": {"matrix": target.tolist()}})
        assert response.status_code == 200, response.text
        body = response.json()
        assert body["solver"] == {"method": "analytic", "structure": "offset_shoulder_parallel_elbow+spherical_wrist",
                                  "complete": True, "time_budget_exhausted": False}
        solutions = np.array([s["joints"] for s in body["solutions"]])
        assert np.abs(joint_difference(standard, solutions, q)).max(axis=1).min() < 1e-7


@pytest.mark.parametrize("kind", sorted(CLASSES))
def test_position_only_targets_hold_the_wrist_and_place_the_tool_in_closed_form(kind):
    """A position target holds joints 4–6 at the reference; joints 1–3 then place the tool point (its positioner
    family, complete); targets far out of reach are unreachable, with complete: true."""
    robot = statements(kind, seed=sorted(CLASSES).index(kind))[2]
    q = centred_configurations(robot, 40, seed=23)
    targets = forward_kinematics(robot, q)
    for q_true, target in zip(q, targets):
        result = solve_ik(robot, target, constrain_orientation=False, reference=q_true)
        assert (result.method, result.complete, result.status) == ("analytic", True, "ok")
        solutions = np.array([s.joints for s in result.solutions])
        assert np.abs(joint_difference(robot, solutions, q_true)).max(axis=1).min() < 1e-7
        assert np.allclose(solutions[:, 3:], q_true[3:])  # the held joints
    if robot.is_revolute.all():
        far = targets[0].copy()
        far[:3, 3] *= 50
        result = solve_ik(robot, far)
        assert (result.status, result.complete) == ("unreachable", True)
