"""Inverse kinematics through the API: limits, singular, unreachable and under-determined targets, the numeric
fallback, reference ordering and the UR5's solution counts.

The textbook's own IK, branch by branch, is in ``test_ik_textbook.py``; the same arms described another way in
``test_ik_frames.py``; 1,000 random vectors per catalogue robot in ``test_ik_recall.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.arms import NUMERIC_ARM, SKEW_6R_DH, SKEW_6R_ROBOT, SKEW_7R
from tests.conftest import assert_problem, catalogue_robot
from tests.ik_helpers import angle_gap, find, joints_of, unlimited, wrapped
from tests.oracles.closed_forms import CLOSED_FORMS

def dh_fk(a, alpha, d, q) -> np.ndarray:
    """base_T_flange of a revolute standard-DH chain, written here independently of the service.

    a, alpha, d: shape (n,); q: shape (..., n) (θ offsets 0). Returns (..., 4, 4), the product of
    A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i) (textbook.md §1.1, eq. 3.10).
    """
    q = np.asarray(q, dtype=float)
    T = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4)).copy()
    for i in range(q.shape[-1]):
        ct, st = np.cos(q[..., i]), np.sin(q[..., i])
        ca, sa = np.cos(alpha[i]), np.sin(alpha[i])
        A = np.zeros(q.shape[:-1] + (4, 4))
        A[..., 0, :] = np.stack([ct, -st * ca, st * sa, a[i] * ct], axis=-1)
        A[..., 1, :] = np.stack([st, ct * ca, -ct * sa, a[i] * st], axis=-1)
        A[..., 2, :] = [0.0, sa, ca, d[i]]
        A[..., 3, 3] = 1.0
        T = T @ A
    return T


#: UR5, Universal Robots' published standard-DH table (robots/ur5.yaml): the textbook prints no closed form.
UR5_TABLE = dict(a=np.array([0.0, -0.425, -0.39225, 0.0, 0.0, 0.0]),
                 alpha=np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0]),
                 d=np.array([0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823]))
UR5_STRETCHED = [0.4, -0.5, 0.0, 0.3, 0.9, -0.2]


def ur5_fk(q) -> np.ndarray:
    """UR5 base_T_tool for q of shape (..., 6)."""
    return dh_fk(UR5_TABLE["a"], UR5_TABLE["alpha"], UR5_TABLE["d"], q)


# --------------------------------------------------------------------------
# Joint limits on prismatic joints (the textbook keeps slides >= 0)
# --------------------------------------------------------------------------

@pytest.mark.parametrize("robot_id, q", [
    ("ex004_1_prp", [0.5, -0.32175055439664213, 0.31622776601683794]),
    ("spong_ex3_2_cylindrical_rpp", [0.4, -0.3, 0.6]),
    ("ex004_2_polar_rrp", [0.5, -0.7, 0.4]),
])
def test_a_slide_below_its_lower_limit_is_rejected(client, robot_id, q):
    """The catalogue gives these slides ``lower: 0``: the retracted solution (slide < 0) is rejected, with the
    violation, and the textbook's branch stays; without limits both are solutions."""
    robot = catalogue_robot(client, robot_id)
    target = {"position": CLOSED_FORMS[robot_id](q)[:3, 3].tolist()}
    free = client.post(f"/v1/robots/{robot_id}/ik", json={"target": target, "limits": unlimited(robot)}).json()
    limited = client.post(f"/v1/robots/{robot_id}/ik", json={"target": target}).json()
    slide = int(np.flatnonzero(~robot.is_revolute)[-1])
    assert (joints_of(free)[:, slide] < 0).sum() >= 1
    assert len(joints_of(limited)) == len(joints_of(free)) - (joints_of(free)[:, slide] < 0).sum()
    assert (joints_of(limited)[:, slide] >= 0).all()
    assert find(robot, joints_of(limited), q) is not None
    assert limited["rejected"] and all(s["within_limits"] is False for s in limited["rejected"])
    assert all(any(v["joint"] == slide and v["value"] < 0 and v["lower"] == 0 for v in s["violations"])
               for s in limited["rejected"])


def _pose_ik(client, robot_id: str, T: np.ndarray, **options) -> dict:
    robot = catalogue_robot(client, robot_id)
    response = client.post(f"/v1/robots/{robot_id}/ik",
                           json={"target": {"matrix": np.asarray(T).tolist()}, "limits": unlimited(robot), **options})
    assert response.status_code == 200, response.text
    return response.json()


