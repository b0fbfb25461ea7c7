"""What a batch of IK targets asks of a joint vector: residuals for the FK check, an error and its Jacobian for
Gauss–Newton.

Two kinds of goal share one interface, so that verification (:mod:`._verify`), refinement and the numeric search
(:mod:`._gauss_newton`) are written once:

* :class:`PoseGoal`: N poses ``world_T_tool`` (N, 4, 4); with ``constrain_orientation`` false only their
  positions count.
* :class:`DirectionGoal`: N positions (N, 3) and unit directions (N, 3) that the tool axis ``tool_axis`` (3,),
  tool frame, must point along; the roll about that axis is free.

Residuals are exact distances: the position error in length units and the orientation error in radians (the
rotation angle between the two frames, or the angle between the tool axis and the direction). The error vector
that Gauss–Newton drives to zero is normalised: positions divided by the arm's size (:func:`~._structure.arm_size`),
so every row is of order one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._forward import (JointTrig, cross, forward_kinematics, geometric_jacobian, radius_about, tool_columns,
                        tool_columns_scalar_rows)
from .._robot import Robot
from ._structure import arm_size

#: Up to this many candidates in all, residuals run the scalar FK on each: cheaper than the array operations,
#: whose fixed cost dominates at that size (one pose's slots).
SCALAR_CANDIDATES = 16


def pose_error(world_T_tool: np.ndarray, world_T_target: np.ndarray, length_scale: float) -> np.ndarray:
    """Twist-like error from the current tool pose to the target, shape (..., 6).

    Rows 0–2: position error divided by ``length_scale``; rows 3–5: rotation error ``½ Σ_i r_i × r*_i``
    (columns of the current and target rotations), which is sin(angle)·axis near the solution.
    """
    position = (world_T_target[..., :3, 3] - world_T_tool[..., :3, 3]) / length_scale
    # the columns' cross products (np.cross's values with the columns as rows, without its axis bookkeeping)
    columns = cross(np.swapaxes(world_T_tool[..., :3, :3], -1, -2), np.swapaxes(world_T_target[..., :3, :3], -1, -2))
    return np.concatenate([position, 0.5 * np.sum(columns, axis=-2)], axis=-1)


@dataclass(frozen=True)
class PoseGoal:
    """N pose targets ``world_T_targets`` (N, 4, 4); only positions count unless ``constrain_orientation``."""

    world_T_targets: np.ndarray
    constrain_orientation: bool = True

    def __len__(self) -> int:
        return len(self.world_T_targets)

    @property
    def rows(self) -> int:
        """The error's length: 6, or 3 for positions."""
        return 6 if self.constrain_orientation else 3

    def take(self, rows: np.ndarray) -> "PoseGoal":
        return PoseGoal(self.world_T_targets[rows], self.constrain_orientation)

    def residuals(self, robot: Robot, joints: np.ndarray, trig: JointTrig | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
        """Position (length units) and orientation (radians) errors of m candidates per target, joints (N, m, n):
        shape (N, m) each. The orientation is computed for position targets too (the answer reports NaN).
        ``trig``: the cos and sin of the joints as rows (N·m, n), when the caller shares them."""
        n_targets, m, n = joints.shape
        if n_targets * m <= SCALAR_CANDIDATES:
            position, orientation = np.empty((n_targets, m)), np.empty((n_targets, m))
            for row, (candidates, target) in enumerate(zip(joints.tolist(),
                                                           self.world_T_targets[:, :3, :].tolist())):
                position[row], orientation[row] = zip(*pose_residuals_of_rows(robot, candidates, target))
            return position, orientation
        x, y, z, p = (c.reshape(3, n_targets, m) for c in tool_columns(robot, joints.reshape(-1, n), trig))
        target = np.moveaxis(self.world_T_targets[:, :3, :], 0, -1)[..., None]  # (3, 4, N, 1)
        tx, ty, tz, tp = target[:, 0], target[:, 1], target[:, 2], target[:, 3]
        delta, dx, dy, dz = p - tp, x - tx, y - ty, z - tz
        return np.sqrt(_dot(delta, delta)), turn_of_chord(_dot(dx, dx) + _dot(dy, dy) + _dot(dz, dz))

    def error(self, robot: Robot, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """The normalised error (K, 3 or 6) of joint vectors q (K, n) against their targets ``rows`` (K,)."""
        error = pose_error(forward_kinematics(robot, q), self.world_T_targets[rows], arm_size(robot))
        return error if self.constrain_orientation else error[:, :3]

    def jacobian(self, robot: Robot, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """d(error)/dq up to sign, (K, 3 or 6, n): the geometric Jacobian, position rows over the arm's size."""
        J = geometric_jacobian(robot, q)
        J[:, :3, :] /= arm_size(robot)
        return J if self.constrain_orientation else J[:, :3, :]


def pose_residuals_of_rows(robot: Robot, candidates: list[list[float]], target: list[list[float]]
                           ) -> list[tuple[float, float]]:
    """:meth:`PoseGoal.residuals` of a few candidates (lists of n floats) against one target (the top three rows
    of its matrix, as lists), on the scalar FK (the same chain program, without the fixed cost of array
    operations). Returns (position, orientation) per candidate."""
    (tx0, ty0, tz0, tp0), (tx1, ty1, tz1, tp1), (tx2, ty2, tz2, tp2) = target
    sqrt, asin = math.sqrt, math.asin
    out = []
    for (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2) in tool_columns_scalar_rows(robot, candidates):
        d0, d1, d2 = p0 - tp0, p1 - tp1, p2 - tp2
        a0, a1, a2, b0, b1, b2 = x0 - tx0, x1 - tx1, x2 - tx2, y0 - ty0, y1 - ty1, y2 - ty2
        c0, c1, c2 = z0 - tz0, z1 - tz1, z2 - tz2
        half_sine = _HALF_SINE_PER_CHORD * sqrt(a0 * a0 + a1 * a1 + a2 * a2 + b0 * b0 + b1 * b1 + b2 * b2
                                                + c0 * c0 + c1 * c1 + c2 * c2)
        # clamped at π as np.minimum clamps, a NaN kept (a NaN candidate's error is NaN, as on arrays)
        out.append((sqrt(d0 * d0 + d1 * d1 + d2 * d2), 2.0 * asin(1.0 if half_sine > 1.0 else half_sine)))
    return out


@dataclass(frozen=True)
class DirectionGoal:
    """N targets: the tool origin at ``positions`` (N, 3), the tool axis ``tool_axis`` (3,, unit, tool frame)
    along ``directions`` (N, 3, unit, world frame)."""

    positions: np.ndarray
    directions: np.ndarray
    tool_axis: np.ndarray

    def __len__(self) -> int:
        return len(self.positions)

    rows = 6
    constrain_orientation = True

    def take(self, rows: np.ndarray) -> "DirectionGoal":
        return DirectionGoal(self.positions[rows], self.directions[rows], self.tool_axis)

    def residuals(self, robot: Robot, joints: np.ndarray, trig: JointTrig | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
        """Position error (length units) and the angle between tool axis and direction (rad), shape (N, m).
        ``trig`` is not used: the FK here builds whole matrices."""
        T = forward_kinematics(robot, joints.reshape(-1, robot.dof)).reshape(joints.shape[:-1] + (4, 4))
        position = np.linalg.norm(T[..., :3, 3] - self.positions[:, None], axis=-1)
        pointing = T[..., :3, :3] @ self.tool_axis
        angle = np.arctan2(radius_about(pointing, self.directions[:, None]),
                           np.einsum("nmi,ni->nm", pointing, self.directions))
        return position, angle

    def error(self, robot: Robot, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """[(p − p(q)) / size; d − R(q) a], shape (K, 6): both parts vanish together at a solution."""
        T = forward_kinematics(robot, q)
        pointing = T[:, :3, :3] @ self.tool_axis
        return np.concatenate([(self.positions[rows] - T[:, :3, 3]) / arm_size(robot),
                               self.directions[rows] - pointing], axis=1)

    def jacobian(self, robot: Robot, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """[J_v / size; −[R a]× J_ω], shape (K, 6, n): d(R a)/dq = ω × (R a)."""
        T = forward_kinematics(robot, q)
        pointing = T[:, :3, :3] @ self.tool_axis
        J = geometric_jacobian(robot, q)
        cross = np.zeros((len(q), 3, 3))
        cross[:, 0, 1], cross[:, 0, 2], cross[:, 1, 2] = -pointing[:, 2], pointing[:, 1], -pointing[:, 0]
        cross = cross - np.swapaxes(cross, 1, 2)
        return np.concatenate([J[:, :3] / arm_size(robot), -cross @ J[:, 3:]], axis=1)


Goal = PoseGoal | DirectionGoal


#: sin(θ/2) per unit of ‖R − R*‖ (Frobenius), the chord between two rotations θ apart: ‖R − R*‖² =
#: 2 tr(I − R*ᵀR) = 4 (1 − cos θ) = 8 sin²(θ/2).
_HALF_SINE_PER_CHORD = 1.0 / math.sqrt(8.0)


def turn_of_chord(chord_squared: np.ndarray) -> np.ndarray:
    """The angle (radians) of the turn between two rotations from ‖R − R*‖² (Frobenius, any shape): exact
    differences of the matrices' entries, so as precise near zero as the entries are, and no trace to cancel.
    (:func:`pose_residuals_of_rows` writes it on floats, with the same constant.)"""
    return 2.0 * np.arcsin(np.minimum(_HALF_SINE_PER_CHORD * np.sqrt(chord_squared), 1.0))


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot products along the leading axis of length 3, broadcasting the rest."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
