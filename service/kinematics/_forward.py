"""Forward kinematics, link frames, joint screws and the geometric Jacobian.

Frames: ``world`` is the frame poses are given in; ``base`` is the robot's
frame 0 (``world_T_base``); frame i is the DH frame attached after joint i;
``flange`` is frame n and ``tool`` is ``flange_T_tool`` after it.

Every function takes joint values ``q`` with shape (n,) or a batch (N, n) and
vectorises over N: there is no Python loop over configurations.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ._conventions import link_transforms
from ._robot import Robot


def _dh_variables(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The (theta, d) columns at joint values q, shape (..., n) each."""
    theta = robot.theta + np.where(robot.is_revolute, q, 0.0)
    d = robot.d + np.where(robot.is_revolute, 0.0, q)
    return theta, d


def link_frames(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Poses of every DH frame in the world frame.

    Parameters
    ----------
    q : ndarray, shape (n,) or (N, n)

    Returns
    -------
    ndarray, shape (..., n + 1, 4, 4)
        ``world_T_frame[i]`` for i = 0 (the base frame) … n (the flange).
    """
    q = np.asarray(q, dtype=float)
    theta, d = _dh_variables(robot, q)
    prev_T_link = link_transforms(robot.convention, robot.a, robot.alpha, d, theta)
    frames = np.empty(q.shape[:-1] + (robot.dof + 1, 4, 4))
    frames[..., 0, :, :] = robot.world_T_base
    for i in range(robot.dof):
        frames[..., i + 1, :, :] = frames[..., i, :, :] @ prev_T_link[..., i, :, :]
    return frames


def forward_kinematics(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Pose of the tool in the world frame, ``world_T_tool``.

    Parameters
    ----------
    q : ndarray, shape (n,) or (N, n)
        Joint values (radians for revolute joints).

    Returns
    -------
    ndarray, shape (4, 4) or (N, 4, 4)

    Examples
    --------
    Spong Example 3.1 (planar RR, a1 = 1, a2 = 0.5) at q = (0.5, -0.7):

    >>> from service.kinematics import Joint, Robot
    >>> arm = Robot([Joint("q1", "revolute", 1.0, 0, 0, 0), Joint("q2", "revolute", 0.5, 0, 0, 0)])
    >>> np.round(forward_kinematics(arm, [0.5, -0.7])[:2, 3], 5).tolist()
    [1.36762, 0.38009]
    """
    q = np.asarray(q, dtype=float)
    theta, d = _dh_variables(robot, q)
    prev_T_link = link_transforms(robot.convention, robot.a, robot.alpha, d, theta)
    world_T_flange = np.broadcast_to(robot.world_T_base, q.shape[:-1] + (4, 4))
    for i in range(robot.dof):
        world_T_flange = world_T_flange @ prev_T_link[..., i, :, :]
    return world_T_flange @ robot.flange_T_tool


class JointScrews(NamedTuple):
    """Joint axes in the world frame at one configuration (or a batch).

    ``directions`` are unit vectors, shape (..., n, 3): the rotation axis of a
    revolute joint or the sliding direction of a prismatic one, oriented so that
    a positive q turns or moves the outboard links positively about or along it.
    ``points`` lie on the axes, shape (..., n, 3). ``world_T_tool`` is the tool
    pose at the same configuration, shape (..., 4, 4).
    """

    directions: np.ndarray
    points: np.ndarray
    world_T_tool: np.ndarray


def joint_screws(robot: Robot, q: np.ndarray) -> JointScrews:
    """Axes and points of every joint in the world frame at joint values q.

    In standard DH the axis of joint i is z_{i-1}; in Craig and Khalil form it
    is z_i. Either way it is read off the link frames, so the result does not
    depend on the convention the robot was described in.
    """
    frames = link_frames(robot, q)
    if robot.convention == "standard":
        axis_frames = frames[..., :-1, :, :]
    else:
        axis_frames = frames[..., 1:, :, :]
    world_T_tool = frames[..., -1, :, :] @ robot.flange_T_tool
    return JointScrews(axis_frames[..., :3, 2].copy(), axis_frames[..., :3, 3].copy(), world_T_tool)


class ScrewModel(NamedTuple):
    """Product-of-exponentials model of a robot, in the world frame.

    ``world_T_tool(q) = exp([S_1] q_1) ⋯ exp([S_n] q_n) · home``, where joint i
    turns about ``directions[i]`` through ``points[i]`` (revolute) or slides
    along ``directions[i]`` (prismatic), all at q = 0.
    """

    directions: np.ndarray  # (n, 3)
    points: np.ndarray  # (n, 3)
    is_revolute: np.ndarray  # (n,)
    home: np.ndarray  # (4, 4) world_T_tool at q = 0


def screw_model(robot: Robot) -> ScrewModel:
    """The product-of-exponentials model of ``robot`` (its joint screws at q = 0)."""
    screws = joint_screws(robot, np.zeros(robot.dof))
    return ScrewModel(screws.directions, screws.points, robot.is_revolute.copy(), screws.world_T_tool)


def geometric_jacobian(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian of the tool point, in the world frame.

    Rows 0–2 map q̇ to the linear velocity of the tool origin, rows 3–5 to
    the angular velocity of the tool (Spong's ``J = [J_v; J_ω]``):
    column i is ``[ω_i × (p_tool − p_i); ω_i]`` for a revolute joint and
    ``[v_i; 0]`` for a prismatic one.

    Parameters
    ----------
    q : ndarray, shape (n,) or (N, n)

    Returns
    -------
    ndarray, shape (6, n) or (N, 6, n)
    """
    directions, points, world_T_tool = joint_screws(robot, q)
    tool_position = world_T_tool[..., None, :3, 3]
    revolute = robot.is_revolute[:, None]
    linear = np.where(revolute, np.cross(directions, tool_position - points), directions)
    angular = np.where(revolute, directions, 0.0)
    return np.concatenate([np.swapaxes(linear, -1, -2), np.swapaxes(angular, -1, -2)], axis=-2)