def _position_ik(client, robot_id: str, position, **options) -> dict:
    robot = catalogue_robot(client, robot_id)
    response = client.post(f"/v1/robots/{robot_id}/ik",
                           json={"target": {"position": list(map(float, position))}, "limits": unlimited(robot),
                                 **options})
    assert response.status_code == 200, response.text
    return response.json()


def assert_fk_reaches(robot_id: str, result: dict, T: np.ndarray, *, position_only: bool = False) -> None:
    """Every solution reproduces the target under the independent closed-form FK, and reports a tiny residual."""
    scale = max(1.0, np.abs(T[:3, 3]).max())
    assert result["solutions"]
    for solution in result["solutions"]:
        reached = CLOSED_FORMS[robot_id](solution["joints"])
        if position_only:
            assert np.abs(reached[:3, 3] - T[:3, 3]).max() < 1e-9 * scale
            assert solution["residual"]["orientation"] is None
        else:
            assert np.abs(reached - T).max() < 1e-9 * scale
            assert solution["residual"]["orientation"] < 1e-9
        assert solution["residual"]["position"] < 1e-9 * scale


def _kinds(result: dict) -> list[tuple]:
    return [(s["kind"], s["joints"], s["relation"]) for s in result["singularities"]]


# --------------------------------------------------------------------------
# Singular targets
# --------------------------------------------------------------------------

PUMA = "puma560_modified"


@pytest.mark.parametrize("theta5, relation, combined", [(0.0, "sum", lambda q4, q6: q4 + q6),
                                                         (np.pi, "difference", lambda q4, q6: q4 - q6)])
def test_puma_wrist_singularity(client, theta5, relation, combined):
    """θ5 = 0 (axes 4 and 6 aligned, same sense in Craig's frames): only θ4 + θ6 is determined; θ5 = π: θ4 − θ6.
    One representative with θ4 = the reference value, or 0; the other three arm branches keep both wrists."""
    q = np.array([0.3, -0.6, 0.4, 0.8, theta5, -0.5])
    T = CLOSED_FORMS[PUMA](q)
    for reference, q4 in ((None, 0.0), ([0.0, 0.0, 0.0, 1.1, 0.0, 0.0], 1.1), ([0.3, -0.6, 0.4, -2.9, 0, 0], -2.9)):
        result = _pose_ik(client, PUMA, T, **({} if reference is None else {"reference": reference}))
        assert ("wrist", [3, 5], relation) in _kinds(result)
        assert_fk_reaches(PUMA, result, T)
        solutions = joints_of(result)
        assert len(solutions) == 7
        arm = angle_gap(solutions[:, :3], q[:3]).max(axis=1)
        family = np.flatnonzero(arm < 1e-7)
        assert len(family) == 1  # the singular arm branch: one representative
        representative = solutions[family[0]]
        assert np.sin(representative[4]) == pytest.approx(0.0, abs=1e-9)
        assert representative[3] == pytest.approx(q4, abs=1e-9)  # the free joint: reference value, or 0
        difference = combined(representative[3], representative[5]) - combined(q[3], q[5])
        assert np.cos(difference) == pytest.approx(1.0, abs=1e-12)  # the determined combination
        assert "wrist" not in result["solutions"][family[0]]["branch"]  # flip and no flip are one family here


ELBOW = "spong_ex4_3_elbow_with_wrist"
A2, A3 = 1.0, 0.8


def test_wrist_centre_on_the_first_axis(client):
    """Spong Fig. 4.4: xc = yc = 0, θ1 is arbitrary. Reported, and θ1 = the reference value, or 0."""
    robot = catalogue_robot(client, ELBOW)
    q2 = 1.2
    q3 = np.arccos(-A2 * np.cos(q2) / A3) - q2  # a2 c2 + a3 c23 = 0: the wrist centre above the base
    q = np.array([0.4, q2, q3, 0.3, 0.9, -0.2])
    T = CLOSED_FORMS[ELBOW](q)
    assert np.hypot(*(T[:2, 3] - 0.2 * T[:2, 2])) < 1e-12
    for reference, q1 in ((None, 0.0), ([0.7, 0, 0, 0, 0, 0], 0.7), ([0.4, 0, 0, 0, 0, 0], 0.4)):
        result = _pose_ik(client, ELBOW, T, **({} if reference is None else {"reference": reference}))
        assert _kinds(result) == [("shoulder", [0], "free")]
        assert_fk_reaches(ELBOW, result, T)
        solutions = joints_of(result)
        assert len(solutions) == 4  # front and back are one family: 2 elbows x 2 wrists
        assert np.allclose(solutions[:, 0], q1, atol=1e-12)
        assert all("shoulder" not in s["branch"] for s in result["solutions"])
        assert sorted(s["branch"]["elbow"] for s in result["solutions"]) == ["down", "down", "up", "up"]
    assert find(robot, solutions, q) is not None  # with reference θ1 = 0.4 the generating vector is a solution


