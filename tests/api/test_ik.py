"""Inverse kinematics through the API: limits, singular, unreachable and under-determined targets, the numeric
fallback, reference ordering and the UR5's solution counts.

The textbook's own IK, branch by branch, is in ``test_ik_textbook.py``; the same arms described another way in
``test_ik_frames.py``; 1,000 random vectors per catalogue robot in ``test_ik_recall.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import catalogue_robot
from tests.ik_helpers import find, joints_of, unlimited
from tests.oracles.closed_forms import CLOSED_FORMS


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
