"""Forward kinematics, link frames, joint screws and the geometric Jacobian.

Frames: ``world`` is the frame poses are given in; ``base`` is the robot's
frame 0 (``world_T_base``); frame i is the DH frame attached after joint i;
``flange`` is frame n and ``tool`` is ``flange_T_tool`` after it. For a robot
built from screws (URDF chains too) frame i is ``F_0 · M(q_1) · F_1 ⋯ M(q_i) · F_i``:
like a standard DH frame it carries the axis of joint i + 1 as its z axis, and
frame n is the flange (see :meth:`Robot.from_screws`).

Every function takes joint values ``q`` with shape (n,) or a batch (N, n) and
vectorises over N: there is no Python loop over configurations.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ._conventions import link_transforms
from ._cache import memo
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
    if robot.chain_transforms is not None:
        return _chain_frames(robot, q)[..., [0, *range(2, robot.dof + 2)], :, :]
    theta, d = _dh_variables(robot, q)
    prev_T_link = link_transforms(robot.convention, robot.a, robot.alpha, d, theta)
    frames = np.empty(q.shape[:-1] + (robot.dof + 1, 4, 4))
    frames[..., 0, :, :] = robot.world_T_base
    for i in range(robot.dof):
        frames[..., i + 1, :, :] = frames[..., i, :, :] @ prev_T_link[..., i, :, :]
    return frames


def _chain_frames(robot: Robot, q: np.ndarray) -> np.ndarray:
    """For a screws robot: world_T_base, then the frame of joint 1's axis (world_T_base · F_0), then frames 1 … n;
    shape (..., n + 2, 4, 4)."""
    chain = robot.chain_transforms
    motion = np.zeros(q.shape + (4, 4))
    c, s = np.cos(q), np.sin(q)
    revolute = robot.is_revolute
    motion[..., 0, 0] = np.where(revolute, c, 1.0)
    motion[..., 0, 1] = np.where(revolute, -s, 0.0)
    motion[..., 1, 0] = np.where(revolute, s, 0.0)
    motion[..., 1, 1] = np.where(revolute, c, 1.0)
    motion[..., 2, 2] = 1.0
    motion[..., 3, 3] = 1.0
    motion[..., 2, 3] = np.where(revolute, 0.0, q)
    frames = np.empty(q.shape[:-1] + (robot.dof + 2, 4, 4))
    frames[..., 0, :, :] = robot.world_T_base
    frames[..., 1, :, :] = robot.world_T_base @ chain[0]
    for i in range(robot.dof):
        frames[..., i + 2, :, :] = frames[..., i + 1, :, :] @ motion[..., i, :, :] @ chain[i + 1]
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
    if q.ndim == 1:
        return _tool_matrix(robot, q.tolist())
    x, y, z, p = tool_columns(robot, q.reshape(-1, q.shape[-1]))
    world_T_tool = np.empty((x.shape[1], 4, 4))
    for column, values in enumerate((x, y, z, p)):
        world_T_tool[:, :3, column] = values.T
    world_T_tool[:, 3, :3] = 0.0
    world_T_tool[:, 3, 3] = 1.0
    return world_T_tool.reshape(q.shape[:-1] + (4, 4))


class _Step(NamedTuple):
    """One link of the chain, as the column operations it needs (zero terms left out)."""

    revolute: bool
    theta: float  # constant part of the joint angle
    d: float  # constant part of the offset along z
    a: float
    cos_alpha: float
    sin_alpha: float
    twisted: bool  # alpha is not 0


def _chain_steps(robot: Robot) -> tuple[_Step, ...]:
    steps = []
    for i in range(robot.dof):
        alpha = float(robot.alpha[i])
        cos_alpha, sin_alpha = math.cos(alpha), math.sin(alpha)
        # an alpha of ±90° gives cos 6e-17, not 0: treat it as the exact 0 it stands for
        cos_alpha = 0.0 if abs(cos_alpha) < 1e-15 else cos_alpha
        sin_alpha = 0.0 if abs(sin_alpha) < 1e-15 else sin_alpha
        steps.append(_Step(bool(robot.is_revolute[i]), float(robot.theta[i]), float(robot.d[i]), float(robot.a[i]),
                           cos_alpha, sin_alpha, alpha != 0.0))
    return tuple(steps)


def tool_columns(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``world_T_tool`` for a batch of joint vectors, as its four columns.

    The chain is multiplied out column by column: post-multiplying by Rz(θ)
    mixes the x and y columns, by Rx(α) the y and z columns, and a
    translation adds a multiple of one column to the position. Each step is
    a few elementwise operations over the whole batch, and terms that are
    zero for this robot (a = 0, d = 0, α = 0) are skipped.

    Parameters
    ----------
    q : ndarray, shape (N, n)

    Returns
    -------
    x, y, z, p : ndarrays, shape (3, N)
        The rotation's columns and the position of the tool, in the world frame.
    """
    if robot.chain_transforms is not None:
        return _screw_chain_columns(robot, np.asarray(q, dtype=float))
    steps = memo(robot, "chain_steps", lambda: _chain_steps(robot))
    qt = np.asarray(q, dtype=float).T  # (n, N)
    angles = np.array([s.theta for s in steps])[:, None] + np.where(robot.is_revolute[:, None], qt, 0.0)
    cos, sin = np.cos(angles), np.sin(angles)
    base = robot.world_T_base
    count = qt.shape[1]
    x, y, z = (np.repeat(base[:3, k:k + 1], count, axis=1) for k in range(3))
    p = np.repeat(base[:3, 3:4], count, axis=1)
    standard = robot.convention == "standard"
    for i, step in enumerate(steps):
        c, s = cos[i], sin[i]
        if standard:  # A = Rz(θ) Tz(d) Tx(a) Rx(α)
            d = step.d if step.revolute else step.d + qt[i]
            if step.revolute and d != 0.0 or not step.revolute:
                p = p + z * d
            x, y = x * c + y * s, y * c - x * s
            if step.a != 0.0:
                p = p + x * step.a
            if step.twisted:
                y, z = y * step.cos_alpha + z * step.sin_alpha, z * step.cos_alpha - y * step.sin_alpha
        else:  # T = Rx(α) Tx(a) Rz(θ) Tz(d)
            if step.a != 0.0:
                p = p + x * step.a
            if step.twisted:
                y, z = y * step.cos_alpha + z * step.sin_alpha, z * step.cos_alpha - y * step.sin_alpha
            x, y = x * c + y * s, y * c - x * s
            d = step.d if step.revolute else step.d + qt[i]
            if step.revolute and d != 0.0 or not step.revolute:
                p = p + z * d
    tool = robot.flange_T_tool
    if not np.array_equal(tool, _IDENTITY):
        R, t = tool[:3, :3], tool[:3, 3]
        p = p + x * t[0] + y * t[1] + z * t[2]
        x, y, z = (x * R[0, k] + y * R[1, k] + z * R[2, k] for k in range(3))
    return x, y, z, p


