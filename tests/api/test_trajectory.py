"""Trajectory IK through HTTP: the paper's table, the group's singular cases, a wrist and a shoulder singularity,
units, the inline twin, and errors.

Golden data: ``tests/data/assur_spiral_tables.json`` (textbook.md §4.4, printed to 6 significant digits).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.config import Settings
from service.kinematics import TrajectoryOptions, follow_trajectory, forward_kinematics
from tests.conftest import DATA, assert_problem, catalogue_robot
from tests.oracles.paths import difference_jacobian, scaled_sigma_min, spiral, wobble

TABLES = json.loads((DATA / "assur_spiral_tables.json").read_text())
ASSUR = "assur001_scara_rrp"


def post(client, robot_id: str, body: dict, status: int = 200):
    response = client.post(f"/v1/robots/{robot_id}/ik/trajectory", json=body)
    assert response.status_code == status, response.text
    answer = response.json()
    if status == 200:
        assert_is_its_model(answer)
    return answer


def assert_is_its_model(answer: dict) -> None:
    """A trajectory answer is encoded without passing through TrajectoryResponse: it must already be it."""
    from service.api.schemas.trajectory import TrajectoryResponse

    assert TrajectoryResponse.model_validate(answer).model_dump(mode="json") == answer


def spiral_samples(t, *, twist=True, acceleration=True) -> list[dict]:
    D, Dd, Ddd = spiral(t)
    samples = []
    for k, time in enumerate(t):
        sample = {"time": float(time), "pose": {"position": D[k].tolist()}}
        if twist:
            sample["twist"] = {"linear": Dd[k].tolist()}
        if acceleration:
            sample["acceleration"] = {"linear": Ddd[k].tolist()}
        samples.append(sample)
    return samples


def pose_samples(times, poses, twists=None, accelerations=None) -> list[dict]:
    samples = []
    for k, time in enumerate(times):
        sample = {"time": float(time), "pose": {"matrix": poses[k].tolist()}}
        if twists is not None:
            sample["twist"] = {"linear": twists[k, :3].tolist(), "angular": twists[k, 3:].tolist()}
        if accelerations is not None:
            sample["acceleration"] = {"linear": accelerations[k, :3].tolist(),
                                      "angular": accelerations[k, 3:].tolist()}
        samples.append(sample)
    return samples


# ---------------------------------------------------------------------------
# The paper's example (textbook.md §4.4)
# ---------------------------------------------------------------------------


def printed(value: float) -> float:
    """A value as the table prints it: 6 significant digits, values below 1e-13 as 0."""
    return 0.0 if abs(value) < 1e-13 else float(f"{value:.6g}")


@pytest.mark.parametrize("mode", [1, 2])
def test_the_papers_table_for_both_assembly_modes(client, mode):
    """θ1, θ2, l3 and their first and second derivatives at t = 0..8 s, as the paper states them (`paper`).

    Every value, printed as the table prints it (6 significant digits), is the table's value; and every value is
    within 1e-6 of the table's except where the print itself has fewer digits than that: θ2'' at t = 3 and 7 s
    is printed −1.29874 (±5e-6) for −1.2987446. So the check is |ours − table| ≤ 1e-6 + 5e-6·|table|, the
    table's own precision.
    """
    body = post(client, ASSUR, {"samples": spiral_samples(np.arange(9.0)), "branch": {"assembly_mode": mode}})
    assert body["solver"]["rates"] == "assur_group" and body["solver"]["task_rows"] == ["vx", "vy", "vz"]
    rows = np.array(TABLES["tables"][f"mode_{mode}"]["rows"])
    for sample, row in zip(body["samples"], rows):
        paper = sample["paper"]
        ours = np.array([paper[part][joint] for joint in range(3)
                         for part in ("joints", "velocities", "accelerations")])  # the table's column order
        assert sample["time"] == row[0]
        assert [printed(v) for v in ours] == pytest.approx(list(row[1:]), abs=1e-12), f"t = {row[0]}"
        np.testing.assert_allclose(ours, row[1:], rtol=5e-6, atol=1e-6, err_msg=f"t = {row[0]}")
        assert np.all(np.abs(ours - row[1:]) <= 1e-6) or row[0] in (3.0, 7.0)
        assert paper["case"] == "regular" and sample["singularities"] == []
        assert sample["branch"] == {"assembly_mode": mode} and sample["branch_changed"] is False
        # The catalogue robot's own joints: q = (θ1, −θ2, l3) (textbook.md §4.1; robots/assur001_scara_rrp.yaml).
        flip = np.array([1.0, -1.0, 1.0])
        for part in ("joints", "velocities", "accelerations"):
            np.testing.assert_allclose(sample[part], flip * np.array(paper[part]), rtol=0, atol=1e-12)
    assert body["summary"]["singular_samples"] == [] and body["summary"]["branch_changes"] == []


def test_reference_picks_the_mode_nearest_to_it_and_degrees_convert_every_angle(client):
    samples = spiral_samples(np.arange(0.0, 8.5, 0.5))
    radians = post(client, ASSUR, {"samples": samples, "reference": [-0.7, 1.4, 100.0]})
    assert {s["branch"]["assembly_mode"] for s in radians["samples"]} == {2}
    degrees = post(client, ASSUR, {"samples": samples, "reference": [-40.0, 80.0, 100.0], "angle_unit": "deg"})
    scale = np.array([180 / np.pi, 180 / np.pi, 1.0])
    for r, d in zip(radians["samples"], degrees["samples"]):
        for part in ("joints", "velocities", "accelerations"):
            np.testing.assert_allclose(d[part], scale * np.array(r[part]), rtol=1e-13, atol=1e-12)
            np.testing.assert_allclose(d["paper"][part], scale * np.array(r["paper"][part]), rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(degrees["summary"]["largest_joint_step"]["values"],
                               scale * np.array(radians["summary"]["largest_joint_step"]["values"]), rtol=1e-13)


def test_inline_twin_answers_as_the_catalogue_robot(client):
    robot = client.get(f"/v1/robots/{ASSUR}").json()
    body = {"samples": spiral_samples(np.arange(9.0)), "branch": {"assembly_mode": 1}}
    inline = client.post("/v1/ik/trajectory", json={**body, "robot": robot})
    assert inline.status_code == 200, inline.text
    assert_is_its_model(inline.json())
    catalogue = post(client, ASSUR, body)
    assert inline.json()["samples"] == catalogue["samples"]


def test_rates_are_null_without_a_twist(client):
    body = post(client, ASSUR, {"samples": spiral_samples(np.arange(3.0), twist=False, acceleration=False)})
    for sample in body["samples"]:
        assert sample["joints"] is not None and sample["velocities"] is None and sample["accelerations"] is None
        assert sample["paper"]["velocities"] is None and sample["residual"] == {"velocity": None,
                                                                               "acceleration": None}


# ---------------------------------------------------------------------------
# The group's singular cases through HTTP
# ---------------------------------------------------------------------------


def line_samples(x, y, xd, yd, z=60.0) -> list[dict]:
    t = np.linspace(0.0, 2.0, len(x))
    return [{"time": float(t[k]), "pose": {"position": [float(x[k]), float(y[k]), z]},
             "twist": {"linear": [float(xd[k]), float(yd[k]), 0.0]},
             "acceleration": {"linear": [0.0, 0.0, 0.0]}} for k in range(len(x))]


S = np.linspace(-1.0, 1.0, 5)  # t − 1 at the five samples


@pytest.mark.parametrize(("x", "xd", "shape", "elbow_deg"), [
    (130 - 20 * S**2, -40 * S, "stretched", 0.0),
    (30 + 20 * S**2, 40 * S, "folded", 180.0),
])
def test_aligned_group_is_flagged_and_damped_only_on_request(client, x, xd, shape, elbow_deg):
    samples = line_samples(x, 5 * S, xd, 5 + 0 * S)
    body = post(client, ASSUR, {"samples": samples, "branch": {"assembly_mode": 1}, "angle_unit": "deg"})
    middle = body["samples"][2]
    assert [(s["kind"], s["relation"]) for s in middle["singularities"]] == [("assur_group", "aligned"),
                                                                            ("jacobian", "near_singular")]
    assert shape in middle["singularities"][0]["detail"]
    assert middle["paper"]["case"] == "aligned" and middle["velocities"] is None and middle["damped"] is False
    np.testing.assert_allclose(np.abs(middle["paper"]["joints"]), [0.0, elbow_deg, 90.0], atol=1e-9)
    assert body["summary"]["singular_samples"] == [2]
    assert body["summary"]["smallest_distance_to_singularity"]["sample"] == 2
    assert body["summary"]["smallest_distance_to_singularity"]["value"] < 1e-12
    assert all(s["velocities"] is not None for k, s in enumerate(body["samples"]) if k != 2)
    damped = post(client, ASSUR, {"samples": samples, "branch": {"assembly_mode": 1}, "damping": 0.01})
    assert damped["samples"][2]["damped"] is True and damped["samples"][2]["velocities"] is not None
    assert damped["solver"]["damping"] == 0.01


def test_coincident_group_with_equal_arms_inline(client):
    """An inline SCARA with l_AB = l_BC = 50 mm crossing its shoulder axis: θ1 is free and keeps its value."""
    robot = {"convention": "standard", "angle_unit": "deg", "length_unit": "mm",
             "joints": [{"type": "revolute", "a": 50.0, "d": 150.0}, {"type": "revolute", "a": 50.0, "alpha": 180},
                        {"type": "prismatic"}]}
    samples = line_samples(20 * S, 0 * S, 20 + 0 * S, 0 * S)
    response = client.post("/v1/ik/trajectory", json={"robot": robot, "samples": samples,
                                                      "reference": [1.8, 2.7, 90.0]})
    assert response.status_code == 200, response.text
    body = response.json()
    assert_is_its_model(body)
    at = body["samples"][2]
    assert [(s["kind"], s["relation"]) for s in at["singularities"]] == [("assur_group", "coincident"),
                                                                        ("jacobian", "near_singular")]
    assert at["paper"]["case"] == "coincident" and at["velocities"] is None
    assert at["joints"][0] == body["samples"][1]["joints"][0]
    assert body["solver"]["rates"] == "assur_group"


def test_unreachable_samples(client):
    samples = line_samples(120 + 20 * S**2, 0 * S, 40 * S, 0 * S)
    body = post(client, ASSUR, {"samples": samples, "branch": {"assembly_mode": 2}})
    assert [s["status"] for s in body["samples"]] == ["unreachable", "ok", "ok", "ok", "unreachable"]
    assert body["samples"][0]["joints"] is None and body["samples"][0]["within_limits"] is None
    assert body["summary"]["unreachable_samples"] == [0, 4]


# ---------------------------------------------------------------------------
# A wrist singularity (PUMA 560): flagged at the right samples
# ---------------------------------------------------------------------------

WRIST_TIMES = np.array([0.0, 0.5, 0.9, 0.99, 0.9999, 1.0, 1.0001, 1.01, 1.1, 1.5, 2.0])


def wrist_path(t):
    """θ5 = 0.3(t − 1) crosses 0 at t = 1 s; θ1 and θ4 turn at 0.2 and 0.1 rad/s; q̇ is constant."""
    q = np.tile([0.3, -0.6, 0.4, 0.5, 0.0, -0.3], (len(t), 1))
    q[:, 0] += 0.2 * t
    q[:, 3] += 0.1 * t
    q[:, 4] = 0.3 * (t - 1.0)
    return q, np.array([0.2, 0, 0, 0.1, 0.3, 0])


def test_a_trajectory_through_a_wrist_singularity_is_flagged_at_the_right_samples(client):
    robot = catalogue_robot(client, "puma560_modified")
    q, qd = wrist_path(WRIST_TIMES)
    fk = client.post("/v1/robots/puma560_modified/fk/batch", json={"joints": q.tolist()}).json()
    poses = np.array([pose["matrix"] for pose in fk["poses"]])
    J = np.array([difference_jacobian(robot, row) for row in q])  # FK differences, not the code under test
    twists = J @ qd
    body = post(client, "puma560_modified", {"samples": pose_samples(WRIST_TIMES, poses, twists),
                                             "reference": q[0].tolist()})
    # Independent distance: the scaled σ_min of the FK-difference Jacobian.
    expected = np.array([scaled_sigma_min(robot, j, list(range(6))) for j in J])
    np.testing.assert_allclose([s["distance_to_singularity"] for s in body["samples"]], expected,
                               rtol=1e-5, atol=1e-9)
    flagged = [k for k, s in enumerate(body["samples"]) if s["singularities"]]
    assert flagged == [4, 5, 6] == list(np.flatnonzero(expected < 1e-3))  # |θ5| ≤ 3e-5 rad; 3e-3 is not
    assert body["summary"]["singular_samples"] == flagged
    kinds = [[(s["kind"], s["relation"]) for s in sample["singularities"]] for sample in body["samples"]]
    assert kinds[5] == [("wrist", "sum"), ("jacobian", "near_singular")]  # θ4 + θ6 only, exactly at θ5 = 0
    assert kinds[4] == kinds[6] == [("jacobian", "near_singular")]
    joints = np.array([s["joints"] for s in body["samples"]])
    regular = [k for k in range(len(q)) if k != 5]
    np.testing.assert_allclose(joints[regular], q[regular], atol=1e-9)
    # At θ5 = 0 only θ4 + θ6 is determined: θ4 keeps the previous sample's value, and the sum is the path's.
    assert joints[5, 3] == joints[4, 3]
    np.testing.assert_allclose(joints[5, 3] + joints[5, 5], q[5, 3] + q[5, 5], atol=1e-9)
    np.testing.assert_allclose(joints[5, [0, 1, 2, 4]], q[5, [0, 1, 2, 4]], atol=1e-9)
    for k, sample in enumerate(body["samples"]):
        if k in flagged:
            assert sample["velocities"] is None and sample["damped"] is False
        else:
            np.testing.assert_allclose(sample["velocities"], qd, atol=1e-6)
    assert body["summary"]["smallest_distance_to_singularity"]["sample"] == 5
    damped = post(client, "puma560_modified", {"samples": pose_samples(WRIST_TIMES, poses, twists),
                                               "reference": q[0].tolist(), "damping": 1e-3})
    assert [k for k, s in enumerate(damped["samples"]) if s["damped"]] == flagged
    assert all(s["velocities"] is not None for s in damped["samples"])


# ---------------------------------------------------------------------------
# A shoulder singularity (elbow arm, Spong Example 4.3): branch following
# ---------------------------------------------------------------------------

SHOULDER_TIMES = np.linspace(0.0, 2.0, 11)


def shoulder_poses() -> np.ndarray:
    """The wrist centre moves along a horizontal line through the first axis (z0) at t = 1 s; tool pointing down."""
    R = np.diag([1.0, -1.0, -1.0])
    s = SHOULDER_TIMES - 1.0
    centre = np.stack([0.4 * s * np.cos(0.3), 0.4 * s * np.sin(0.3), 1.2 + 0 * s], axis=-1)
    T = np.tile(np.eye(4), (len(s), 1, 1))
    T[:, :3, :3] = R
    T[:, :3, 3] = centre + 0.2 * R[:, 2]  # d6 = 0.2 m along the tool z axis
    return T


def geometric_labels(client, joints) -> dict:
    """Shoulder and elbow labels from the link frames alone (Spong: left arm = wrist centre in front of the
    shoulder along link 1; elbow up = the elbow above the line from the shoulder to the wrist centre)."""
    frames = client.post("/v1/robots/spong_ex4_3_elbow_with_wrist/fk",
                         json={"joints": joints, "frames": True}).json()["frames"]
    shoulder, elbow, centre = (np.array(frames[i]["position"]) for i in (1, 2, 3))
    forward = np.array(frames[1]["matrix"])[:3, 0]  # x1: link 1's forward direction
    reach = centre - shoulder
    line = reach / np.linalg.norm(reach)
    rejection = (elbow - shoulder) - ((elbow - shoulder) @ line) * line
    return {"shoulder": "left" if reach @ forward > 0 else "right", "elbow": "up" if rejection[2] > 0 else "down"}


def test_holding_the_branch_through_a_shoulder_singularity_keeps_the_labels(client):
    held = {"shoulder": "left", "elbow": "up"}
    poses = shoulder_poses()
    body = post(client, "spong_ex4_3_elbow_with_wrist", {"samples": pose_samples(SHOULDER_TIMES, poses),
                                                         "branch": held})
    samples = body["samples"]
    assert all({k: s["branch"][k] for k in held} == held for s in samples)
    assert not any(s["branch_changed"] for s in samples) and body["summary"]["branch_changes"] == []
    assert body["summary"]["singular_samples"] == [5]
    assert ("shoulder", "free") in [(x["kind"], x["relation"]) for x in samples[5]["singularities"]]
    for k, sample in enumerate(samples):
        np.testing.assert_allclose(forward_kinematics(catalogue_robot(client, "spong_ex4_3_elbow_with_wrist"),
                                                      sample["joints"]), poses[k], atol=1e-9)
        if k != 5:  # on the axis itself left/right and up/down are undefined
            assert geometric_labels(client, sample["joints"]) == held, f"sample {k}"
    # Holding "left" across the axis needs the arm to turn half a turn: the summary shows it.
    assert body["summary"]["largest_joint_step"]["values"][0] == pytest.approx(np.pi, abs=1e-9)
    assert body["summary"]["largest_joint_step"]["samples"][0] == 6


def test_continuing_through_a_shoulder_singularity_changes_the_labels_once_after_it(client):
    poses = shoulder_poses()
    start = [0.3 + np.pi, 1.5, -1.2, 0.0, 0.5, 0.0]  # near the left/elbow-up solution at t = 0
    body = post(client, "spong_ex4_3_elbow_with_wrist", {"samples": pose_samples(SHOULDER_TIMES, poses),
                                                         "reference": start})
    samples = body["samples"]
    assert body["summary"]["branch_changes"] == [6]
    assert body["summary"]["largest_joint_step"]["values"][0] < 1e-9  # θ1 does not move: the arm reaches over
    for k, sample in enumerate(samples):
        expected = {"shoulder": "left", "elbow": "up"} if k <= 5 else {"shoulder": "right", "elbow": "down"}
        assert {key: sample["branch"][key] for key in expected} == expected, f"sample {k}"
        if k != 5:
            assert geometric_labels(client, sample["joints"]) == expected, f"sample {k}"


# ---------------------------------------------------------------------------
# Through HTTP as in the core
# ---------------------------------------------------------------------------


def test_http_rates_are_the_cores_for_a_pose_path_and_angular_rates_follow_the_unit(client):
    """The SCARA (Spong Example 3.6) on a path that turns the tool about z: its twist's angular part is in the
    request's angle unit."""
    robot = catalogue_robot(client, "spong_ex3_6_scara_rrpr")
    q0 = np.array([0.4, -0.9, 0.3, 0.5])
    t = np.linspace(0.0, 3.0, 7)
    poses, twists, accelerations = wobble(t, forward_kinematics(robot, q0), 0.1, [0, 0, 1], None)
    core = follow_trajectory(robot, t, poses, twists=twists, accelerations=accelerations,
                             options=TrajectoryOptions(reference=q0))
    body = post(client, "spong_ex3_6_scara_rrpr",
                {"samples": pose_samples(t, poses, twists, accelerations), "reference": q0.tolist()})
    assert body["solver"]["task_rows"] == ["vx", "vy", "vz", "wz"] and body["solver"]["rates"] == "jacobian"
    for sample, ours in zip(body["samples"], core.samples):
        np.testing.assert_allclose(sample["velocities"], ours.velocities, rtol=0, atol=1e-14)
        np.testing.assert_allclose(sample["accelerations"], ours.accelerations, rtol=0, atol=1e-14)
    degrees = twists.copy(), accelerations.copy()
    degrees[0][:, 3:] *= 180 / np.pi
    degrees[1][:, 3:] *= 180 / np.pi
    in_degrees = post(client, "spong_ex3_6_scara_rrpr", {
        "samples": pose_samples(t, poses, *degrees), "reference": (q0 * [180 / np.pi, 180 / np.pi, 1,
                                                                         180 / np.pi]).tolist(),
        "angle_unit": "deg"})
    scale = np.array([180 / np.pi, 180 / np.pi, 1.0, 180 / np.pi])
    for d, r in zip(in_degrees["samples"], body["samples"]):
        np.testing.assert_allclose(d["velocities"], scale * np.array(r["velocities"]), rtol=1e-12, atol=1e-12)


