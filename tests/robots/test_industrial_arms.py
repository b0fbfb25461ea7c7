"""Industrial arms of the catalogue held to their sources, computed here independently of the service core.

* OPW arms (KUKA, ABB): the forward kinematics of Brandstötter, Angerer & Hofbaur (2014), written from the seven
  OPW parameters and the source's sign corrections and joint offsets (theta_opw = sign * q - offset).
* UFACTORY arms: the vendor's published modified and standard D-H tables, evaluated here.

Each catalogue entry's FK (POST /v1/robots/{id}/fk/batch) must agree at 50 random configurations to 1e-9 m, and every
OPW arm must be solved in closed form with the generating vector among the solutions.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from service.kinematics.ik import joint_difference
from tests.conftest import catalogue_robot
from tests.oracles.opw import OPW_SOURCES, opw_forward
from tests.oracles.rotations import about, axis_angle

DATA_DIR = Path(__file__).resolve().parents[1] / "data"
N_RANDOM = 50
ATOL = 1e-9

#: the same arms in tests/data/opw_arms.json (geometry only)
OPW_DATA_IDS = {"kuka_kr6_r900_2": "kuka_kr6_r900_2", "abb_irb120": "abb_irb120",
                "fanuc_lrmate200id": "fanuc_lrmate200id"}

#: KR 210 R2700 extra, kr210r2700extra_macro.xacro: (origin xyz, axis) of joint_a1..a6, then tool0 = Rot_y(90 deg)
KR210_URDF_JOINTS = [
    ((0, 0, 0.675), (0, 0, -1)), ((0.350, 0, 0), (0, 1, 0)), ((1.150, 0, 0), (0, 1, 0)),
    ((0, 0, -0.041), (-1, 0, 0)), ((1.200, 0, 0), (0, 1, 0)), ((0.215, 0, 0), (-1, 0, 0)),
]
#: IRB 6700-200/2.60, irb6700_200_260_macro.xacro: (origin xyz, axis) of joint_1..6, then tool0 = Rot_y(90 deg)
IRB6700_URDF_JOINTS = [
    ((0, 0, 0.78), (0, 0, 1)), ((0.32, 0, 0), (0, 1, 0)), ((0, 0, 1.125), (0, 1, 0)),
    ((0, 0, 0.2), (1, 0, 0)), ((1.1425, 0, 0), (0, 1, 0)), ((0.2, 0, 0), (1, 0, 0)),
]
#: LR Mate 200iD, lrmate200id_macro.xacro: (origin xyz, axis) of joint_1..6, then tool0 = rpy (pi, -pi/2, 0)
LRMATE_URDF_JOINTS = [
    ((0, 0, 0.330), (0, 0, 1)), ((0.050, 0, 0), (0, 1, 0)), ((0, 0, 0.330), (0, -1, 0)),
    ((0, 0, 0.035), (-1, 0, 0)), ((0.335, 0, 0), (0, -1, 0)), ((0.080, 0, 0), (-1, 0, 0)),
]


def urdf_forward(joints, tool_rotation: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Base_T_tool0 (4, 4) of a URDF chain whose joint origins have rpy = 0."""
    pose = np.eye(4)
    for (xyz, axis), angle in zip(joints, q):
        step = np.eye(4)
        step[:3, :3] = axis_angle(axis, angle)
        step[:3, 3] = xyz
        pose = pose @ step
    tool = np.eye(4)
    tool[:3, :3] = tool_rotation
    return pose @ tool


def dh_forward(rows, q: np.ndarray, modified: bool) -> np.ndarray:
    """FK (4, 4) of a UFACTORY table: rows of (theta offset rad, d m, alpha rad, a m); modified rows hold a_{i-1}, alpha_{i-1}."""
    pose = np.eye(4)
    for (offset, d, alpha, a), qi in zip(rows, q):
        theta = qi + offset
        ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
        if modified:
            step = np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d], [st * sa, ct * sa, ca, ca * d],
                             [0, 0, 0, 1]])
        else:
            step = np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d],
                             [0, 0, 0, 1]])
        pose = pose @ step
    return pose


def ufactory_tables() -> dict:
    """robot id -> {'modified': rows, 'standard': rows} in rad and m, as UFACTORY publishes them."""
    # xArm 6 (xarm-6.md): a2 = sqrt(284.5^2 + 53.5^2) mm, T2_offset = -atan(284.5/53.5), T3_offset = -T2_offset
    a2 = math.hypot(284.5, 53.5) / 1000
    t2 = -math.atan(284.5 / 53.5)
    h = math.pi / 2
    xarm6 = {
        "modified": [(0, 0.267, 0, 0), (t2, 0, -h, 0), (-t2, 0, 0, a2), (0, 0.3425, -h, 0.0775), (0, 0, h, 0),
                     (0, 0.097, -h, 0.076)],
        "standard": [(0, 0.267, -h, 0), (t2, 0, 0, a2), (-t2, 0, -h, 0.0775), (0, 0.3425, h, 0), (0, 0, -h, 0.076),
                     (0, 0.097, 0, 0)],
    }
    with open(DATA_DIR / "lite6_dh.json", encoding="utf-8") as stream:
        lite6 = json.load(stream)
    lite6 = {form: [(math.radians(t), d / 1000, math.radians(al), a / 1000) for t, d, al, a in lite6[form]]
             for form in ("modified", "standard")}
    return {"ufactory_xarm6": xarm6, "ufactory_lite6": lite6}


