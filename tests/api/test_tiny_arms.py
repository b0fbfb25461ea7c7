"""Inline arms of links 1e-11 to 2e-6 long with a slide, and targets metres out: requests within every cap that a
hostile probe sent. Each answered 500 (a stack of linear solves failed on one exactly singular system: the
Newton and Gauss–Newton steps damp J Jᵀ by an absolute λ far below its entries) or ran on past its deadline (a
family's representative walked towards a slide's reference 1e11 normalised lengths away, in 0.2 steps). Each is
now answered, and none says more than it knows.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from service.kinematics.ik import _general_6r
from service.kinematics.ik._general_6r_chain import newton

BODIES = Path(__file__).parent.parent / "data" / "tiny_arms"


@pytest.mark.parametrize("name", ["slide_arm_fk_pose", "slide_arm_direction", "slide_arm_position",
                                  "slide_far_along_a_family"])
def test_a_tiny_arm_with_a_slide_metres_out_is_answered(client, monkeypatch, name):
    body = json.loads((BODIES / f"{name}.json").read_text())
    calls = []

    def counted(*args, **kwargs):  # the family walk's Newton runs, bounded (before: 832,193,821,970 steps)
        calls.append(1)
        assert len(calls) < 2_000, "the walk along the family is not bounded"
        return newton(*args, **kwargs)

    monkeypatch.setattr(_general_6r, "newton", counted)
    response = client.post("/v1/ik", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["status"] in ("ok", "not_found", "unreachable")
    if name == "slide_arm_fk_pose":  # the arm's own pose: never out of reach
        assert answer["status"] != "unreachable"


def test_a_family_walk_takes_at_most_its_steps(monkeypatch):
    """The walk to a family's representative runs Newton at most MAX_FAMILY_STEPS times, however far the
    reference asks it to go, and a change that is not finite moves nothing."""
    calls = []
    monkeypatch.setattr(_general_6r, "newton", lambda *args, **kwargs: calls.append(1) or args[4])
    plan = _general_6r.General6RPlan.__new__(_general_6r.General6RPlan)
    plan.directions = plan.points = plan.revolute = None
    q = np.zeros((2, 6))
    change = np.array([[1e11, 0, 0, 0, 0, 0], [np.inf, 0, 0, 0, 0, 0]])
    moved = plan._along_family(np.tile(np.eye(4), (2, 1, 1)), q, change, np.zeros(2, dtype=int))
    assert len(calls) == _general_6r.MAX_FAMILY_STEPS
    assert moved[1].tolist() == [0.0] * 6 and moved[0, 0] == pytest.approx(1e11)