# ---------------------------------------------------------------------------
# Errors
# ---------------------------------------------------------------------------


def scara_body(**changes) -> dict:
    samples = [{"time": 0.0, "pose": {"position": [100.0, -20.0, 50.0]}, "twist": {"linear": [31.4, 0.0, 10.0]}},
               {"time": 0.1, "pose": {"position": [103.0, -19.8, 51.0]}, "twist": {"linear": [31.0, 3.1, 10.0]}}]
    body = {"samples": samples}
    body.update(changes)
    return body


@pytest.mark.parametrize(("change", "loc", "match"), [
    (lambda b: b["samples"][1].update(time=0.0), ["body", "samples", 1, "time"], "increase strictly"),
    (lambda b: b["samples"][1].update(time=-1.0), ["body", "samples", 1, "time"], "increase strictly"),
    (lambda b: b["samples"][0]["twist"].update(linear=[1.0, 2.0]), ["body", "samples", 0, "twist", "linear"], None),
    (lambda b: b["samples"][0]["twist"].update(linear=[1.0, 2.0, 3.0, 4.0]), ["body", "samples", 0, "twist"], None),
    (lambda b: b["samples"][0]["twist"].pop("linear"), ["body", "samples", 0, "twist"], "'linear', 'angular'"),
    (lambda b: b["samples"][0].update(twist={"angular": [0.0, 0.0, 1.0]}),
     ["body", "samples", 0, "twist", "linear"], "vx, vy, vz"),
    (lambda b: b["samples"][0].update(twist=None, acceleration={"linear": [0.0, 0.0, 0.0]}),
     ["body", "samples", 0, "acceleration"], "needs the sample's twist"),
    (lambda b: b["samples"][1].update(pose={"matrix": np.eye(4).tolist()}), ["body", "samples", 1, "pose"],
     "same kind"),
    (lambda b: b.update(branch={"shoulder": "left"}), ["body", "branch", "shoulder"], "assembly_mode"),
    (lambda b: b.update(branch={"assembly_mode": 3}), ["body", "branch", "assembly_mode"], None),
    (lambda b: b.update(branch={"knee": "up"}), ["body", "branch", "knee"], None),
    (lambda b: b.update(reference=[0.1, 0.2]), ["body", "reference"], None),
    (lambda b: b.update(samples=[]), ["body", "samples"], None),
    (lambda b: b.update(damping=0.0), ["body", "damping"], None),
    (lambda b: b.update(singularity_tolerance=-1.0), ["body", "singularity_tolerance"], None),
    (lambda b: b["samples"][0].update(time="soon"), ["body", "samples", 0, "time"], None),
])
def test_bad_samples_are_422_problems_that_point_at_the_field(client, change, loc, match):
    body = scara_body()
    change(body)
    response = client.post(f"/v1/robots/{ASSUR}/ik/trajectory", json=body)
    assert_problem(response, 422, loc=loc, match=match)


