"""The arrays form of the IK batch holds exactly the objects form's answer, in columns.

Both forms are requested for the same seeded targets under different options (limits that expand into
2π-equivalents, filtering, a reference with trimming, degrees, position-only and unreachable targets, a cap that
cuts the list), and the objects form is turned into columns here to compare.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import catalogue_robot


def _targets(client, robot_id: str, count: int, seed: int, *, position_only: bool = False) -> list[dict]:
    robot = catalogue_robot(client, robot_id)
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (count, robot.dof))
    q[:, ~robot.is_revolute] = 0.3
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    targets = [{"position": p["position"]} if position_only else {"matrix": p["matrix"]} for p in poses]
    far = [[1, 0, 0, 50.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    return targets + [{"matrix": far}]


def _columns_of_objects(results: list[dict]) -> dict:
    """The objects form rearranged the way the arrays form lays it out."""
    solvers, reports = [], []

    def index(items, item):
        if item not in items:
            items.append(item)
        return items.index(item)

    targets = {key: [] for key in ("status", "detail", "solver", "singularities", "truncated", "trimmed",
                                   "available", "solution_count", "rejected_count")}
    tables = {"solutions": [], "rejected": []}
    for row, result in enumerate(results):
        targets["status"].append(result["status"])
        targets["detail"].append(result["detail"])
        targets["solver"].append(index(solvers, {**result["solver"], "free_joints": result["free_joints"]}))
        targets["singularities"].append([index(reports, s) for s in result["singularities"]])
        targets["truncated"].append(result["truncated"])
        targets["trimmed"].append(result["trimmed"])
        targets["available"].append(result["available"])
        targets["solution_count"].append(len(result["solutions"]))
        targets["rejected_count"].append(len(result["rejected"]))
        for name in tables:
            tables[name] += [(row, s) for s in result[name]]
    columns = {}
    for name, rows in tables.items():
        labels = sorted({label for _, s in rows for label in s["branch"]})
        columns[name] = {
            "target": [row for row, _ in rows],
            "joints": [s["joints"] for _, s in rows],
            "within_limits": [s["within_limits"] for _, s in rows],
            "residual_position": [s["residual"]["position"] for _, s in rows],
            "residual_orientation": [s["residual"]["orientation"] for _, s in rows],
            "branch": {label: [s["branch"].get(label) for _, s in rows] for label in labels},
        }
        if any("clearance" in s for _, s in rows):
            columns[name]["clearance"] = [s["clearance"] for _, s in rows]
            columns[name]["collisions"] = [s["collisions"] for _, s in rows]
    return {"solvers": solvers, "singularity_reports": reports, "targets": targets, **columns}


def _assert_same(arrays: dict, objects: dict) -> None:
    assert arrays["format"] == "arrays"
    assert arrays["solvers"] == objects["solvers"]
    assert arrays["singularity_reports"] == objects["singularity_reports"]
    assert arrays["targets"] == objects["targets"]
    for name in ("solutions", "rejected"):
        got, want = arrays[name], objects[name]
        assert got["target"] == want["target"]
        assert got["within_limits"] == want["within_limits"]
        assert {k: v for k, v in got["branch"].items() if any(x is not None for x in v)} == want["branch"]
        np.testing.assert_allclose(np.array(got["joints"]).reshape(-1, 1), np.array(want["joints"]).reshape(-1, 1),
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(got["residual_position"], want["residual_position"], rtol=0, atol=1e-15)
        assert [x is None for x in got["residual_orientation"]] == [x is None for x in want["residual_orientation"]]
        assert ("clearance" in want) == (got.get("clearance") is not None)
        if "clearance" in want:
            assert got["clearance"] == want["clearance"] and got["collisions"] == want["collisions"]


CASES = {
    "puma, its own limits (2π-equivalents of joints 4 and 6)": ("puma560_modified", {}, False),
    "puma, limits filtered out, reference, trimmed": (
        "puma560_modified", {"reference": [0.1, -0.5, 0.3, 0, 0.4, 0], "max_solutions": 3}, False),
    "puma, not filtered, degrees, l2 ordering with weights": (
        "puma560_modified", {"filter_limits": False, "angle_unit": "deg", "reference": [10, -20, 30, 0, 40, 0],
                             "ordering": {"norm": "l2", "weights": [2, 1, 1, 1, 1, 1]}, "max_joint_move": 150}, False),
    "puma, no limits, reference, weights, per-joint max_joint_move, max_solutions (the array path)": (
        "puma560_modified", {"limits": [None] * 6, "reference": [0.1, -0.5, 0.3, 0, 0.4, 0],
                             "ordering": {"weights": [2, 1, 1, 0.5, 1, 1]},
                             "max_joint_move": [2.5, 2.5, None, 3, 3, 3], "max_solutions": 5}, False),
    "puma, one-sided and narrow limits (one value per joint)": (
        "puma560_modified", {"limits": [{"lower": -3.2, "upper": 3.2}, None, {"lower": -1.0, "upper": None},
                                        None, {"lower": None, "upper": 2.0}, None],
                             "reference": [0, 0, 0, 0, 0, 0], "max_equivalents": 3}, False),
    "ur5, ±360° limits expand every joint": ("ur5", {}, False),
    "ur5, a cap that cuts the list": ("ur5", {"max_equivalents": 100, "reference": [0, 0, 0, 0, 0, 0]}, False),
    "ur5, no limits": ("ur5", {"limits": [None] * 6}, False),
    "stanford (prismatic joint), position and pose": ("spong_ex3_5_stanford", {}, False),
    "polar arm, position-only targets": ("ex004_2_polar_rrp", {}, True),
    "puma, collisions with a table and a post, not filtered by limits": (
        "puma560_standard", {"filter_limits": False, "collisions": {"margin": 0.005, "obstacles": [
            {"name": "table", "box": {"center": [0.55, 0.0, -0.15], "size": [0.5, 1.0, 0.1]}},
            {"name": "post", "capsule": {"from": [0.27, -0.2, -0.6], "to": [0.27, -0.2, 0.6], "radius": 0.06}}]}},
        False),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_arrays_form_equals_objects_form(client, case):
    robot_id, options, position_only = CASES[case]
    targets = _targets(client, robot_id, 40, seed=sorted(CASES).index(case), position_only=position_only)
    objects = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": targets, **options})
    arrays = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": targets, "format": "arrays", **options})
    assert objects.status_code == arrays.status_code == 200, arrays.text
    _assert_same(arrays.json(), _columns_of_objects(objects.json()["results"]))


def test_arrays_form_mixes_target_kinds_in_request_order(client):
    targets = _targets(client, "spong_ex3_5_stanford", 6, seed=7)
    mixed = [t if i % 2 else {"position": t["matrix"][0][3:] + t["matrix"][1][3:] + t["matrix"][2][3:]}
             for i, t in enumerate(targets)]
    objects = client.post("/v1/robots/spong_ex3_5_stanford/ik/batch", json={"targets": mixed})
    arrays = client.post("/v1/robots/spong_ex3_5_stanford/ik/batch", json={"targets": mixed, "format": "arrays"})
    assert objects.status_code == arrays.status_code == 200, arrays.text
    _assert_same(arrays.json(), _columns_of_objects(objects.json()["results"]))


def test_arrays_form_reports_a_bad_target_like_the_objects_form(client):
    targets = _targets(client, "puma560_modified", 3, seed=1)
    targets[2]["matrix"][0][0] = 2.0  # not a rotation
    for form in ("objects", "arrays"):
        response = client.post("/v1/robots/puma560_modified/ik/batch", json={"targets": targets, "format": form})
        assert response.status_code == 422
        assert any(e["loc"][:4] == ["body", "targets", 2, "matrix"] for e in response.json()["errors"])


@pytest.mark.parametrize("case", sorted(CASES))
def test_objects_form_is_what_its_model_says(client, case):
    """The batch objects form is encoded without passing through the response model: it must already be it."""
    from service.api.schemas.ik import IKBatchResponse

    robot_id, options, position_only = CASES[case]
    targets = _targets(client, robot_id, 15, seed=sorted(CASES).index(case), position_only=position_only)
    response = client.post(f"/v1/robots/{robot_id}/ik/batch",
                           json={"targets": targets, **{**options, "filter_limits": False}})
    assert response.status_code == 200
    body = response.json()
    assert IKBatchResponse.model_validate(body).model_dump(mode="json") == body


@pytest.mark.parametrize("case", sorted(CASES))
def test_single_answer_is_what_its_model_says(client, case):
    """A single IK answer is encoded without passing through IKResponse either: it must already be it, and be the
    batch's answer for the same target."""
    from service.api.schemas.ik import IKResponse

    robot_id, options, position_only = CASES[case]
    targets = _targets(client, robot_id, 3, seed=sorted(CASES).index(case), position_only=position_only)
    batch = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": targets, **options}).json()["results"]
    for target, expected in zip(targets, batch):
        response = client.post(f"/v1/robots/{robot_id}/ik", json={"target": target, **options})
        assert response.status_code == 200
        body = response.json()
        assert IKResponse.model_validate(body).model_dump(mode="json") == body
        _assert_same_answer(_ties_in_one_order(body), _ties_in_one_order(expected))


