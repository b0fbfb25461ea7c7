"""Arms stated the way CAD exports and vendors state them: rounded DH values, rounded base and tool quaternions,
and the exact DH table of an arm given by its screws (whatever offsets that takes)."""

from __future__ import annotations

import numpy as np

from service.kinematics import Joint, Robot


def rounded(robot: Robot, seed: int, *, base_and_tool: bool = True) -> Robot:
    """``robot`` as a CAD export writes it: angles in radians to 4 decimals (π/2 → 1.5708), parallel axes
    (α = 0 or π) 1e-5 rad off, lengths to 0.1 mm (the robot's unit taken as metres), and, with
    ``base_and_tool``, a random base and tool whose quaternions are written to 6 decimals (0.707107) and
    translations to 0.1 mm."""
    rng = np.random.default_rng(seed)
    joints = []
    for joint in robot.joints:
        alpha = round(joint.alpha, 4)
        if abs(np.sin(alpha)) < 1e-3:
            alpha += rng.choice([-1.0, 1.0]) * 1e-5
        joints.append(Joint(joint.name, joint.kind, round(joint.a, 4), alpha, round(joint.d, 4),
                            round(joint.theta, 4)))
    transforms = {}
    if base_and_tool:
        for key in ("world_T_base", "flange_T_tool"):
            transforms[key] = _rounded_transform(rng)
    return Robot(joints, convention=robot.convention, **transforms)


def _rounded_transform(rng: np.random.Generator) -> np.ndarray:
    w, x, y, z = quaternion = np.round(rng.normal(size=4) / 2, 6)
    w, x, y, z = quaternion / np.linalg.norm(quaternion)  # a reader normalises the written quaternion
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = np.round(rng.uniform(-0.2, 0.2, 3), 4)
    return T


def standard_dh_from_screws(directions: np.ndarray, points: np.ndarray, home: np.ndarray) -> Robot:
    """The exact standard-DH robot (all revolute) whose joint i turns about the line (points[i], directions[i]) and
    whose tool is at ``home`` at q = 0 (world frame). Frame 0 is put on axis 1 by ``world_T_base``; frame i's
    origin is the foot on axis i+1 of its common normal with axis i, wherever that is (kilometres away for
    nearly parallel axes: the table then carries the huge compensating offsets a CAD converter would write)."""
    n = len(directions)
    z = directions[0] / np.linalg.norm(directions[0])
    x = _perpendicular(z)
    frame = np.eye(4)
    frame[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    frame[:3, 3] = points[0]
    world_T_base = frame.copy()
    joints = []
    for i in range(n):
        origin, x_prev, z_prev = frame[:3, 3], frame[:3, 0], frame[:3, 2]
        if i + 1 < n:
            k, p = directions[i + 1] / np.linalg.norm(directions[i + 1]), points[i + 1]
        else:
            k, p = z_prev, origin
        normal = np.cross(z_prev, k)
        sine = np.linalg.norm(normal)
        if sine > 1e-15:
            # the common normal: along n = z_prev × k, of signed length (p − origin)·n̂ (well conditioned); its
            # foot on axis i at origin + s z_prev, s = ((p − origin) × k)·n / |n|²
            unit = normal / sine
            s = float(np.cross(p - origin, k) @ normal) / sine ** 2
            foot_prev = origin + s * z_prev
            length = float((p - origin) @ unit)
            x_new = unit if length >= 0 else -unit
            gap = abs(length) * x_new
        else:
            foot_prev = origin
            gap = p + k * ((origin - p) @ k) - origin
            x_new = gap / np.linalg.norm(gap) if np.linalg.norm(gap) > 1e-12 else x_prev
        foot = foot_prev + gap
        theta = np.arctan2(np.cross(x_prev, x_new) @ z_prev, x_prev @ x_new)
        alpha = np.arctan2(np.cross(z_prev, k) @ x_new, z_prev @ k)
        joints.append(Joint(f"q{i + 1}", "revolute", float(gap @ x_new), float(alpha),
                            float((foot_prev - origin) @ z_prev), float(theta)))
        frame = np.eye(4)
        frame[:3, :3] = np.column_stack([x_new, np.cross(k, x_new), k])
        frame[:3, 3] = foot
    flange_T_tool = np.linalg.inv(frame) @ home
    return Robot(joints, convention="standard", world_T_base=world_T_base, flange_T_tool=flange_T_tool)


def _perpendicular(k: np.ndarray) -> np.ndarray:
    trial = np.eye(3)[np.argmin(np.abs(k))]
    u = np.cross(k, trial)
    return u / np.linalg.norm(u)


def urdf_chain_screws(joints: list[dict]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint axes (n, 3), points on them (n, 3) and the tool pose at q = 0 (4, 4) of a URDF chain of revolute
    joints with ``<axis xyz="0 0 1">``, each given by its ``<origin>`` (``xyz``, ``rpy``: fixed-axis roll, pitch,
    yaw, R = Rz(y) Ry(p) Rx(r)); the tool is the last joint's frame."""
    frame = np.eye(4)
    directions, points = [], []
    for joint in joints:
        r, p, y = joint["rpy"]
        origin = np.eye(4)
        origin[:3, :3] = _rot("z", y) @ _rot("y", p) @ _rot("x", r)
        origin[:3, 3] = joint["xyz"]
        frame = frame @ origin
        directions.append(frame[:3, 2].copy())
        points.append(frame[:3, 3].copy())
    return np.array(directions), np.array(points), frame


def _rot(axis: str, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]