@pytest.mark.parametrize("q3, kind", [(0.0, "stretched"), (np.pi, "folded")])
def test_stretched_and_folded_elbow(client, q3, kind):
    """D = ±1 (eq. 4.29): the two elbow branches meet; one solution per shoulder and wrist, no elbow label."""
    robot = catalogue_robot(client, ELBOW)
    q = np.array([0.4, 0.5, q3, 0.3, 0.9, -0.2])
    T = CLOSED_FORMS[ELBOW](q)
    result = _pose_ik(client, ELBOW, T)
    assert ("elbow", [2], kind) in _kinds(result)
    assert_fk_reaches(ELBOW, result, T)
    solutions = joints_of(result)
    assert len(solutions) == 4 and find(robot, solutions, q) is not None
    assert np.allclose(np.cos(solutions[:, 2]), np.cos(q3), atol=1e-9)
    assert all("elbow" not in s["branch"] for s in result["solutions"])


def test_ur5_with_a_stretched_elbow(client):
    """UR5, θ3 = 0: the elbow is stretched, reported, and the generating vector is among the (FK-checked)
    solutions; test_ur5_counts_are_the_real_solution_counts shows no solution is missing at this pose."""
    robot = catalogue_robot(client, "ur5")
    q = np.array(UR5_STRETCHED)
    T = ur5_fk(q)
    result = _pose_ik(client, "ur5", T)
    assert ("elbow", [2], "stretched") in _kinds(result)
    solutions = joints_of(result)
    assert find(robot, solutions, q) is not None
    assert len(solutions) < 8
    for s in solutions:
        assert np.abs(ur5_fk(s) - T).max() < 1e-9
    assert "elbow" not in result["solutions"][find(robot, solutions, q)]["branch"]


@pytest.mark.parametrize("robot_id, q, kind", [
    ("assur001_scara_rrp", [0.3, 0.0, 40.0], "position"),  # stretched: |AC| = l_AB + l_BC
    ("assur001_scara_rrp", [0.3, np.pi, 40.0], "position"),  # folded: |AC| = l_AB - l_BC
    ("spong_ex3_6_scara_rrpr", [0.3, 0.0, 0.4, 0.5], "pose"),
])
def test_scara_aligned_links(client, robot_id, q, kind):
    """The RRR (Assur) group with A, B and C aligned (P/Q = ±1): the two assembly modes meet."""
    robot = catalogue_robot(client, robot_id)
    T = CLOSED_FORMS[robot_id](q)
    result = _pose_ik(client, robot_id, T) if kind == "pose" else _position_ik(client, robot_id, T[:3, 3])
    assert _kinds(result) == [("assur_group", [1], "aligned")]
    assert_fk_reaches(robot_id, result, T, position_only=kind == "position")
    solutions = joints_of(result)
    assert len(solutions) == 1 and find(robot, solutions, q) is not None
    assert "assembly_mode" not in result["solutions"][0]["branch"]


def test_scara_with_equal_links_and_the_point_on_the_first_axis(client):
    """File 001 §2: A ≡ B with l_AC = l_BC: the group assembles but C is undefined (increased mobility). Joint 1 is
    free: the reference value, or 0; the links fold onto each other (q2 = π)."""
    robot = {"convention": "standard", "joints": [{"a": 0.5}, {"a": 0.5, "alpha": np.pi}, {"type": "prismatic"}]}
    for reference, q1 in ((None, 0.0), ([0.4, 0.0, 0.0], 0.4)):
        body = {"robot": robot, "target": {"position": [0.0, 0.0, -0.3]}}
        if reference is not None:
            body["reference"] = reference
        result = client.post("/v1/ik", json=body).json()
        assert _kinds(result) == [("assur_group", [0, 1], "coincident")]
        [solution] = result["solutions"]
        assert solution["joints"] == pytest.approx([q1, np.pi, 0.3], abs=1e-12)
        assert solution["residual"]["position"] < 1e-12