_IDENTITY = np.eye(4)


def _apply_columns(x, y, z, p, T: np.ndarray):
    """Columns of frame · T for a fixed rigid T, shape (4, 4); works on arrays and on scalars alike."""
    R, t = T[:3, :3], T[:3, 3]
    p = p + x * t[0] + y * t[1] + z * t[2]
    return (*(x * R[0, k] + y * R[1, k] + z * R[2, k] for k in range(3)), p)


def _screw_chain_columns(robot: Robot, q: np.ndarray):
    """:func:`tool_columns` of a screws robot: base · F_0, then per joint its motion about local z and F_i."""
    chain = robot.chain_transforms
    qt = q.T
    count = qt.shape[1]
    base = robot.world_T_base @ chain[0]
    x, y, z = (np.repeat(base[:3, k:k + 1], count, axis=1) for k in range(3))
    p = np.repeat(base[:3, 3:4], count, axis=1)
    cos, sin = np.cos(qt), np.sin(qt)
    for i in range(robot.dof):
        if robot.is_revolute[i]:
            c, s = cos[i], sin[i]
            x, y = x * c + y * s, y * c - x * s
        else:
            p = p + z * qt[i]
        x, y, z, p = _apply_columns(x, y, z, p, chain[i + 1] @ robot.flange_T_tool if i == robot.dof - 1
                                    else chain[i + 1])
    return x, y, z, p


def _screw_chain_scalar(robot: Robot, q: list[float]):
    """:func:`_screw_chain_columns` for one joint vector, in scalar arithmetic (unrolled, no array overhead)."""
    def build():
        fixed = [robot.world_T_base @ robot.chain_transforms[0], *robot.chain_transforms[1:-1],
                 robot.chain_transforms[-1] @ robot.flange_T_tool]
        return [tuple(T[:3, :].T.ravel().tolist()) for T in fixed]  # x, y, z, p columns, flattened

    fixed = memo(robot, "screw_chain_scalar", build)
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = fixed[0]
    for revolute, value, F in zip(robot.is_revolute.tolist(), q, fixed[1:]):
        if revolute:
            c, s = math.cos(value), math.sin(value)
            x0, x1, x2, y0, y1, y2 = (x0 * c + y0 * s, x1 * c + y1 * s, x2 * c + y2 * s,
                                      y0 * c - x0 * s, y1 * c - x1 * s, y2 * c - x2 * s)
        else:
            p0, p1, p2 = p0 + z0 * value, p1 + z1 * value, p2 + z2 * value
        a0, a1, a2, b0, b1, b2, c0, c1, c2, t0, t1, t2 = F
        p0, p1, p2 = (p0 + x0 * t0 + y0 * t1 + z0 * t2, p1 + x1 * t0 + y1 * t1 + z1 * t2,
                      p2 + x2 * t0 + y2 * t1 + z2 * t2)
        x0, x1, x2, y0, y1, y2, z0, z1, z2 = (
            x0 * a0 + y0 * a1 + z0 * a2, x1 * a0 + y1 * a1 + z1 * a2, x2 * a0 + y2 * a1 + z2 * a2,
            x0 * b0 + y0 * b1 + z0 * b2, x1 * b0 + y1 * b1 + z1 * b2, x2 * b0 + y2 * b1 + z2 * b2,
            x0 * c0 + y0 * c1 + z0 * c2, x1 * c0 + y1 * c1 + z1 * c2, x2 * c0 + y2 * c1 + z2 * c2)
    return (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2)


