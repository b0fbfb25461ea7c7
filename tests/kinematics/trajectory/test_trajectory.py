"""Branch-consistent trajectories in the core: the Assur SCARA through the RRR group, branch rules, singular
samples, limits and the summary, and the validation of samples.

Golden data: ``tests/data/assur_spiral_tables.json`` (textbook.md §4.4).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import (InvalidInputError, Joint, Limits, Robot, TrajectoryOptions, follow_trajectory,
                                forward_kinematics)
from service.kinematics._assur import assur_scara_forward, assur_scara_inverse
from service.kinematics._assur_arm import assur_scara_of
from service.kinematics._trajectory import _follow, ambiguous_labels
from service.kinematics.ik import IKOptions, IKResult, Singularity, Solution
from tests.conftest import DATA
from tests.ik_helpers import wrapped
from tests.oracles.paths import spiral

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
TABLES = json.loads((DATA / "assur_spiral_tables.json").read_text())
NAN3 = [np.nan] * 3


def robot(robot_id: str) -> Robot:
    return CATALOGUE.get(robot_id).robot


def position_targets(points) -> np.ndarray:
    T = np.tile(np.eye(4), (len(points), 1, 1))
    T[:, :3, 3] = points
    return T


def linear(vectors) -> np.ndarray:
    """Twists or accelerations with only the linear part given."""
    return np.concatenate([np.asarray(vectors, dtype=float), np.full((len(vectors), 3), np.nan)], axis=1)


# ---------------------------------------------------------------------------
# The paper's SCARA found in a robot
# ---------------------------------------------------------------------------


def test_the_catalogue_assur_scara_is_the_papers_geometry_and_joint_map():
    assur = assur_scara_of(robot("assur001_scara_rrp"))
    assert (assur.l_OA, assur.l_AB, assur.l_BC) == (150.0, 80.0, 50.0)
    q, qd, qdd = assur.paper_from_joints([0.5, 0.7, 100.0], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0])
    np.testing.assert_allclose(q, [0.5, -0.7, 100.0])  # q2_DH = -theta2_paper (textbook.md §4.1)
    np.testing.assert_allclose(qd, [1.0, -2.0, 3.0])
    np.testing.assert_allclose(qdd, [4.0, -5.0, 6.0])
    others = [e.description.id for e in CATALOGUE.entries() if assur_scara_of(e.robot) is not None]
    assert others == ["assur001_scara_rrp"]


def craig_scara(flip_elbow: bool) -> Robot:
    """The paper's SCARA in Craig's convention on a moved and turned base; optionally joint 2's axis points down."""
    base = np.eye(4)
    c, s = np.cos(0.6), np.sin(0.6)
    base[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    base[:3, 3] = [10.0, -5.0, 20.0]
    alpha = np.pi if flip_elbow else 0.0
    return Robot([Joint("t1", "revolute", 0.0, 0.0, 150.0, 0.3), Joint("t2", "revolute", 80.0, alpha, 0.0, -0.2),
                  Joint("l3", "prismatic", 50.0, np.pi - alpha, 0.0, 0.0)], convention="modified",
                 world_T_base=base)


@pytest.mark.parametrize("flip_elbow", [False, True])
def test_joint_map_of_another_description_reproduces_the_papers_forward_kinematics(flip_elbow):
    """joints_from_paper then FK gives the paper's FK (textbook.md §4.1) in the paper's frame, for any frames."""
    arm = craig_scara(flip_elbow)
    assur = assur_scara_of(arm)
    assert (assur.l_AB, assur.l_BC) == pytest.approx((80.0, 50.0), abs=1e-12)
    rng = np.random.default_rng(0)
    theta1, theta2 = rng.uniform(-3, 3, (2, 50))
    l3 = rng.uniform(0, 100, 50)
    paper = assur_scara_inverse(np.zeros((50, 3)), np.zeros((50, 3)), np.zeros((50, 3)), 1, 1, 1, 1)
    paper = type(paper)(**{**paper.__dict__, "theta1": theta1, "theta2": theta2, "l3": l3})
    q, _, _ = assur.joints_from_paper(paper)
    tool = forward_kinematics(arm, q)[:, :3, 3]
    np.testing.assert_allclose(assur.to_paper_points(tool),
                               assur_scara_forward(theta1, theta2, l3, assur.l_OA, assur.l_AB, assur.l_BC), atol=1e-10)
    back, _, _ = assur.paper_from_joints(q)
    np.testing.assert_allclose(back, np.stack([theta1, theta2, l3], axis=-1), atol=1e-12)


# ---------------------------------------------------------------------------
# The paper's example through the trajectory core
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("mode", [1, 2])
def test_spiral_follows_the_group_and_the_table(mode):
    t = np.arange(9.0)
    D, Dd, Ddd = spiral(t)
    result = follow_trajectory(robot("assur001_scara_rrp"), t, position_targets(D), constrain_orientation=False,
                               twists=linear(Dd), accelerations=linear(Ddd),
                               options=TrajectoryOptions(branch={"assembly_mode": mode}))
    assert result.rates == "assur_group" and result.task.names == ("vx", "vy", "vz")
    group = assur_scara_inverse(D, Dd, Ddd, 150.0, 80.0, 50.0, mode)
    paper = np.array([np.concatenate([s.paper.joints, s.paper.velocities, s.paper.accelerations])
                      for s in result.samples])
    np.testing.assert_allclose(paper, np.concatenate([group.q, group.qd, group.qdd], axis=1), rtol=0, atol=1e-12)
    rows = np.array(TABLES["tables"][f"mode_{mode}"]["rows"])
    ours = paper[:, [0, 3, 6, 1, 4, 7, 2, 5, 8]]
    np.testing.assert_allclose(ours, rows[:, 1:], rtol=5e-6, atol=1e-6)
    assert all(s.branch == {"assembly_mode": mode} and not s.branch_changed and not s.singularities
               for s in result.samples)
    np.testing.assert_allclose([s.joints for s in result.samples], group.q * [1, -1, 1], atol=1e-12)
    assert max(s.velocity_residual for s in result.samples) < 1e-15
    assert max(s.acceleration_residual for s in result.samples) < 1e-15


# ---------------------------------------------------------------------------
# The group's singular cases
# ---------------------------------------------------------------------------


T5 = np.linspace(0.0, 2.0, 5)


def radial(robot_, x, xd, xdd, y=None, yd=None, **options):
    """A path along x (and optionally y) at height 60 mm, twist and acceleration given."""
    zero = np.zeros_like(T5)
    y, yd = (zero, zero) if y is None else (y, yd)
    return follow_trajectory(robot_, T5, position_targets(np.stack([x, y, zero + 60], -1)),
                             constrain_orientation=False, twists=linear(np.stack([xd, yd, zero], -1)),
                             accelerations=linear(np.stack([xdd, zero, zero], -1)),
                             options=TrajectoryOptions(**options))


def kinds(sample) -> list[tuple[str, str]]:
    return [(s.kind, s.relation) for s in sample.singularities]


@pytest.mark.parametrize(("name", "x", "xd", "elbow"), [
    ("stretched", 130 - 20 * (T5 - 1) ** 2, -40 * (T5 - 1), 0.0),
    ("folded", 30 + 20 * (T5 - 1) ** 2, 40 * (T5 - 1), np.pi),
])
def test_aligned_group_gives_positions_flags_and_no_rates(name, x, xd, elbow):
    arm = robot("assur001_scara_rrp")
    y, yd = 5 * (T5 - 1), 5 + 0 * T5  # moving along the boundary circle at t = 1: a motion the arm can make
    result = radial(arm, x, xd, -40 + 0 * T5, y, yd, branch={"assembly_mode": 2})
    singular = result.samples[2]
    assert kinds(singular) == [("assur_group", "aligned"), ("jacobian", "near_singular")]
    assert name in singular.singularities[0].detail
    assert singular.paper.case == "aligned" and singular.distance_to_singularity < 1e-12
    np.testing.assert_allclose(np.abs(singular.paper.joints), [0.0, elbow, 90.0], atol=1e-12)
    assert np.isnan(singular.velocities).all() and np.isnan(singular.accelerations).all() and not singular.damped
    assert singular.branch == {"assembly_mode": 2} and not any(s.branch_changed for s in result.samples)
    assert result.summary.singular_samples == [2]
    for k in (0, 1, 3, 4):
        assert np.isfinite(result.samples[k].velocities).all() and result.samples[k].paper.case == "regular"
    damped = radial(arm, x, xd, -40 + 0 * T5, y, yd, branch={"assembly_mode": 2}, damping=0.01).samples[2]
    assert damped.damped and np.isfinite(damped.velocities).all()
    assert damped.velocity_residual < 0.05  # close to the requested twist, not equal to it


def test_coincident_group_keeps_the_free_joint_of_the_previous_sample():
    """Equal arms (50, 50 mm), the tool crossing the shoulder axis: θ1 is free there."""
    arm = Robot([Joint("t1", "revolute", 50.0, 0, 150.0, 0), Joint("t2", "revolute", 50.0, np.pi, 0, 0),
                 Joint("l3", "prismatic", 0, 0, 0, 0)])
    result = radial(arm, 20 * (T5 - 1), 20 + 0 * T5, 0 * T5, reference=np.array([1.8, 2.7, 90.0]))
    before, at = result.samples[1], result.samples[2]
    assert kinds(at) == [("assur_group", "coincident"), ("jacobian", "near_singular")]
    assert at.paper.case == "coincident" and np.isnan(at.velocities).all()
    assert at.joints[0] == before.joints[0]  # joint 1 continues
    np.testing.assert_allclose(forward_kinematics(arm, at.joints)[:3, 3], [0, 0, 60], atol=1e-12)
    np.testing.assert_allclose(abs(at.joints[1]), np.pi, atol=1e-12)
    assert result.summary.singular_samples == [2]


def test_unreachable_samples_are_reported_and_the_path_continues_after_them():
    arm = robot("assur001_scara_rrp")
    result = radial(arm, 120 + 20 * (T5 - 1) ** 2, 40 * (T5 - 1), 40 + 0 * T5, branch={"assembly_mode": 1})
    assert [s.status for s in result.samples] == ["unreachable", "ok", "ok", "ok", "unreachable"]
    assert result.summary.unreachable_samples == [0, 4]
    assert result.samples[0].joints is None and result.samples[0].paper is None
    assert all(s.paper.case == "regular" for s in result.samples[1:4])
    assert np.isnan(result.summary.largest_joint_step).sum() == 0  # samples 1-3 are consecutive


# ---------------------------------------------------------------------------
# Branch rules, on hand-made IK results
# ---------------------------------------------------------------------------


def fake(solutions, singularities=()):
    return IKResult("ok" if solutions else "unreachable",
                    [Solution(np.array(q, dtype=float), dict(b), 0.0, 0.0) for q, b in solutions],
                    "analytic", "fake", True, list(singularities))


RR = Robot([Joint("q1", "revolute", 1.0, 0, 0, 0), Joint("q2", "revolute", 0.5, 0, 0, 0)])


def follow_fake(results, held=None, reference=None):
    times = np.arange(float(len(results)))
    return _follow(RR, times, np.tile(np.eye(4), (len(results), 1, 1)), results, held or {}, reference,
                   Limits.of(RR), False, IKOptions())


def test_held_labels_choose_the_branch_and_are_kept_through_a_singular_sample():
    up, down = {"elbow": "up"}, {"elbow": "down"}
    stretched = Singularity("elbow", (1,), "stretched_or_folded")
    results = [fake([([0.0, 0.5], up), ([0.5, -0.5], down)]),
               fake([([0.0, 0.0], down)], [stretched]),  # the merged solution is labelled by sign noise
               fake([([0.1, -0.4], down), ([-0.3, 0.4], up)])]
    samples = follow_fake(results, held={"elbow": "up"})
    np.testing.assert_allclose([s.joints for s in samples], [[0.0, 0.5], [0.0, 0.0], [-0.3, 0.4]])
    assert [s.branch for s in samples] == [up, up, up]
    assert [s.branch_changed for s in samples] == [False, False, False]
    assert [s.status for s in samples] == ["ok", "ok", "ok"]


def test_continuation_keeps_the_previous_label_at_the_singular_sample_and_changes_after_it():
    up, down = {"elbow": "up"}, {"elbow": "down"}
    stretched = Singularity("elbow", (1,), "stretched_or_folded")
    results = [fake([([0.5, -0.5], down), ([0.0, 0.5], up)]),
               fake([([0.0, 0.0], down)], [stretched]),
               fake([([0.1, -0.4], down), ([-0.3, 0.6], up)])]
    samples = follow_fake(results, reference=np.array([0.1, 0.45]))
    assert [s.branch for s in samples] == [up, up, down]  # nearest to the reference, then to each sample
    assert [s.branch_changed for s in samples] == [False, False, True]


def test_unavailable_branch_continues_on_the_nearest_and_says_so():
    up, down = {"elbow": "up"}, {"elbow": "down"}
    results = [fake([([0.0, 0.5], up)]), fake([([0.1, -0.1], down), ([2.0, 1.0], down)]), fake([]),
               fake([([0.2, 0.3], up)])]
    samples = follow_fake(results, held={"elbow": "up"})
    assert [s.status for s in samples] == ["ok", "branch_unavailable", "unreachable", "ok"]
    np.testing.assert_allclose(samples[1].joints, [0.1, -0.1])
    assert [s.branch_changed for s in samples] == [False, True, False, True]


def test_revolute_joints_continue_across_the_wrap():
    results = [fake([([3.0, 0.1], {})]), fake([([-3.1, 0.2], {})]), fake([([-2.9, 0.3], {})])]
    samples = follow_fake(results)
    np.testing.assert_allclose([s.joints[0] for s in samples], [3.0, 2 * np.pi - 3.1, 2 * np.pi - 2.9])


def test_free_shoulder_makes_the_elbow_label_ambiguous_too():
    assert ambiguous_labels([Singularity("shoulder", (0,), "free")]) == {"shoulder", "elbow"}
    assert ambiguous_labels([Singularity("shoulder", (0,), "boundary")]) == {"shoulder"}
    assert ambiguous_labels([Singularity("assur_group", (1,), "aligned"),
                             Singularity("wrist", (3, 5), "sum")]) == {"assembly_mode", "wrist"}
    assert ambiguous_labels([Singularity("reach", (2,), "boundary")]) == set()


# ---------------------------------------------------------------------------
# Limits and the summary
# ---------------------------------------------------------------------------


def test_limit_violations_and_largest_steps_in_the_summary():
    """The Stanford arm's slide d3 is limited to [0.3048, 1.27] m: a path that pulls it in below that."""
    arm = robot("spong_ex3_5_stanford")
    t = np.linspace(0, 1, 6)
    q = np.tile([0.3, 0.9, 0.5, 0.4, 0.7, -0.2], (6, 1))
    q[:, 2] = 0.5 - 0.3 * t  # 0.5 … 0.2 m
    q[:, 0] += 0.1 * t**2
    result = follow_trajectory(arm, t, forward_kinematics(arm, q), options=TrajectoryOptions(reference=q[0]))
    np.testing.assert_allclose([s.joints for s in result.samples], q, atol=1e-9)
    below = [k for k in range(6) if q[k, 2] < 0.3048]
    assert [(k, v.joint) for k, v in result.summary.limit_violations] == [(k, 2) for k in below]
    np.testing.assert_allclose(result.summary.largest_joint_step, np.abs(np.diff(q, axis=0)).max(axis=0),
                               atol=1e-9)
    assert result.summary.largest_joint_step_at[0] == 5 and result.summary.largest_joint_step_at[2] is not None
    distances = [s.distance_to_singularity for s in result.samples]
    assert result.summary.smallest_distance_to_singularity == min(distances)
    assert result.summary.smallest_distance_at == int(np.argmin(distances))


# ---------------------------------------------------------------------------
# Validation
# ---------------------------------------------------------------------------


def scara_call(**overrides):
    arm = robot("spong_ex3_6_scara_rrpr")
    q = np.array([[0.3, -0.8, 0.2, 0.1], [0.35, -0.8, 0.2, 0.1]])
    arguments = dict(times=[0.0, 0.1], world_T_targets=forward_kinematics(arm, q),
                     twists=np.zeros((2, 6)), accelerations=None, options=TrajectoryOptions())
    arguments.update(overrides)
    return follow_trajectory(arm, arguments.pop("times"), arguments.pop("world_T_targets"), **arguments)


@pytest.mark.parametrize(("overrides", "location", "match"), [
    ({"times": [0.0, 0.0]}, ("samples", 1, "time"), "increase strictly"),
    ({"times": [0.2, 0.1]}, ("samples", 1, "time"), "increase strictly"),
    ({"times": [0.0, np.inf]}, ("samples", 1, "time"), "finite"),
    ({"times": [0.0]}, ("samples",), "target poses"),
    ({"twists": np.zeros((2, 5))}, ("twist",), "shape"),
    ({"twists": np.array([[0, 0, 0, 0, 0, 0], [0, 0, 0] + NAN3])}, ("samples", 1, "twist", "angular"), "wz"),
    ({"accelerations": np.array([[0.0] * 6, [0.0] * 6]), "twists": np.array([[0.0] * 6, [np.nan] * 6])},
     ("samples", 1, "acceleration"), "needs the sample's twist"),
    ({"options": TrajectoryOptions(branch={"assembly_mode": 1, "wrist": "flip"})}, ("branch", "wrist"),
     "assembly_mode"),
    ({"options": TrajectoryOptions(reference=np.zeros(3))}, ("reference",), "shape"),
    ({"options": TrajectoryOptions(damping=0.0)}, ("damping",), "positive"),
    ({"options": TrajectoryOptions(singularity_tolerance=-1.0)}, ("singularity_tolerance",), "non-negative"),
])
def test_invalid_samples_and_options_raise_with_a_location(overrides, location, match):
    with pytest.raises(InvalidInputError, match=match) as error:
        scara_call(**overrides)
    assert error.value.location == location


def test_a_twist_is_optional_per_sample():
    result = scara_call(twists=np.array([[0.1, 0, 0, 0, 0, 0.2], [np.nan] * 6]))
    assert np.isfinite(result.samples[0].velocities).all() and np.isnan(result.samples[1].velocities).all()
    assert result.samples[1].velocity_residual is None


def test_a_sample_that_may_not_continue_the_branch_says_so_whatever_its_labels():
    """Issue 22.11: the labels alone do not tell a neighbouring branch; branch_changed is also set where the
    joints cannot be told to continue the branch (the previous samples extrapolate to [0.3, 0.5])."""
    on_path = [fake([([0.1 * k, 0.5], {"elbow": "up"})]) for k in range(3)]
    ended = follow_fake(on_path + [fake([([1.5, -0.5], {"elbow": "up"})])])  # nothing near the extrapolation
    assert [s.branch_changed for s in ended] == [False, False, False, True]
    split = follow_fake(on_path + [fake([([0.3, 0.52], {"elbow": "up"}), ([0.3, 0.48], {"elbow": "up"})])])
    assert [s.branch_changed for s in split] == [False, False, False, True]  # two about as near: not known
    clear = follow_fake(on_path + [fake([([0.3, 0.5001], {"elbow": "up"}), ([0.3, 0.45], {"elbow": "up"})])])
    assert [s.branch_changed for s in clear] == [False, False, False, False]
    np.testing.assert_allclose(clear[3].joints, [0.3, 0.5001])


def test_the_continuation_is_the_nearest_to_the_extrapolated_joints_not_to_the_last():
    """Two solutions with the same labels: the one the path's motion leads to, though the other is nearer to
    the previous sample's joints."""
    on_path = [fake([([0.1 * k, 0.5 - 0.1 * k], {})]) for k in range(3)]  # moving by (0.1, -0.1) a sample
    samples = follow_fake(on_path + [fake([([0.22, 0.32], {}), ([0.3, 0.2], {})])])
    np.testing.assert_allclose(samples[3].joints, [0.3, 0.2])


def test_a_seven_joint_arm_with_a_coaxial_pair_follows_its_path_with_the_pair_held():
    """A UR5 with a joint added on its first axis: the redundancy is the pair's split, so every sample is the
    UR5's closed form with q2 held at the reference (issue 22 item 1). The generating path comes back up to that
    split: q1 + q2 and joints 3–7 as generated, q2 constant."""
    rows = [(0.0, 0.0, 0.05), (0.0, np.pi / 2, 0.039159), (-0.425, 0.0, 0.0), (-0.39225, 0.0, 0.0),
            (0.0, np.pi / 2, 0.10915), (0.0, -np.pi / 2, 0.09465), (0.0, 0.0, 0.0823)]
    arm = Robot([Joint(f"q{k + 1}", "revolute", a, alpha, d, 0.0) for k, (a, alpha, d) in enumerate(rows)])
    start, velocity = np.array([0.4, -0.9, -1.2, 1.0, 0.6, -0.8, 2.1]), np.array([0.3, 0.2, 0.1, -0.2, 0.1, 0.2, -0.1])
    times = np.linspace(0.0, 1.0, 12)
    path = start + times[:, None] * velocity
    result = follow_trajectory(arm, times, forward_kinematics(arm, path), options=TrajectoryOptions(reference=start))
    assert result.method == "analytic" and "coaxial" in result.structure
    assert all(sample.status == "ok" for sample in result.samples)
    joints = np.array([sample.joints for sample in result.samples])
    np.testing.assert_allclose(joints[:, 1], start[1], atol=1e-12)
    split = joints[:, 0] + joints[:, 1] - path[:, 0] - path[:, 1]
    np.testing.assert_allclose(wrapped(split), 0.0, atol=1e-9)
    np.testing.assert_allclose(joints[:, 2:], path[:, 2:], atol=1e-9)