# --------------------------------------------------------------------------
# Unreachable targets
# --------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id, target", [
    (PUMA, {"position": [2.0, 0.0, 0.0], "orientation": {"type": "rpy", "angles": [3.0, 0.1, 0.2]}}),
    (ELBOW, {"position": [0.0, 0.0, 3.0], "orientation": {"type": "quaternion", "wxyz": [1, 0, 0, 0]}}),
    ("ur5", {"position": [1.2, 0.0, 0.1], "orientation": {"type": "quaternion", "wxyz": [0, 1, 0, 0]}}),
    ("assur001_scara_rrp", {"position": [200.0, 0.0, 50.0]}),  # |AC| > l_AB + l_BC
    ("assur001_scara_rrp", {"position": [10.0, 0.0, 50.0]}),  # |AC| < l_AB - l_BC
    ("ex004_4_polar_offset_rrp", {"position": [0.1, 0.1, 1.0]}),  # rho^2 + h^2 < l2^2
    ("spong_ex3_1_planar_rr", {"position": [0.3, 0.4, 0.2]}),  # off the arm's plane
])
def test_outside_the_workspace(client, robot_id, target):
    result = client.post(f"/v1/robots/{robot_id}/ik", json={"target": target}).json()
    assert result["status"] == "unreachable"
    assert result["solutions"] == [] and result["rejected"] == []
    assert "position" in result["detail"] and "outside the workspace" in result["detail"]
    assert result["solver"]["method"] == "analytic" and result["solver"]["complete"] is True


def test_scara_with_a_tilted_orientation_is_unreachable(client):
    """Spong eq. 4.56: a SCARA can only reach R = [[cα, sα, 0], [sα, −cα, 0], [0, 0, −1]]. A reachable position with
    that orientation is solved; tilted by 0.1 rad it is unreachable, and the detail says the orientation is."""
    position = CLOSED_FORMS["spong_ex3_6_scara_rrpr"]([0.3, 0.7, 0.4, -0.2])[:3, 3].tolist()
    alpha = 0.4
    upright = [[np.cos(alpha), np.sin(alpha), 0], [np.sin(alpha), -np.cos(alpha), 0], [0, 0, -1]]
    tilt = np.array([[1, 0, 0], [0, np.cos(0.1), -np.sin(0.1)], [0, np.sin(0.1), np.cos(0.1)]])
    ok = client.post("/v1/robots/spong_ex3_6_scara_rrpr/ik",
                     json={"target": {"position": position, "orientation": {"type": "matrix", "matrix": upright}}})
    assert ok.json()["status"] == "ok" and len(ok.json()["solutions"]) == 2
    tilted = client.post("/v1/robots/spong_ex3_6_scara_rrpr/ik", json={"target": {
        "position": position, "orientation": {"type": "matrix", "matrix": (tilt @ upright).tolist()}}}).json()
    assert tilted["status"] == "unreachable" and tilted["solutions"] == []
    assert "orientation" in tilted["detail"] and "4.56" in tilted["detail"]
    assert "position is reachable" in tilted["detail"]


# --------------------------------------------------------------------------
# Under-determined targets: position only, more joints than the target fixes
# --------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id, q, free, count", [
    (PUMA, [0.3, -0.6, 0.4, 0.8, 0.3, -0.5], [3, 4, 5], 4),
    (ELBOW, [0.3, -0.6, 0.4, 0.8, 0.3, -0.5], [3, 4, 5], 4),
    ("spong_ex3_6_scara_rrpr", [0.3, -0.6, 0.4, 0.8], [3], 2),
    ("ex004_3_spherical_rrpr", [0.3, 0.6, 0.4, 0.8], [3], 4),  # 2 with q3 >= 0, 2 more with q3 < 0
    # the wrist's tool point lies on axis 3: q3 never moves it (subproblem 3 is degenerate for every target)
    ("spong_ex3_3_spherical_wrist_rrr", [0.5, -0.7, 1.1], [2], 2),
])
def test_a_position_only_target_names_the_free_joints(client, robot_id, q, free, count):
    """The target fixes 3 coordinates; the other joints are named in ``free_joints`` and held at the reference
    value, or 0. Targets are made with the free joints at those values, so the generating vector is a solution."""
    robot = catalogue_robot(client, robot_id)
    rng = np.random.default_rng(3)
    for reference in (None, rng.uniform(-1, 1, robot.dof)):
        held = np.zeros(len(free)) if reference is None else reference[free]
        q = np.array(q, dtype=float)
        q[free] = held
        T = CLOSED_FORMS[robot_id](q)
        options = {} if reference is None else {"reference": reference.tolist()}
        result = _position_ik(client, robot_id, T[:3, 3], **options)
        assert result["status"] == "ok" and result["free_joints"] == free
        assert result["solver"]["complete"] is True
        solutions = joints_of(result)
        assert len(solutions) == count
        assert np.abs(solutions[:, free] - held).max() < 1e-12  # the free joints: reference value, or 0
        assert_fk_reaches(robot_id, result, T, position_only=True)
        assert find(robot, solutions, q) is not None


