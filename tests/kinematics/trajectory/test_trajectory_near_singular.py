"""Trajectories that pass near a singularity (issue 22.11): the joints stay on the continuous branch, to the last
digits, and held labels hold where the true path's joints carry them.

Independent truth: each path is generated in joint space, q(t) (``tests.oracles.paths.near_singular_path``), and
the poses and twists come from forward kinematics and its difference Jacobian ([ṗ; ω] of the tool origin, world
frame, as api.md's trajectory twist). The paths come within σmin/σmax ≈ 1e-5 of a singularity at their middle,
never crossing it.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from service.config import Settings
from service.kinematics import TrajectoryOptions, follow_trajectory, forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik
from service.robots.catalogue import load_catalogue
from tests.conftest import DATA
from tests.oracles.paths import NEAR_SINGULAR_TIMES, UR5E_PATH, near_singular_path, sigma_ratio, twists_of
from tests.arms import standard_dh_from_screws, urdf_chain_screws

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


def doosan():
    joints = json.loads((DATA / "doosan_m1013_urdf_joints.json").read_text())["joints"]
    return standard_dh_from_screws(*urdf_chain_screws(joints))


@pytest.mark.parametrize("given", ["poses", "twists", "twists_and_accelerations"])
def test_ur5e_stays_on_its_branch_past_a_near_singularity(given):
    robot = CATALOGUE.get("ur5e").robot
    q, qd, qdd = near_singular_path(robot, *UR5E_PATH, NEAR_SINGULAR_TIMES)
    assert 1e-6 < sigma_ratio(robot, q[99]) < 1e-4
    twists = twists_of(robot, q, qd) if given != "poses" else None
    accelerations = None
    if given == "twists_and_accelerations":  # p̈ and ω̇ by differences of the twist along the exact q(t)
        h = 1e-6
        ahead = near_singular_path(robot, *UR5E_PATH, NEAR_SINGULAR_TIMES + h)
        behind = near_singular_path(robot, *UR5E_PATH, NEAR_SINGULAR_TIMES - h)
        accelerations = (twists_of(robot, ahead[0], ahead[1]) - twists_of(robot, behind[0], behind[1])) / (2 * h)
    result = follow_trajectory(robot, NEAR_SINGULAR_TIMES, forward_kinematics(robot, q), twists=twists,
                               accelerations=accelerations, options=TrajectoryOptions(reference=q[0]))
    joints = np.array([s.joints for s in result.samples])
    assert np.abs(joints - q).max() <= 1e-9  # every sample on the generating path: no jump, no neighbour
    true_step = np.abs(np.diff(q, axis=0)).max(axis=0)
    assert (result.summary.largest_joint_step <= true_step + 1e-9).all()
    middle = [k for k in range(len(NEAR_SINGULAR_TIMES)) if abs(NEAR_SINGULAR_TIMES[k] - 0.5) < 0.1]
    assert not any(result.samples[k].branch_changed for k in middle)


#: A Kinova Jaco 2 (the vendor's URDF) path whose middle is 3e-5 (σmin/σmax) from a singularity: before issue
#: 22.11 its middle samples were off by 1.8e-9 rad, at a pose residual the FK check accepts.
JACO2_PATH = ([-2.603, -1.654, 1.893, 0.516, -2.55, -0.42], [-0.042, -0.681, 0.469, -0.773, -0.218, 0.033], 1e-5)


@pytest.mark.parametrize(("robot_id", "path"), [("kinova_jaco2", JACO2_PATH), ("ur5e", UR5E_PATH)])
def test_near_singular_samples_are_polished_to_the_last_digits(robot_id, path):
    """Joint accuracy at the middle samples, where σmin/σmax ≈ 1e-5: the residual a closed form or a search
    stops at leaves the joints off by residual / σmin; the trajectory polishes them with the core's Gauss–Newton
    (the generating joints are the truth)."""
    robot = CATALOGUE.get(robot_id).robot
    q, _, _ = near_singular_path(robot, *path, NEAR_SINGULAR_TIMES)
    assert sigma_ratio(robot, q[99]) < 1e-4
    result = follow_trajectory(robot, NEAR_SINGULAR_TIMES, forward_kinematics(robot, q),
                               options=TrajectoryOptions(reference=q[0]))
    joints = np.array([s.joints for s in result.samples])
    errors = np.abs(joint_difference(robot, joints, q)).max(axis=1)
    assert errors[90:110].max() <= 1e-10
    assert errors.max() <= 1e-9


#: A Doosan M1013 (the vendor's URDF, π/2 written 1.571) path whose middle passes 3e-6 (σmin/σmax) from its elbow
#: singularity. The idealised closed form hands the samples near it to the numeric search; before issue 22.11
#: those solutions carried no labels and the labels of the idealised arm flipped within δ of its own fold, so
#: with the first sample's labels held, 37 samples came back branch_unavailable on the true path's joints.
DOOSAN_PATH = ([2.901, 1.412, 0.259, -1.402, -2.132, 2.953], [0.032, -0.768, 0.247, 0.553, 0.226, 0.835], 1e-5)


def test_doosan_held_labels_hold_where_the_true_path_carries_them():
    robot = doosan()
    q, qd, _ = near_singular_path(robot, *DOOSAN_PATH, NEAR_SINGULAR_TIMES)
    assert sigma_ratio(robot, q[99]) < 1e-4
    poses = forward_kinematics(robot, q)
    first = solve_ik(robot, poses[0], reference=q[0]).solutions[0]
    assert np.abs(joint_difference(robot, first.joints, q[0])).max() < 1e-9
    held = dict(first.branch)
    assert set(held) == {"shoulder", "elbow", "wrist"}
    result = follow_trajectory(robot, NEAR_SINGULAR_TIMES, poses, twists=twists_of(robot, q, qd),
                               options=TrajectoryOptions(branch=held))
    assert [s.status for s in result.samples] == ["ok"] * len(NEAR_SINGULAR_TIMES)
    assert all(s.branch == held for s in result.samples)
    joints = np.array([s.joints for s in result.samples])
    assert np.abs(joint_difference(robot, joints, q)).max() <= 1e-9


def test_the_idealised_arms_labels_are_left_out_where_its_fold_and_the_true_arms_differ():
    """The root of the Doosan case, in single IK: at the true path's near-singular samples the generating
    solution carries the shoulder and wrist labels (also where the numeric search completes the closed form's
    answer), and the elbow label either as held or left out (the idealised arm's elbow fold is within its δ of
    the true arm's)."""
    robot = doosan()
    q, _, _ = near_singular_path(robot, *DOOSAN_PATH, NEAR_SINGULAR_TIMES)
    poses = forward_kinematics(robot, q)
    held = solve_ik(robot, poses[0], reference=q[0]).solutions[0].branch
    for k in range(90, 110):
        result = solve_ik(robot, poses[k], reference=q[k])
        own = [s for s in result.solutions if np.abs(joint_difference(robot, s.joints, q[k])).max() < 1e-6]
        assert len(own) == 1, f"sample {k}: the generating joints are not among the solutions"
        branch = own[0].branch
        assert (branch["shoulder"], branch["wrist"]) == (held["shoulder"], held["wrist"]), f"sample {k}"
        assert branch.get("elbow", held["elbow"]) == held["elbow"], f"sample {k}"