def test_a_pose_target_on_a_scara_needs_the_angular_part_it_controls(client):
    robot = catalogue_robot(client, "spong_ex3_6_scara_rrpr")
    poses = forward_kinematics(robot, np.array([[0.3, -0.8, 0.2, 0.1], [0.35, -0.8, 0.2, 0.1]]))
    samples = pose_samples([0.0, 0.1], poses, np.zeros((2, 6)))
    samples[1]["twist"].pop("angular")
    response = client.post("/v1/robots/spong_ex3_6_scara_rrpr/ik/trajectory", json={"samples": samples})
    assert_problem(response, 422, loc=["body", "samples", 1, "twist", "angular"], match="wz")


def test_unknown_robot_is_404(client):
    assert_problem(client.post("/v1/robots/no_such_robot/ik/trajectory", json=scara_body()), 404)


def test_more_samples_than_kin_max_batch_is_413():
    with TestClient(create_app(Settings(max_batch=3))) as small:
        samples = spiral_samples(np.arange(4.0))
        assert_problem(small.post(f"/v1/robots/{ASSUR}/ik/trajectory", json={"samples": samples}), 413,
                       match="KIN_MAX_BATCH")
        assert small.post(f"/v1/robots/{ASSUR}/ik/trajectory", json={"samples": samples[:3]}).status_code == 200
        robot = small.get(f"/v1/robots/{ASSUR}").json()
        assert_problem(small.post("/v1/ik/trajectory", json={"samples": samples, "robot": robot}), 413)