def test_held_free_joints_that_move_the_point_are_named_when_it_is_out_of_reach(client):
    """The elbow arm's tool point is d6 from the wrist centre: with the wrist held at 0 some reachable points are
    out of reach. The answer must not claim the point is unreachable (issue 14): it searches every joint, answers
    with solutions marked incomplete, and names the held joints."""
    q = np.array([0.3, -0.6, 0.4, 0.8, 1.3, -0.5])
    T = CLOSED_FORMS[ELBOW](q)
    held = _position_ik(client, ELBOW, T[:3, 3])
    assert held["status"] == "ok" and held["solver"]["complete"] is False
    assert held["solver"]["method"] == "numeric"
    assert "outside the workspace" not in held["detail"]
    assert "q4, q5, q6" in held["detail"]
    reached = _position_ik(client, ELBOW, T[:3, 3], reference=q.tolist())  # held at the generating values
    assert reached["status"] == "ok"
    assert find(catalogue_robot(client, ELBOW), joints_of(reached), q) is not None


def test_the_spherical_wrist_places_its_tool_point_with_two_solutions(client):
    """Position only, the wrist's tool point is d6 (c4 s5, s4 s5, c5): θ4 = atan2(y, x), θ5 = acos(z / d6), or the
    flip (θ4 + π, −θ5); θ6 is free (0 here)."""
    robot = catalogue_robot(client, "spong_ex3_3_spherical_wrist_rrr")
    x, y, z = CLOSED_FORMS["spong_ex3_3_spherical_wrist_rrr"]([0.5, -0.7, 1.1])[:3, 3]
    solutions = joints_of(_position_ik(client, "spong_ex3_3_spherical_wrist_rrr", [x, y, z]))
    theta4, theta5 = np.arctan2(y, x), np.arccos(z / 0.2)
    assert find(robot, solutions, [theta4, theta5, 0.0]) is not None
    assert find(robot, solutions, [theta4 + np.pi, -theta5, 0.0]) is not None


# --------------------------------------------------------------------------
# The numeric fallback
# --------------------------------------------------------------------------

#: the skew 6R arm's size (sum of its |a| and |d|): the scale of its position tolerances
SKEW_SCALE = float(np.abs(SKEW_6R_DH["a"]).sum() + np.abs(SKEW_6R_DH["d"]).sum())


def _inline_ik(client, robot: dict, target: dict, **options):
    response = client.post("/v1/ik", json={"robot": robot, "target": target, **options})
    assert response.status_code == 200, response.text
    return response.json()


@pytest.mark.parametrize("seed", range(5))
def test_a_skew_6r_arm_gets_every_solution_from_the_general_solver(client, seed):
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, 6)
    T = dh_fk(SKEW_6R_DH["a"], SKEW_6R_DH["alpha"], SKEW_6R_DH["d"], q)
    result = _inline_ik(client, SKEW_6R_ROBOT, {"matrix": T.tolist()})
    assert result["status"] == "ok"
    assert result["solver"] == {"method": "analytic", "structure": "general_6r", "complete": True,
                                "time_budget_exhausted": False}
    solutions = joints_of(result)
    for solution in result["solutions"]:  # every solution passes an FK check independent of the service
        reached = dh_fk(SKEW_6R_DH["a"], SKEW_6R_DH["alpha"], SKEW_6R_DH["d"], solution["joints"])
        assert np.abs(reached - T).max() < 1e-9 * SKEW_SCALE
        assert solution["residual"]["position"] <= 1e-9 * SKEW_SCALE
        assert solution["residual"]["orientation"] <= 1e-9
        assert solution["branch"] == {}
    robot = type("Revolute6", (), {"is_revolute": np.ones(6, dtype=bool)})
    assert find(robot, solutions, q) is not None  # the generating vector was found
    for i in range(len(solutions)):  # merged: no two the same
        others = np.delete(solutions, i, axis=0)
        assert find(robot, others, solutions[i], tolerance=1e-6) is None