def _ties_in_one_order(answer: dict) -> dict:
    """The answer with each list of solutions sorted by joint values: solutions equally near the reference come
    in the solver's slot order, which the scalar path of one pose and the array path of a batch may differ in
    (the order by distance is tested with the ordering options)."""
    def key(solution):
        return [round(value, 9) for value in solution["joints"]]
    return {**answer, "solutions": sorted(answer["solutions"], key=key),
            "rejected": sorted(answer["rejected"], key=key)}


def _assert_same_answer(a, b, where: str = "") -> None:
    """Equal, but for the last bits of floats (the single pose takes the family's scalar path, a batch the
    array path)."""
    if isinstance(a, float) or isinstance(b, float):
        assert abs(a - b) <= 1e-9, where
    elif isinstance(a, dict):
        assert list(a) == list(b), where
        for key in a:
            _assert_same_answer(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b)):
            _assert_same_answer(x, y, f"{where}[{k}]")
    else:
        assert a == b, where


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "kuka_kr6_r900_2"])
def test_arrays_form_of_one_target(client, robot_id):
    """A batch of one pose is answered on the single-pose path (the float check of the scalar slots): its columns
    encode as the batch's do, and hold the objects form's answer."""
    targets = _targets(client, robot_id, 1, seed=3)[:1]
    for options in ({}, {"limits": [{"lower": -np.pi, "upper": np.pi}] * 6, "filter_limits": False}):
        objects = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": targets, **options})
        arrays = client.post(f"/v1/robots/{robot_id}/ik/batch",
                             json={"targets": targets, "format": "arrays", **options})
        assert objects.status_code == arrays.status_code == 200, arrays.text
        if options:  # ±π, flagged rather than filtered: at least the generating configuration is listed
            assert objects.json()["results"][0]["solutions"]
        _assert_same(arrays.json(), _columns_of_objects(objects.json()["results"]))