def test_a_long_trajectory_stops_while_its_samples_are_read():
    """The samples were converted to core targets without a budget check, and the answer built without one either:
    10,000 UR5 samples answered their 503 1.2 s after a 5 s deadline. With a 1 ms deadline, 300 samples now stop
    while they are read, before any solving."""
    pose = {"matrix": [[1, 0, 0, 0.4], [0, 1, 0, 0.1], [0, 0, 1, 0.3], [0, 0, 0, 1]]}
    body = {"samples": [{"time": 0.01 * k, "pose": pose} for k in range(300)]}
    with TestClient(create_app(Settings())) as client:
        response = client.post("/v1/robots/ur5/ik/trajectory", json=body, headers={"X-Request-Timeout-Ms": "1"})
    problem = assert_problem(response, 503)
    assert "during reading the samples" in problem["detail"]


# ---------------------------------------------------------------------------
# Issue 22.11: a redundant arm's free joints, as in single IK; a near-singular path through HTTP
# ---------------------------------------------------------------------------


def test_a_seven_joint_arm_holds_the_free_joint_the_request_names(client):
    """Kinova Gen3 with q3 held at 0.3 rad: every sample's joints are the generating path's, q3 exactly 0.3 and
    its rate 0 (before issue 22.11 the request was a 422: the field did not exist)."""
    robot = catalogue_robot(client, "kinova_gen3")
    t = np.linspace(0.0, 1.0, 11)
    q = np.array([0.2, 0.4, 0.3, -1.6, 0.2, 1.5, 0.4]) + np.outer(t, [0.3, -0.2, 0.0, 0.25, -0.3, 0.2, 0.1])
    qd = np.tile([0.3, -0.2, 0.0, 0.25, -0.3, 0.2, 0.1], (len(t), 1))
    J = np.array([difference_jacobian(robot, row) for row in q])  # FK differences, not the code under test
    body = {"samples": pose_samples(t, forward_kinematics(robot, q), J @ qd[0]),
            "free_joints": [{"joint": 2, "values": [0.3]}], "reference": q[0].tolist()}
    answer = post(client, "kinova_gen3", body)
    joints = np.array([s["joints"] for s in answer["samples"]])
    np.testing.assert_allclose(joints, q, atol=1e-9)
    assert (joints[:, 2] == 0.3).all()
    np.testing.assert_allclose([s["velocities"] for s in answer["samples"]], qd, atol=1e-6)
    assert answer["summary"]["branch_changes"] == []
    degrees = post(client, "kinova_gen3", {**body, "angle_unit": "deg", "reference": np.degrees(q[0]).tolist(),
                                           "free_joints": [{"joint": 2, "values": [float(np.degrees(0.3))]}],
                                           "samples": pose_samples(t, forward_kinematics(robot, q))})
    np.testing.assert_allclose(np.radians([s["joints"] for s in degrees["samples"]]), q, atol=1e-9)


