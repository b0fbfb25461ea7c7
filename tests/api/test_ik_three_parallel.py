"""Three parallel axes without a spherical wrist, through the API: an inline arm of each new class answers in
closed form (``complete: true``) with the generating vector among its solutions."""

from __future__ import annotations

import numpy as np
import pytest

from tests.arms import THREE_PARALLEL_CASES as CASES, random_three_parallel_arm
from tests.ik_helpers import find, fk_inline, joints_of


def _description(robot) -> dict:
    return {"convention": robot.convention,
            "joints": [{"a": j.a, "alpha": j.alpha, "d": j.d, "theta": j.theta} for j in robot.joints],
            "base": robot.world_T_base.tolist(), "tool": robot.flange_T_tool.tolist()}


@pytest.mark.parametrize("case", sorted(CASES))
def test_an_inline_arm_of_each_class_is_solved_in_closed_form(client, case):
    robot = random_three_parallel_arm(case, "modified", seed=71)
    description = _description(robot)
    for q in np.random.default_rng(71).uniform(-np.pi, np.pi, (4, 6)):
        T = fk_inline(client, description, q)
        response = client.post("/v1/ik", json={"robot": description, "target": {"matrix": T.tolist()},
                                               "limits": [None] * 6})
        assert response.status_code == 200, response.text
        body = response.json()
        assert body["status"] == "ok"
        assert body["solver"] == {**body["solver"], "method": "analytic", "structure": CASES[case][0],
                                  "complete": True}
        assert find(robot, joints_of(body), q) is not None