def _tool_matrix(robot: Robot, q: list[float]) -> np.ndarray:
    """``world_T_tool`` for one joint vector: :func:`tool_columns` in scalar arithmetic (no array overhead)."""
    (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2) = tool_columns_scalar(robot, q)
    return np.array([[x0, y0, z0, p0], [x1, y1, z1, p1], [x2, y2, z2, p2], [0.0, 0.0, 0.0, 1.0]])


def _screw_z(frame: tuple, c: float, s: float, d: float) -> tuple:
    """A frame (x, y, z, p columns, flattened) moved by Rot_z(theta)·Trans_z(d), given c, s of theta (they commute)."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = frame
    if d:
        p0, p1, p2 = p0 + z0 * d, p1 + z1 * d, p2 + z2 * d
    return (x0 * c + y0 * s, x1 * c + y1 * s, x2 * c + y2 * s, y0 * c - x0 * s, y1 * c - x1 * s, y2 * c - x2 * s,
            z0, z1, z2, p0, p1, p2)


def _screw_x(frame: tuple, step) -> tuple:
    """A frame moved by Trans_x(a)·Rot_x(alpha) of a chain step (they commute); zero terms are skipped."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = frame
    if step.a:
        p0, p1, p2 = p0 + x0 * step.a, p1 + x1 * step.a, p2 + x2 * step.a
    if step.twisted:
        ca, sa = step.cos_alpha, step.sin_alpha
        y0, y1, y2, z0, z1, z2 = (y0 * ca + z0 * sa, y1 * ca + z1 * sa, y2 * ca + z2 * sa,
                                  z0 * ca - y0 * sa, z1 * ca - y1 * sa, z2 * ca - y2 * sa)
    return x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2


def tool_columns_scalar(robot: Robot, q: list[float]) -> tuple[tuple[float, float, float], ...]:
    """:func:`tool_columns` for one joint vector (a list of floats), in scalar arithmetic: the columns x, y, z, p
    of ``world_T_tool`` as tuples of three floats."""
    if robot.chain_transforms is not None:
        return _screw_chain_scalar(robot, q)
    steps = memo(robot, "chain_steps", lambda: _chain_steps(robot))
    start = memo(robot, "base_columns", lambda: robot.world_T_base[:3].T.tolist())
    (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2) = start
    frame = (x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2)
    standard = robot.convention == "standard"
    for step, value in zip(steps, q):
        if step.revolute:
            angle, d = step.theta + value, step.d
        else:
            angle, d = step.theta, step.d + value
        # Standard DH is a screw about z (theta, d) then about x (a, alpha); Craig and Khalil the other way round.
        if standard:
            frame = _screw_x(_screw_z(frame, math.cos(angle), math.sin(angle), d), step)
        else:
            frame = _screw_z(_screw_x(frame, step), math.cos(angle), math.sin(angle), d)
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = frame
    x, y, z, p = (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2)
    tool = memo(robot, "tool_scalar", lambda: None if np.array_equal(robot.flange_T_tool, _IDENTITY)
                else robot.flange_T_tool[:3].T.tolist())
    if tool is None:
        return x, y, z, p
    # as in tool_columns: p += R_flange t, then each column of R_flange · R_tool
    (r0, r1, r2, t) = tool
    p = tuple(p[a] + x[a] * t[0] + y[a] * t[1] + z[a] * t[2] for a in range(3))
    x, y, z = (tuple(x[a] * r[0] + y[a] * r[1] + z[a] * r[2] for a in range(3)) for r in (r0, r1, r2))
    return x, y, z, p


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
    q = np.asarray(q, dtype=float)
    if robot.chain_transforms is not None:
        frames = _chain_frames(robot, q)
        world_T_tool = frames[..., -1, :, :] @ robot.flange_T_tool
        axis_frames = frames[..., 1:-1, :, :]
        return JointScrews(axis_frames[..., :3, 2].copy(), axis_frames[..., :3, 3].copy(), world_T_tool)
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