def test_free_joints_on_a_six_joint_arm_is_a_422_at_the_field(client):
    body = {"samples": [{"time": 0.0, "pose": {"position": [0.3, 0.1, 0.4], "quaternion_wxyz": [0, 1, 0, 0]}}],
            "free_joints": [{"joint": 2, "values": [0.3]}]}
    problem = post(client, "ur5e", body, status=422)
    assert problem["errors"][0]["loc"][:2] == ["body", "free_joints"], problem
    assert "more than 6 joints" in problem["errors"][0]["msg"]


def test_a_ur5e_path_near_its_shoulder_singularity_stays_on_its_branch_through_http(client):
    """The issue's case through the route: poses and twists by FK of a joint path whose middle is 3e-5 (σmin/σmax)
    from the shoulder singularity; every sample on the generating joints, and the rates its q̇."""
    from tests.oracles.paths import NEAR_SINGULAR_TIMES, UR5E_PATH, near_singular_path, twists_of

    robot = catalogue_robot(client, "ur5e")
    q, qd, _ = near_singular_path(robot, *UR5E_PATH, NEAR_SINGULAR_TIMES)
    answer = post(client, "ur5e", {"samples": pose_samples(NEAR_SINGULAR_TIMES, forward_kinematics(robot, q),
                                                           twists_of(robot, q, qd)),
                                   "reference": q[0].tolist(), "damping": 1e-6})
    joints = np.array([s["joints"] for s in answer["samples"]])
    assert np.abs(joints - q).max() <= 1e-9
    assert all(s["status"] == "ok" for s in answer["samples"])
    middle = [k for k in range(len(NEAR_SINGULAR_TIMES)) if abs(NEAR_SINGULAR_TIMES[k] - 0.5) < 0.1]
    assert not any(answer["samples"][k]["branch_changed"] for k in middle)
    velocities = np.array([s["velocities"] for s in answer["samples"]])
    assert np.abs(velocities - qd).max() < 1e-3 * np.abs(qd).max()