def test_numeric_time_budget_refuses_rather_than_cuts(client):
    """The numeric search is bounded by iterations (deterministic); time_budget_ms bounds its time, and a search
    that needs longer is a 503 with Retry-After, never a partial answer that depends on the server's load."""
    import time

    # four skew revolute joints and two slides: no family (nor the general solver, which takes one slide at most)
    # covers it, so the numeric search answers
    T = _fk_pose(client, NUMERIC_ARM, [0.3, 0.4, 0.8, 0.2, -0.4, 0.1])
    start = time.perf_counter()
    cut = client.post("/v1/ik", json={"robot": NUMERIC_ARM, "target": {"matrix": T.tolist()},
                                      "numeric": {"starts": 2000, "time_budget_ms": 5}})
    elapsed = time.perf_counter() - start
    body = assert_problem(cut, 503, match="numeric search")
    assert cut.headers["retry-after"] == "1" and "5 ms" in body["detail"]
    assert elapsed < 2.0  # 5 ms of search plus one iteration and HTTP; not the whole 2,000-start search
    full = _inline_ik(client, NUMERIC_ARM, {"matrix": T.tolist()}, numeric={"starts": 48, "time_budget_ms": 5000})
    again = _inline_ik(client, NUMERIC_ARM, {"matrix": T.tolist()}, numeric={"starts": 48, "time_budget_ms": 5000})
    assert full["solver"]["time_budget_exhausted"] is False and full["status"] == "ok"
    assert full["solutions"] == again["solutions"]  # the same answer every time
    short = _inline_ik(client, NUMERIC_ARM, {"matrix": T.tolist()}, numeric={"starts": 48, "iterations": 3})
    assert short["solver"]["time_budget_exhausted"] is True and "iteration cap (3)" in short["detail"]


def _revolute(a, alpha, d, kind="revolute"):
    return {"type": kind, "a": a, "alpha": alpha, "d": d}


SKEW_PRISMATIC = {"convention": "standard", "joints": [
    _revolute(0.1, 0.4, 0.2), _revolute(0.2, -0.7, 0.0, "prismatic"), _revolute(0.3, 1.0, 0.1),
    _revolute(0.05, 0.6, 0.0, "prismatic"), _revolute(0.1, -1.1, 0.2), _revolute(0.0, 0.3, 0.1)]}
PLANAR_START = {"convention": "standard", "joints": [
    _revolute(0.3, 0.0, 0.1), _revolute(0.25, 0.0, 0.0), _revolute(0.2, 0.8, 0.1),
    _revolute(0.05, 0.6, 0.0, "prismatic"), _revolute(0.1, -1.1, 0.2), _revolute(0.0, 0.3, 0.1)]}
NO_LENGTHS = {"convention": "standard", "joints": [_revolute(0, al, 0) for al in (0.9, -1.2, 0.5, 0.8, -0.6, 1.3)]}
SKEW_2R = {"convention": "standard", "joints": [_revolute(0.3, 0.7, 0.1), _revolute(0.2, 0.0, 0.4)]}
ONE_JOINT = {"convention": "modified", "joints": [_revolute(0.3, 0.7, 0.1)]}

#: (robot, joint vector whose FK is the target, target kind): every one reachable
REACHABLE = [
    (NUMERIC_ARM, [0.3, -0.2, 0.9, 1.4, -0.7, 0.2], "pose"),  # four skew revolute joints and two slides
    (SKEW_PRISMATIC, [0.4, 0.3, -1.1, 0.2, 2.0, -0.6], "pose"),
    # 3 joints more than the target fixes, and joints 1–3 (planar: axes 1 ∥ 2 ∥ 3) cannot place a point alone. (The
    # skew RPR start of SKEW_PRISMATIC can: its position targets are solved in closed form, skew_axes_with_slide.)
    (PLANAR_START, [0.4, 0.3, -1.1, 0.2, 2.0, -0.6], "position"),
    (SKEW_2R, [1.0, -0.5], "position"),
]

#: (robot, target): out of reach (or only an orientation the arm cannot give)
UNREACHABLE = [
    (SKEW_7R, {"position": [1e6, -1e6, 3.0], "orientation": {"type": "euler_zyz", "angles": [1, 2, 3]}}),
    (SKEW_PRISMATIC, {"position": [50.0, 0.0, 0.0], "orientation": {"type": "rpy", "angles": [0, 0, 0]}}),
    (NO_LENGTHS, {"position": [1.0, 0.0, 0.0], "orientation": {"type": "rpy", "angles": [0, 0, 0]}}),
    (SKEW_2R, {"position": [0.1, 0.2, 0.3]}),
    (ONE_JOINT, {"position": [0.3, 0.5, 0.1]}),
]


