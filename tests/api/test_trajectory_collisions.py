"""Trajectories that stay on collision-free branches (issue 25, item 3): over HTTP on the PUMA 560 and its capsule
model, every sample's clearance recomputed independently from the FK link frames (tests/collision_check.py), the
branch change a collision forces checked against single IK's solutions at that pose, and the rules for a branch
that is blocked everywhere, a held branch, the filter off, the cost cap and hostile options."""

from __future__ import annotations

import numpy as np
import pytest

from tests.collision_check import independent_check
from tests.ik_helpers import wrapped

ROBOT = "puma560_standard"
START = [0.4, 0.6, -2.0, 0.7, 1.1, -0.5]  # elbow up
MOVE = np.array([-0.1, 0.1, 0.05])  # the tool's straight move, metres, orientation held
SAMPLES = 21
#: A lamp the elbow-up branch's upper arm meets two thirds of the way (found by a search over random spheres
#: near the arm; the elbow-down branch passes it).
LAMP = {"name": "lamp", "sphere": {"center": [0.362, 0.138, 0.390], "radius": 0.03}}


@pytest.fixture(scope="module")
def path(client) -> list[dict]:
    start = np.array(client.post(f"/v1/robots/{ROBOT}/fk", json={"joints": START}).json()["pose"]["matrix"])
    samples = []
    for k in range(SAMPLES):
        pose = start.copy()
        pose[:3, 3] += MOVE * k / (SAMPLES - 1)
        samples.append({"time": 0.1 * k, "pose": {"matrix": pose.tolist()}})
    return samples


def _follow(client, samples, **options) -> dict:
    response = client.post(f"/v1/robots/{ROBOT}/ik/trajectory", json={"samples": samples, "reference": START,
                                                                        **options})
    assert response.status_code == 200, response.text
    return response.json()


def _reaches(client, joints, pose) -> bool:
    reached = client.post(f"/v1/robots/{ROBOT}/fk", json={"joints": joints}).json()["pose"]["matrix"]
    return np.allclose(reached, pose["matrix"], atol=1e-9)


def test_a_collision_forces_a_branch_change_and_says_so(client, path):
    plain = _follow(client, path)
    assert not plain["summary"]["branch_changes"] and "clearance" not in plain["samples"][0]
    assert "colliding_samples" not in plain["summary"]
    collisions = {"self": False, "obstacles": [LAMP]}
    answer = _follow(client, path, collisions=collisions)
    samples, summary = answer["samples"], answer["summary"]
    forced = summary["collision_branch_changes"]
    assert forced == [k for k, s in enumerate(samples) if s["collision_forced"]] and len(forced) == 1
    k = forced[0]
    assert 0 < k < SAMPLES - 1 and k in summary["branch_changes"] and samples[k]["branch_changed"]
    assert samples[k - 1]["branch"]["elbow"] == "up" and samples[k]["branch"]["elbow"] == "down"
    for before, free in zip(plain["samples"][:k], samples[:k]):  # the path is clear until k: unchanged
        assert np.allclose(before["joints"], free["joints"], atol=1e-9)
    # at k, the solution single IK lists nearest the previous sample's joints collides: the continuation
    solutions = client.post(f"/v1/robots/{ROBOT}/ik", json={"target": path[k]["pose"], "filter_limits": False}
                            ).json()["solutions"]
    previous = np.array(samples[k - 1]["joints"])
    continuation = min(solutions, key=lambda s: np.linalg.norm(wrapped(np.array(s["joints"]) - previous)))
    assert independent_check(client, ROBOT, continuation["joints"], [LAMP], 0.0, self_collision=False)[0] < 0
    for sample, pose in zip(samples, path):
        assert sample["status"] == "ok" and _reaches(client, sample["joints"], pose["pose"])
        clearance, close = independent_check(client, ROBOT, sample["joints"], [LAMP], 0.0, self_collision=False)
        assert sample["clearance"] == pytest.approx(clearance, abs=1e-9) and clearance >= 0
        assert sample["collisions"] == [] and not close
    assert summary["colliding_samples"] == []
    assert summary["smallest_clearance"]["value"] == min(s["clearance"] for s in samples)


