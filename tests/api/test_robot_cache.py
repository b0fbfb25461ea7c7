"""Inline robots are built once per description (a bounded LRU cache with metrics); robots with a request's own
base/tool are kept on their parent, so their IK plans are built once too."""

from __future__ import annotations

import re

import numpy as np
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.api.robot_cache import RobotCache
from service.config import Settings
from service.kinematics import Robot
from service.kinematics._robot import FRAMED_ROBOTS_KEPT
from service.kinematics.ik import cached_plan
from tests.arms import SKEW_6R_ROBOT  # a general 6R arm: its plan is the costliest to build


def _lookups(client, outcome: str) -> float:
    text = client.get("/metrics").text
    found = re.search(rf'kin_robot_cache_lookups_total{{cache="inline",outcome="{outcome}"}} ([\d.e+]+)', text)
    return float(found.group(1)) if found else 0.0


def _pose(client, robot: dict, joints: list[float]) -> list:
    response = client.post("/v1/fk", json={"robot": robot, "joints": joints})
    assert response.status_code == 200, response.text
    return response.json()["pose"]["matrix"]


def test_the_same_inline_description_is_built_once_and_answers_the_same():
    with TestClient(create_app(Settings(robot_cache_size=2))) as client:
        hits, misses = _lookups(client, "hit"), _lookups(client, "miss")
        target = {"matrix": _pose(client, SKEW_6R_ROBOT, [0.3, -0.2, 0.5, 0.1, 0.4, -0.6])}  # the one build
        first = client.post("/v1/ik", json={"robot": SKEW_6R_ROBOT, "target": target}).json()
        second = client.post("/v1/ik", json={"robot": SKEW_6R_ROBOT, "target": target}).json()
        assert first == second and first["status"] == "ok"
        assert _lookups(client, "miss") - misses == 1 and _lookups(client, "hit") - hits == 2
        # the cached object carries the plan built by the first request
        cache: RobotCache = client.app.state.inline_robots
        (robot,) = [r for r in cache._entries.values() if r.dof == 6 and np.allclose(r.a, [j["a"] for j in
                                                                                          SKEW_6R_ROBOT["joints"]])]
        assert cached_plan(robot, constrain_orientation=True, reference=None) is \
            cached_plan(robot, constrain_orientation=True, reference=None)


def test_the_cache_is_bounded_least_recently_used_first():
    with TestClient(create_app(Settings(robot_cache_size=2))) as client:
        cache: RobotCache = client.app.state.inline_robots
        arms = [{"convention": "standard", "joints": [{"a": 0.1 * (k + 1)}, {"a": 0.2}]} for k in range(3)]
        for arm in (arms[0], arms[1], arms[0], arms[2]):  # arms[1] is the least recently used when arms[2] comes
            assert client.post("/v1/fk", json={"robot": arm, "joints": [0, 0]}).status_code == 200
        kept = sorted(float(robot.a[0]) for robot in cache._entries.values())
        assert len(cache) == 2 and np.allclose(kept, [0.1, 0.3])


def test_a_description_that_fails_is_not_kept_and_fails_every_time():
    with TestClient(create_app(Settings(robot_cache_size=4))) as client:
        bad = {"convention": "standard", "joints": [{"a": 0.1, "alpha": "not a number"}]}
        for _ in range(2):
            assert client.post("/v1/fk", json={"robot": bad, "joints": [0]}).status_code == 422
        wrong_sign = {"convention": "standard", "joints": [{"a": 0.1, "limits": {"lower": 1.0, "upper": -1.0}}]}
        for _ in range(2):
            assert client.post("/v1/fk", json={"robot": wrong_sign, "joints": [0]}).status_code == 422
        assert len(client.app.state.inline_robots) == 0


def test_size_zero_turns_the_cache_off():
    with TestClient(create_app(Settings(robot_cache_size=0))) as client:
        arm = {"convention": "standard", "joints": [{"a": 0.1}]}
        for _ in range(2):
            assert client.post("/v1/fk", json={"robot": arm, "joints": [0]}).status_code == 200
        assert len(client.app.state.inline_robots) == 0


def test_with_frames_returns_the_kept_robot_for_the_same_frames(client):
    robot: Robot = client.app.state.catalogue.get("ur5").robot
    tool = np.eye(4)
    tool[2, 3] = 0.1
    framed = robot.with_frames(None, tool)
    assert robot.with_frames(None, tool.copy()) is framed
    assert robot.with_frames(tool, None) is not framed and robot.with_frames(None, np.eye(4)) is not framed
    assert np.allclose(framed.flange_T_tool, tool) and np.allclose(framed.world_T_base, robot.world_T_base)
    for k in range(FRAMED_ROBOTS_KEPT + 5):  # bounded: older frames are dropped, then built anew
        other = np.eye(4)
        other[0, 3] = 0.01 * (k + 1)
        robot.with_frames(None, other)
    assert robot.with_frames(None, tool) is not framed
    assert robot.derived.namespace_size("with_frames") == FRAMED_ROBOTS_KEPT