def _scale(robot: dict) -> float:
    return sum(abs(j.get("a", 0)) + abs(j.get("d", 0)) for j in robot["joints"]) or 1.0


def _fk_pose(client, robot: dict, q) -> np.ndarray:
    return np.array(client.post("/v1/fk", json={"robot": robot, "joints": list(q)}).json()["pose"]["matrix"])


@pytest.mark.parametrize("robot, q, kind", REACHABLE)
@pytest.mark.parametrize("numeric", [None, {"starts": 1, "iterations": 1}])
def test_the_numeric_fallback_never_fails_and_never_returns_a_wrong_solution(client, robot, q, kind, numeric):
    """Reachable targets: with the default search at least one solution, every one FK-correct; with a 1-start,
    1-iteration search the answer may be empty, but is still a 200 and still correct."""
    T = _fk_pose(client, robot, q)
    target = {"matrix": T.tolist()} if kind == "pose" else {"position": T[:3, 3].tolist()}
    result = _inline_ik(client, robot, target, **({} if numeric is None else {"numeric": numeric}))
    assert result["solver"]["method"] == "numeric" and result["solver"]["complete"] is False
    if numeric is None:
        assert result["status"] == "ok" and result["solutions"]
    else:  # found nothing: not a proof that the target is unreachable
        assert result["status"] in ("ok", "not_found")
    for solution in result["solutions"]:
        reached = _fk_pose(client, robot, solution["joints"])
        error = np.abs(reached - T).max() if kind == "pose" else np.abs(reached[:3, 3] - T[:3, 3]).max()
        assert error < 1e-9 * _scale(robot)
        assert solution["residual"]["position"] < 1e-9 * _scale(robot)


def test_a_one_joint_arm_places_its_point_in_closed_form(client):
    """One revolute joint places a point by subproblem 1 (it was the numeric search). This arm's tool point is on
    its axis (modified DH, no offset after the joint): every value reaches it, so the joint is free and takes the
    reference value."""
    T = _fk_pose(client, ONE_JOINT, [0.7])
    result = _inline_ik(client, ONE_JOINT, {"position": T[:3, 3].tolist()}, reference=[-0.4])
    assert result["status"] == "ok" and result["solver"]["method"] == "analytic"
    assert result["solver"]["complete"] is True
    assert [s["joints"] for s in result["solutions"]] == [[pytest.approx(-0.4, abs=1e-12)]]
    assert any(s["kind"] == "shoulder" and s["relation"] == "free" for s in result["singularities"])


@pytest.mark.parametrize("robot, target", UNREACHABLE)
def test_unreachable_targets_of_any_arm_are_a_plain_answer(client, robot, target):
    result = _inline_ik(client, robot, target)
    assert result["solutions"] == [] and result["detail"]
    if result["solver"]["method"] == "numeric":  # it cannot prove the target is out of reach, and says so
        assert result["status"] == "not_found" and "may be outside the workspace" in result["detail"]
    else:
        assert result["status"] == "unreachable"


# --------------------------------------------------------------------------
# Ordering by a reference
# --------------------------------------------------------------------------


@pytest.mark.parametrize("norm", ["linf", "l2"])
def test_reference_orders_nearest_first_across_the_wrap(client, norm):
    """Continuous joints (no limits): distances are measured across the 2π wrap. The reference is one solution
    moved by whole turns on three joints plus a small step: that solution comes first, and the order is the
    independent wrap-aware distance's."""
    robot = catalogue_robot(client, ELBOW)
    q = np.array([2.9, -0.6, 0.4, -3.0, 0.3, 3.1])
    T = CLOSED_FORMS[ELBOW](q)
    plain = joints_of(_pose_ik(client, ELBOW, T))
    assert len(plain) == 8
    rng = np.random.default_rng(11)
    for chosen in range(8):
        reference = plain[chosen] + np.array([2 * np.pi, 0, -2 * np.pi, 0, 4 * np.pi, 0]) + rng.uniform(-0.05, 0.05, 6)
        ordered = _pose_ik(client, ELBOW, T, reference=reference.tolist(), ordering={"norm": norm})
        solutions = joints_of(ordered)
        assert find(robot, solutions[:1], plain[chosen]) == 0
        difference = np.abs(wrapped(solutions - reference))
        distance = difference.max(axis=1) if norm == "linf" else np.linalg.norm(difference, axis=1)
        assert np.all(np.diff(distance) >= 0)
        assert distance[0] <= (0.05 if norm == "linf" else 0.05 * np.sqrt(6)) + 1e-12
        nearest = _pose_ik(client, ELBOW, T, reference=reference.tolist(), ordering={"norm": norm}, max_solutions=3)
        assert np.allclose(joints_of(nearest), solutions[:3]) and nearest["trimmed"] == 5


