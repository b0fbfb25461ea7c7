"""Every inverse kinematics of textbook.md, every branch, through the API.

The oracle ``tests/oracles/textbook_ik.py`` writes the textbook's (corrected)
formulas out branch by branch; targets come from the independent closed-form FK
of ``tests/oracles/closed_forms.py``. For seeded random targets, every textbook
branch must be among the service's solutions (revolute joints mod 2π) and carry
the textbook's name for it; with the prismatic joints held ≥ 0, as the textbook
does, the service's set must be exactly the textbook's.
"""

from __future__ import annotations

import doctest
import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import catalogue_robot
from tests.ik_helpers import (
    find,
    joints_of,
    pose_target,
    random_configurations,
    slides_non_negative,
    unlimited,
)
from tests.oracles.closed_forms import CLOSED_FORMS
from tests.oracles import textbook_ik
from tests.oracles.textbook_ik import TEXTBOOK_IK

DATA = Path(__file__).resolve().parents[1] / "data"
TARGETS = 100

#: textbook.md §7: the number of branches the textbook gives (slides ≥ 0), per robot.
TEXTBOOK_COUNT = {
    "spong_ex3_1_planar_rr": 2,
    "spong_ex3_2_cylindrical_rpp": 1,
    "spong_ex3_3_spherical_wrist_rrr": 2,
    "spong_ex3_4_cylindrical_with_wrist": 2,
    "spong_ex3_5_stanford": 4,
    "spong_ex3_6_scara_rrpr": 2,
    "spong_ex4_3_elbow_with_wrist": 8,
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": 8,
    "spong_sec4_3_spherical_arm_rrp": 2,
    "spong_sec4_3_spherical_arm_table3_4_frames": 2,
    "assur001_scara_rrp": 2,
    "ex004_1_prp": 1,
    "ex004_2_polar_rrp": 2,
    "ex004_3_spherical_rrpr": 2,
    "ex004_4_polar_offset_rrp": 2,
    "puma560_modified": 8,
    "puma560_khalil": 8,
}


#: joint kinds in table order, for the oracle's own check (independent of the service)
TEXTBOOK_KINDS = {
    "spong_ex3_1_planar_rr": "RR", "spong_ex3_2_cylindrical_rpp": "RPP", "spong_ex3_3_spherical_wrist_rrr": "RRR",
    "spong_ex3_4_cylindrical_with_wrist": "RPPRRR", "spong_ex3_5_stanford": "RRPRRR", "spong_ex3_6_scara_rrpr": "RRPR",
    "spong_ex4_3_elbow_with_wrist": "RRRRRR", "spong_sec4_3_elbow_shoulder_offset_with_wrist": "RRRRRR",
    "spong_sec4_3_spherical_arm_rrp": "RRP", "spong_sec4_3_spherical_arm_table3_4_frames": "RRP",
    "assur001_scara_rrp": "RRP", "ex004_1_prp": "PRP", "ex004_2_polar_rrp": "RRP", "ex004_3_spherical_rrpr": "RRPR",
    "ex004_4_polar_offset_rrp": "RRP", "puma560_modified": "RRRRRR", "puma560_khalil": "RRRRRR",
}


def test_the_oracle_covers_every_textbook_robot():
    assert set(TEXTBOOK_IK) == set(TEXTBOOK_COUNT) == set(TEXTBOOK_KINDS)


def test_the_oracle_examples_hold():
    result = doctest.testmod(textbook_ik)
    assert result.attempted >= 3 and result.failed == 0


@pytest.mark.parametrize("robot_id", sorted(TEXTBOOK_IK))
def test_the_oracle_round_trips_through_the_closed_forms(robot_id):
    """The oracle itself: every branch reproduces the target under the independent closed-form FK."""
    kind, oracle = TEXTBOOK_IK[robot_id]
    rng = np.random.default_rng(7)
    for _ in range(50):
        q = rng.uniform(-np.pi, np.pi, len(TEXTBOOK_KINDS[robot_id]))
        slides = np.array([kind_ == "P" for kind_ in TEXTBOOK_KINDS[robot_id]])
        q[slides] = rng.uniform(0.1, 1.0, slides.sum()) * (100.0 if robot_id.startswith("assur") else 1.0)
        T = CLOSED_FORMS[robot_id](q)
        branches = oracle(T if kind == "pose" else T[:3, 3])
        assert len(branches) >= TEXTBOOK_COUNT[robot_id]
        for branch in branches:
            reached = CLOSED_FORMS[robot_id](branch.joints)
            error = np.abs(reached - T).max() if kind == "pose" else np.abs(reached[:3, 3] - T[:3, 3]).max()
            assert error < 1e-9 * max(1.0, np.abs(T[:3, 3]).max()), branch.name


def _targets(robot_id: str, q: np.ndarray, kind: str) -> tuple[list[np.ndarray], list[dict]]:
    poses = [CLOSED_FORMS[robot_id](row) for row in q]
    return poses, [pose_target(T, kind) for T in poses]