def test_a_held_branch_that_collides_keeps_its_labels_and_says_no_collision_free_solution(client, path):
    # the lamp meets the upper arm, which both wrists of the right-shoulder elbow-up branch share
    answer = _follow(client, path, branch={"shoulder": "right", "elbow": "up"},
                     collisions={"self": False, "obstacles": [LAMP]})
    samples = answer["samples"]
    blocked = [k for k, s in enumerate(samples) if s["status"] == "no_collision_free_solution"]
    assert blocked and blocked == answer["summary"]["colliding_samples"]
    assert all(s["branch"]["elbow"] == "up" and s["branch"]["shoulder"] == "right" and not s["collision_forced"]
               for s in samples)
    for k in blocked:
        clearance, close = independent_check(client, ROBOT, samples[k]["joints"], [LAMP], 0.0, self_collision=False)
        assert clearance < 0 and samples[k]["clearance"] == pytest.approx(clearance, abs=1e-9)
        assert [(p["a"], p["b"]) for p in samples[k]["collisions"]] == list(close)


def test_a_path_blocked_everywhere_continues_and_lists_each_collision(client, path):
    cage = {"name": "cage", "box": {"center": [0, 0, 0], "size": [3, 3, 3]}}
    plain = _follow(client, path)
    answer = _follow(client, path, collisions={"obstacles": [cage]})
    assert [s["status"] for s in answer["samples"]] == ["no_collision_free_solution"] * SAMPLES
    assert answer["summary"]["colliding_samples"] == list(range(SAMPLES))
    assert not answer["summary"]["collision_branch_changes"]
    for blocked, free in zip(answer["samples"], plain["samples"]):  # nothing to prefer: the branch is kept
        assert np.allclose(blocked["joints"], free["joints"], atol=1e-9)
        assert any(pair["b"] == "cage" for pair in blocked["collisions"])


def test_without_the_filter_the_path_is_unchanged_and_flagged(client, path):
    plain = _follow(client, path)
    flagged = _follow(client, path, collisions={"self": False, "filter": False, "obstacles": [LAMP]})
    colliding = []
    for k, (before, sample) in enumerate(zip(plain["samples"], flagged["samples"])):
        assert np.allclose(before["joints"], sample["joints"], atol=1e-9) and not sample["collision_forced"]
        clearance, _ = independent_check(client, ROBOT, sample["joints"], [LAMP], 0.0, self_collision=False)
        assert sample["clearance"] == pytest.approx(clearance, abs=1e-9)
        if clearance < 0:
            colliding.append(k)
    assert colliding and flagged["summary"]["colliding_samples"] == colliding
    assert flagged["summary"]["collision_branch_changes"] == []


def test_a_check_past_its_cap_is_refused_before_any_work(path):
    from fastapi.testclient import TestClient

    from service.api.app import create_app
    from service.config import Settings

    with TestClient(create_app(Settings(_env_file=None, max_collision_checks=100))) as capped:
        response = capped.post(f"/v1/robots/{ROBOT}/ik/trajectory",
                               json={"samples": path, "collisions": {"obstacles": [LAMP]}})
    assert response.status_code == 413, response.text
    assert "KIN_MAX_COLLISION_CHECKS = 100" in response.json()["detail"]


@pytest.mark.parametrize("collisions, location", [
    ({"obstacles": [{"name": "ball", "sphere": {"center": [0, 0, 1], "radius": -0.1}}]},
     ["body", "collisions", "obstacles", 0, "sphere", "radius"]),
    ({"ignore": [[0, 9]]}, ["body", "collisions", "ignore", 0, 1]),
    ({"obstacles": [{"name": "link 2", "sphere": {"center": [0, 0, 1], "radius": 0.1}}]},
     ["body", "collisions", "obstacles", 0, "name"]),
])
def test_hostile_collision_options_are_located_422s(client, path, collisions, location):
    response = client.post(f"/v1/robots/{ROBOT}/ik/trajectory", json={"samples": path, "collisions": collisions})
    assert response.status_code == 422, response.text
    assert response.headers["content-type"] == "application/problem+json"
    assert any(error["loc"][:len(location)] == location for error in response.json()["errors"]), response.json()