def test_reference_with_multi_turn_joints_measures_the_actual_travel(client):
    """UR5 joints span ±360°: each solution has 2π-equivalents within the limits, different physical positions of
    the cable-limited joint. Nearest first then means the equivalent with the least actual travel."""
    q = np.array([0.4, -1.1, 1.3, -0.6, 1.2, -2.5])
    T = ur5_fk(q)
    reference = q + np.array([-2 * np.pi, 0, 0, 2 * np.pi, 0, 2 * np.pi]) + 0.01  # all within ±2π
    result = client.post("/v1/robots/ur5/ik", json={"target": {"matrix": T.tolist()}, "reference": reference.tolist()})
    solutions = joints_of(result.json())
    assert np.abs(solutions[0] - (reference - 0.01)).max() < 1e-9  # the equivalent itself, not its wrapped twin
    travel = np.abs(solutions - reference).max(axis=1)
    assert np.all(np.diff(travel) >= 0)
    assert np.all(np.abs(solutions) <= 2 * np.pi + 1e-9)


# --------------------------------------------------------------------------
# UR5: poses with fewer than 8 solutions really have fewer
# --------------------------------------------------------------------------


def _dense_search(target: np.ndarray, starts: int = 600, iterations: int = 60, seed: int = 0) -> np.ndarray:
    """Every UR5 solution a Levenberg–Marquardt search from ``starts`` random starts converges to, shape (k, 6).

    Independent of the service: its own FK (:func:`ur5_fk`), finite-difference Jacobian of the 12 entries of the
    top three rows of the pose, per-start damping; converged (error < 1e-10) vectors wrapped and merged at 1e-4.
    """
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (starts, 6))
    damping = np.full(starts, 1e-3)

    def error(joints):
        return (target[:3, :] - ur5_fk(joints)[:, :3, :]).reshape(len(joints), 12)

    e = error(q)
    cost = np.einsum("si,si->s", e, e)
    step_size = 1e-7
    for _ in range(iterations):
        J = np.empty((starts, 12, 6))
        for i in range(6):
            dq = np.zeros(6)
            dq[i] = step_size
            J[:, :, i] = (ur5_fk(q + dq) - ur5_fk(q - dq))[:, :3, :].reshape(starts, 12) / (2 * step_size)
        Jt = np.swapaxes(J, 1, 2)
        step = np.linalg.solve(Jt @ J + damping[:, None, None] * np.eye(6), (Jt @ e[..., None]))[..., 0]
        trial = q + step
        trial_error = error(trial)
        trial_cost = np.einsum("si,si->s", trial_error, trial_error)
        better = trial_cost < cost
        q[better], e[better], cost[better] = trial[better], trial_error[better], trial_cost[better]
        damping = np.where(better, np.maximum(damping * 0.3, 1e-12), damping * 10)
    found: list[np.ndarray] = []
    for candidate in wrapped(q[np.sqrt(cost) < 1e-10]):
        if not any(np.abs(wrapped(candidate - other)).max() < 1e-4 for other in found):
            found.append(candidate)
    return np.array(found)


def test_ur5_counts_are_the_real_solution_counts(client):
    """For poses where the service returns 8, 6, 4 and 2 solutions (and the stretched-elbow pose), a dense
    multi-start numeric search finds exactly the same set: no solution is missing, none is extra. The 8-solution
    pose shows the search is dense enough to find them all."""
    robot = catalogue_robot(client, "ur5")
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, (300, 6))
    poses = ur5_fk(q)
    results = client.post("/v1/robots/ur5/ik/batch", json={
        "targets": [{"matrix": T.tolist()} for T in poses], "limits": unlimited(robot)}).json()["results"]
    counts = [len(r["solutions"]) for r in results]
    chosen = [counts.index(count) for count in (8, 6, 4, 2)]
    cases = [(poses[i], results[i]) for i in chosen]
    stretched = ur5_fk(np.array(UR5_STRETCHED))
    cases.append((stretched, _pose_ik(client, "ur5", stretched)))
    assert [len(result["solutions"]) for _, result in cases] == [8, 6, 4, 2, 5]
    for T, result in cases:
        service = joints_of(result)
        searched = _dense_search(T)
        assert len(searched) == len(service), (searched, service)
        assert all(find(robot, service, s, tolerance=1e-4) is not None for s in searched)