@pytest.mark.parametrize("robot_id, q0, q1", [
    ("franka_panda", [1.3259, 1.9502, 0.8228, 1.3389, -0.4329, 1.0029, -0.4614],
     [1.7557, 2.2237, 0.7022, 1.6231, -0.8663, 1.4279, -0.2683]),
    ("kuka_iiwa14", [0.3, 0.8, -0.4, -1.2, 0.6, 0.9, 0.2], [0.6, 1.0, -0.2, -1.0, 0.4, 1.2, 0.5]),
])
def test_a_redundant_arm_on_a_smooth_path_keeps_its_branch_unchanged(client, robot_id, q0, q1):
    """A redundant arm's answer lists members of a family over its free joint, several near the previous
    sample's joints: choosing among members of one branch (the same labels) is not a change of branch. A probe
    found every sample after the first marked branch_changed with its labels unchanged."""
    Q = np.linspace(q0, q1, 60)[:6].tolist()
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": Q}).json()["poses"]
    answer = client.post(f"/v1/robots/{robot_id}/ik/trajectory",
                         json={"samples": [{"time": 0.1 * k, "pose": pose} for k, pose in enumerate(poses)],
                               "reference": Q[0]}).json()
    samples = answer["samples"]
    assert [s["status"] for s in samples] == ["ok"] * 6
    assert all(s["branch"] == samples[0]["branch"] for s in samples)
    assert not any(s["branch_changed"] for s in samples) and answer["summary"]["branch_changes"] == []