def random_joints(seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-np.pi, np.pi, (N_RANDOM, 6))


def service_poses(client, robot_id: str, q: np.ndarray) -> np.ndarray:
    response = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()})
    assert response.status_code == 200, response.text
    return np.array([pose["matrix"] for pose in response.json()["poses"]])


@pytest.mark.parametrize("robot_id", sorted(OPW_SOURCES))
def test_opw_arm_fk_matches_the_opw_parameters(client, robot_id):
    p, signs, offsets = OPW_SOURCES[robot_id]
    q = random_joints(sorted(OPW_SOURCES).index(robot_id))
    expected = np.array([opw_forward(p, signs, offsets, qi) for qi in q])
    np.testing.assert_allclose(service_poses(client, robot_id, q), expected, rtol=0, atol=ATOL)


@pytest.mark.parametrize("robot_id", sorted(OPW_DATA_IDS))
def test_opw_parameters_agree_with_the_golden_data(robot_id):
    with open(DATA_DIR / "opw_arms.json", encoding="utf-8") as stream:
        golden = json.load(stream)["arms"][OPW_DATA_IDS[robot_id]]["opw"]
    assert golden == pytest.approx(OPW_SOURCES[robot_id][0], abs=1e-12)


@pytest.mark.parametrize("robot_id, joints, tool_rotation", [
    ("kuka_kr210_r2700", KR210_URDF_JOINTS, about("y", math.pi / 2)),
    ("abb_irb6700", IRB6700_URDF_JOINTS, about("y", math.pi / 2)),
    ("fanuc_lrmate200id", LRMATE_URDF_JOINTS, about("y", -math.pi / 2) @ np.diag([1.0, -1.0, -1.0])),  # Rz(0) Ry Rx(pi)
])
def test_opw_parameters_are_those_of_the_urdf(robot_id, joints, tool_rotation):
    """The OPW data, signs and offsets used above reproduce the ROS-Industrial URDF the entry cites."""
    p, signs, offsets = OPW_SOURCES[robot_id]
    for qi in random_joints(7):
        np.testing.assert_allclose(opw_forward(p, signs, offsets, qi), urdf_forward(joints, tool_rotation, qi),
                                   rtol=0, atol=ATOL)


@pytest.mark.parametrize("robot_id", ["ufactory_lite6", "ufactory_xarm6"])
def test_ufactory_fk_matches_the_published_tables(client, robot_id):
    tables = ufactory_tables()[robot_id]
    q = random_joints(11 + len(robot_id))
    actual = service_poses(client, robot_id, q)
    for form in ("modified", "standard"):
        expected = np.array([dh_forward(tables[form], qi, modified=form == "modified") for qi in q])
        np.testing.assert_allclose(actual, expected, rtol=0, atol=ATOL, err_msg=form)


@pytest.mark.parametrize("robot_id", sorted(OPW_SOURCES))
def test_opw_arm_is_solved_in_closed_form(client, robot_id):
    robot = catalogue_robot(client, robot_id)
    q = random_joints(100 + sorted(OPW_SOURCES).index(robot_id))[:20]
    for q_true, pose in zip(q, service_poses(client, robot_id, q)):
        response = client.post(f"/v1/robots/{robot_id}/ik",
                               json={"target": {"matrix": pose.tolist()}, "limits": [None] * 6})
        assert response.status_code == 200, response.text
        body = response.json()
        assert body["solver"]["method"] == "analytic"
        assert body["solver"]["complete"] is True
        solutions = np.array([s["joints"] for s in body["solutions"]])
        assert np.abs(joint_difference(robot, solutions, q_true)).max(axis=1).min() < 1e-7, q_true


def test_kinova_gen3_fk_matches_the_user_guides_table(client):
    """The catalogue's Gen3 against the Kinova Gen3 User Guide's classical DH table (restated with its source in
    tests/data/redundant_and_deficient_arms.json), evaluated here: base Rx(180°), then the seven rows."""
    with open(DATA_DIR / "redundant_and_deficient_arms.json", encoding="utf-8") as stream:
        guide = json.load(stream)["gen3"]
    rows = [(math.radians(row["theta"]), row["d"], math.radians(row["alpha"]), row["a"]) for row in guide["joints"]]
    base = np.array(guide["base"], dtype=float)
    rng = np.random.default_rng(37)
    q = rng.uniform(-2.0, 2.0, (50, 7))  # within every actuator's limits
    poses = client.post("/v1/robots/kinova_gen3/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    actual = np.array([pose["matrix"] for pose in poses])
    expected = np.array([base @ dh_forward(rows, qi, modified=False) for qi in q])
    np.testing.assert_allclose(actual, expected, rtol=0, atol=ATOL)