@pytest.mark.parametrize("robot_id", sorted(TEXTBOOK_IK))
def test_every_textbook_branch_is_a_solution_with_the_textbook_name(client, robot_id):
    kind, oracle = TEXTBOOK_IK[robot_id]
    robot = catalogue_robot(client, robot_id)
    q = random_configurations(robot, TARGETS, seed=100 + sorted(TEXTBOOK_IK).index(robot_id))
    poses, targets = _targets(robot_id, q, kind)
    everything = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": targets, "limits": unlimited(robot)})
    textbook = client.post(f"/v1/robots/{robot_id}/ik/batch",
                           json={"targets": targets, "limits": slides_non_negative(robot)})
    assert everything.status_code == 200 and textbook.status_code == 200
    labelled = 0
    for T, all_solutions, kept in zip(poses, everything.json()["results"], textbook.json()["results"]):
        branches = oracle(T if kind == "pose" else T[:3, 3])
        assert len([b for b in branches if not b.negative_slide]) == TEXTBOOK_COUNT[robot_id]
        solutions = joints_of(all_solutions)
        for branch in branches:
            index = find(robot, solutions, branch.joints)
            assert index is not None, (branch.name, branch.joints, solutions)
            label = all_solutions["solutions"][index]["branch"]
            for name, value in branch.labels.items():
                assert label.get(name) == value, (name, branch.name, branch.joints, label)
                labelled += 1
        # the textbook keeps prismatic joints >= 0: then the service's set is the textbook's, exactly
        textbook_set = [b.joints for b in branches if not b.negative_slide]
        kept_solutions = joints_of(kept)
        assert len(kept_solutions) == len(textbook_set)
        assert all(find(robot, kept_solutions, joints) is not None for joints in textbook_set)
    names = {name for b in oracle(poses[0] if kind == "pose" else poses[0][:3, 3]) for name in b.labels}
    assert labelled >= len(names) * TARGETS  # the labels were really compared


# --------------------------------------------------------------------------
# Spong Example 4.1 (the Stanford arm), with the book's numbers
# --------------------------------------------------------------------------

EXAMPLE = json.loads((DATA / "textbook_ik_examples.json").read_text())["spong_ex3_5_stanford"][0]
STANFORD = "spong_ex3_5_stanford"


def _example_request(**extra) -> dict:
    return {"target": {"matrix": EXAMPLE["target"]}, **extra}


def test_example_4_1_book_solution_reaches_the_book_target(client):
    response = client.post(f"/v1/robots/{STANFORD}/fk", json={"joints": EXAMPLE["book_solution"]})
    assert np.abs(np.array(response.json()["pose"]["matrix"]) - EXAMPLE["target"]).max() < 1e-12
    assert np.abs(CLOSED_FORMS[STANFORD](EXAMPLE["book_solution"]) - EXAMPLE["target"]).max() < 1e-12


def test_example_4_1_every_branch_with_the_books_numbers(client):
    robot = catalogue_robot(client, STANFORD)
    response = client.post(f"/v1/robots/{STANFORD}/ik", json=_example_request(limits=slides_non_negative(robot)))
    assert response.status_code == 200
    result = response.json()
    assert result["status"] == "ok"
    assert result["solver"]["complete"] is True and result["solver"]["method"] == "analytic"
    solutions = joints_of(result)
    assert len(solutions) == len(EXAMPLE["solutions"]) == 3  # left arm: one family; right arm: flip and no flip
    for expected in EXAMPLE["solutions"]:
        index = find(robot, solutions, expected["joints"])
        assert index is not None, expected
        assert result["solutions"][index]["branch"] == expected["branch"]  # no wrist label in the singular family
        if "printed" in expected:  # the numbers printed in textbook.md §2.5
            assert np.abs(solutions[index] - expected["printed"]).max() < EXAMPLE["tolerance"]["printed_digits"]
        assert result["solutions"][index]["residual"]["position"] < 1e-9
        assert result["solutions"][index]["residual"]["orientation"] < 1e-9
    # theta5 = 0: the wrist singularity, theta4 + theta6 = pi. The report is per target: the left arm's
    # retracted twin (d3 = -0.5, theta5 = pi: only theta4 - theta6 is determined) is listed in `rejected`.
    wrist = [s for s in result["singularities"] if s["kind"] == "wrist"]
    assert [(s["joints"], s["relation"]) for s in wrist] == [([3, 5], "sum"), ([3, 5], "difference")]
    twin = [s for s in result["rejected"] if abs(s["joints"][2] + 0.5) < 1e-12 and abs(np.sin(s["joints"][4])) < 1e-9]
    assert len(twin) == 1 and np.cos(twin[0]["joints"][4]) == pytest.approx(-1.0)
    assert twin[0]["branch"] == {"shoulder": "left"}
    left = solutions[find(robot, solutions, EXAMPLE["solutions"][0]["joints"])]
    assert left[3] == pytest.approx(0.0, abs=1e-12)  # no reference: the free joint is 0
    assert np.cos(left[3] + left[5]) == pytest.approx(-1.0, abs=1e-12)  # theta4 + theta6 = pi
    assert left[4] == pytest.approx(0.0, abs=1e-9)


def test_example_4_1_reference_sets_the_free_wrist_joint(client):
    """With the book's solution as reference, the representative of the singular family IS the book's solution."""
    robot = catalogue_robot(client, STANFORD)
    response = client.post(f"/v1/robots/{STANFORD}/ik", json=_example_request(
        limits=slides_non_negative(robot), reference=EXAMPLE["book_solution"]))
    result = response.json()
    first = np.array(result["solutions"][0]["joints"])  # nearest first
    assert np.abs(first - EXAMPLE["book_solution"]).max() < 1e-9
    assert result["solutions"][0]["branch"]["shoulder"] == "left"


def test_example_4_1_within_the_catalogue_limits(client):
    """textbook_ik_examples.json notes: with θ4 = 20°, the left family member (20°, 0, 160°) fits every limit."""
    reference = np.array(EXAMPLE["book_solution"])
    reference[3] = np.radians(20)
    result = client.post(f"/v1/robots/{STANFORD}/ik", json=_example_request(reference=reference.tolist())).json()
    assert result["status"] == "ok"
    left = [s for s in result["solutions"] if s["branch"].get("shoulder") == "left"]
    assert len(left) == 1
    q = np.array(left[0]["joints"])
    assert np.degrees(q[[3, 5]]) == pytest.approx([20.0, 160.0], abs=1e-7)
    assert all(s["within_limits"] for s in result["solutions"])
    # the right-arm no_flip solution breaks the theta4 limit [-260, 80] deg: it is rejected, with its violation
    assert any(v["joint"] == 3 for s in result["rejected"] for v in s["violations"])


# --------------------------------------------------------------------------
# File 001: the Assur SCARA's trajectory table (textbook.md §4.4), positions
# --------------------------------------------------------------------------

ASSUR = json.loads((DATA / "assur_spiral_tables.json").read_text())


@pytest.mark.parametrize("mode", [1, 2])
def test_assur_scara_table_positions_both_assembly_modes(client, mode):
    """Each row's (θ1, θ2, l3), paper convention, is the service's assembly-mode solution (q2_DH = −θ2)."""
    robot = catalogue_robot(client, "assur001_scara_rrp")
    rows = np.array(ASSUR["tables"][f"mode_{mode}"]["rows"], dtype=float)
    t = rows[:, 0]
    targets = [{"position": [100 + 20 * np.sin(np.pi * s / 2), -20 * np.cos(np.pi * s / 2), 50 + 10 * s]} for s in t]
    results = client.post("/v1/robots/assur001_scara_rrp/ik/batch",
                          json={"targets": targets, "limits": unlimited(robot)}).json()["results"]
    for row, result in zip(rows, results):
        solutions = joints_of(result)
        assert len(solutions) == 2
        index = find(robot, solutions, [row[1], -row[4], row[7]], tolerance=5e-6 * max(1.0, row[7]))
        assert index is not None, (row, solutions)
        assert result["solutions"][index]["branch"] == {"assembly_mode": mode}


# --------------------------------------------------------------------------
# Errata (textbook.md §10): the misprinted formulas give no solution; the corrected ones are the service's
# --------------------------------------------------------------------------


def test_scara_eq_4_62_as_printed_is_not_a_solution(client):
    """Erratum 3: d3 = oz + d4 (printed) vs d3 = −oz − d4. For every target the printed d3 misses, the service's
    d3 is the corrected one."""
    robot = catalogue_robot(client, "spong_ex3_6_scara_rrpr")
    q = random_configurations(robot, 30, seed=9)
    _, targets = _targets("spong_ex3_6_scara_rrpr", q, "pose")
    results = client.post("/v1/robots/spong_ex3_6_scara_rrpr/ik/batch", json={"targets": targets}).json()["results"]
    for target, result in zip(targets, results):
        oz = target["matrix"][2][3]
        d3 = joints_of(result)[:, 2]
        assert np.allclose(d3, -oz - 0.2, atol=1e-12)
        assert np.abs(d3 - (oz + 0.2)).min() > 1e-3


def test_elbow_formulas_without_d1_are_not_solutions(client):
    """Erratum 4: with Table 4.1's d1 = 0.5, the source's literal zc (the corrected formulas with d1 = 0) gives
    joint vectors that are not solutions; the service returns the corrected ones (compared above)."""
    robot = catalogue_robot(client, "spong_ex4_3_elbow_with_wrist")
    q = random_configurations(robot, 20, seed=10)
    checked = 0
    for row in q:
        T = CLOSED_FORMS["spong_ex4_3_elbow_with_wrist"](row)
        literal = textbook_ik.elbow_with_wrist(T, d1=0.0, a2=1.0, a3=0.8, d6=0.2)
        result = client.post("/v1/robots/spong_ex4_3_elbow_with_wrist/ik",
                             json={"target": {"matrix": T.tolist()}}).json()
        for branch in literal:
            assert find(robot, joints_of(result), branch.joints, tolerance=1e-6) is None
            assert np.abs(CLOSED_FORMS["spong_ex4_3_elbow_with_wrist"](branch.joints) - T).max() > 1e-3
            checked += 1
    assert checked >= 40
