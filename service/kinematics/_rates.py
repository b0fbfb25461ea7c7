"""Joint rates from Cartesian rates, for every arm: J̇ and the inverse velocity and acceleration maps.

With the geometric Jacobian ``J(q)`` of :func:`~._forward.geometric_jacobian`
(rows 0-2: the linear velocity of the tool origin, rows 3-5: the tool's angular
velocity, both in the world frame)::

    [ṗ; ω]  = J(q) q̇                      (the twist)
    [p̈; ω̇]  = J(q) q̈ + J̇(q, q̇) q̇         (its time derivative)

so ``q̇ = J⁻¹ v`` and ``q̈ = J⁻¹ (a − J̇ q̇)``. Here ``v`` is the velocity of the
tool *origin* (not the spatial twist at the world origin) and ``a`` holds the
second derivative of the tool position and the angular acceleration.

**J̇ is analytic** (:func:`jacobian_derivative`): from the screw form of the
columns, with ``ω_i`` and ``p_i`` the axis and a point of joint i and ``p`` the
tool origin. The axis of joint i is fixed in the link before it, so it moves
with the joints j < i only::

    Ω_i  = Σ_{j<i} ω_j q̇_j                         (angular velocity of that link)
    ω̇_i  = Ω_i × ω_i
    ṗ_i  = Σ_{j<i} J_v,j(p_i) q̇_j                  (velocity of p_i on that link)
    ṗ    = Σ_j J_v,j(p) q̇_j                        (velocity of the tool origin)
    revolute:  d/dt [ω_i × (p − p_i); ω_i] = [ω̇_i × (p − p_i) + ω_i × (ṗ − ṗ_i); ω̇_i]
    prismatic: d/dt [ω_i; 0]              = [Ω_i × ω_i; 0]

(``J_v,j(x) = ω_j × (x − p_j)`` for a revolute joint, ``ω_j`` for a prismatic
one.) It holds in every DH convention because it only uses the axes in the
world frame.

**Task rows.** An arm with fewer than six joints controls only part of the
twist, so the rates are solved on the rows it controls (:func:`task_space`).
The rule, from the target kind and the joint axes of the joints that move
(columns; joints the IK holds fixed, the free joints of a position-only target,
are left out and keep a zero rate):

1. A position-only target uses the three linear rows; a pose target all six.
2. If no moving joint is revolute, the angular rows are dropped (the
   orientation cannot change).
3. If every moving revolute axis is parallel to one direction u (a SCARA, a
   planar arm), the angular rows reduce to the one row ``ω·u``; if moreover no
   slide moves along u (a planar arm), the linear row along u is dropped too.

So a PUMA pose uses all 6 rows, a position-only target 3 (x, y, z), a SCARA
pose x, y, z and the rotation about its axis, a planar RR arm x and y. With m
task rows and k moving joints: m = k is solved exactly; m > k by least squares
(exact when the twist is one the arm can produce: the residual says how far it
is from one); m < k with the minimum-norm rates (a redundant arm).

**Distance to a singularity.** The rows are solved in scaled form: linear
rows are divided by the robot's characteristic length L and prismatic columns
multiplied by it, so the scaled task Jacobian J_s is dimensionless. The
distance of a configuration from a singularity is the smallest singular value
of J_s (0 at a singularity; about 1 for a well-conditioned arm). Below
``tolerance`` (default :data:`~._tolerances.RATE_SINGULARITY_TOLERANCE`) the
sample is flagged singular: its rates are NaN, or, when ``damping`` λ is given,
the damped least-squares rates ``Jᵀ(JJᵀ + λ²I)⁻¹ v`` (in the scaled form).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ._errors import InvalidInputError
from ._forward import cross, geometric_jacobian, joint_screws, radius_about, screw_model
from ._robot import Robot, rotation_with_z
from ._tolerances import GEOMETRY_TOLERANCE, RATE_SINGULARITY_TOLERANCE

__all__ = ["JointRates", "TaskSpace", "jacobian_derivative", "joint_rates", "rate_residuals", "task_jacobian",
           "task_space"]

_AXES = "xyz"


def jacobian_derivative(robot: Robot, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Time derivative of the geometric Jacobian, J̇(q, q̇), in the world frame.

    Parameters
    ----------
    q, qd : ndarray, shape (n,) or (N, n)
        Joint values and joint velocities (rad, rad/s for revolute joints;
        length, length/s for prismatic ones).

    Returns
    -------
    ndarray, shape (6, n) or (N, 6, n)
        Rows as in :func:`~._forward.geometric_jacobian`, per unit time.

    Examples
    --------
    The planar RR arm (a1 = 1, a2 = 0.5) turning its first joint at 1 rad/s:
    column 1 is ω × p, whose derivative is the centripetal term −ω² p.

    >>> from service.kinematics import Joint, Robot
    >>> arm = Robot([Joint("q1", "revolute", 1.0, 0, 0, 0), Joint("q2", "revolute", 0.5, 0, 0, 0)])
    >>> np.round(jacobian_derivative(arm, [0.0, 0.0], [1.0, 0.0])[:2], 6).tolist()
    [[-1.5, -0.5], [0.0, 0.0]]
    """
    q = np.asarray(q, dtype=float)
    qd = np.broadcast_to(np.asarray(qd, dtype=float), q.shape)
    directions, points, world_T_tool = joint_screws(robot, q)  # (..., n, 3) each
    p = world_T_tool[..., None, :3, 3]  # (..., 1, 3)
    revolute = robot.is_revolute[:, None]  # (n, 1)
    # Each joint's twist in spatial form (angular w_j, linear at the world origin s_j), times q̇_j.
    w = np.where(revolute, directions, 0.0) * qd[..., None]
    s = np.where(revolute, cross(points, directions), directions) * qd[..., None]
    # Exclusive cumulative sums: the twist of the link that carries axis i (joints j < i).
    W = np.cumsum(w, axis=-2) - w
    S = np.cumsum(s, axis=-2) - s
    point_velocity = S + cross(W, points)  # ṗ_i
    tool_velocity = np.sum(s, axis=-2)[..., None, :] + cross(np.sum(w, axis=-2)[..., None, :], p)  # ṗ
    axis_rate = cross(W, directions)  # ω̇_i (or the slide direction's rate)
    linear = np.where(revolute,
                      cross(axis_rate, p - points) + cross(directions, tool_velocity - point_velocity),
                      axis_rate)
    angular = np.where(revolute, axis_rate, 0.0)
    return np.concatenate([np.swapaxes(linear, -1, -2), np.swapaxes(angular, -1, -2)], axis=-2)


# --------------------------------------------------------------------------
# Task rows
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class TaskSpace:
    """The twist rows an arm controls and the joints whose rates are solved.

    Attributes
    ----------
    basis : ndarray, shape (m, 6)
        Orthonormal rows; the task twist is ``basis @ [ṗ; ω]``.
    names : tuple of str
        One per row: ``vx``, ``vy``, ``vz``, ``wx``, ``wy``, ``wz``, or
        ``w·[ux, uy, uz]`` / ``v·[…]`` for a direction off the world axes.
    columns : ndarray of int, shape (k,)
        Joints whose rates are solved; the others are held (rate 0).
    solve : {"exact", "least_squares", "minimum_norm"}
        m = k, m > k or m < k.
    target_rows : ndarray of int
        Rows of the twist a target of this kind specifies (0-2, or 0-5): the
        ones the residual is measured on.
    """

    basis: np.ndarray
    names: tuple[str, ...]
    columns: np.ndarray
    solve: Literal["exact", "least_squares", "minimum_norm"]
    target_rows: np.ndarray

    @property
    def uses_linear(self) -> bool:
        return bool(np.any(np.abs(self.basis[:, :3]) > 0.0))

    @property
    def uses_angular(self) -> bool:
        return bool(np.any(np.abs(self.basis[:, 3:]) > 0.0))


def _row_name(kind: str, direction: np.ndarray) -> str:
    for axis in range(3):
        if abs(abs(direction[axis]) - 1.0) <= GEOMETRY_TOLERANCE * 10:
            return ("" if direction[axis] > 0 else "-") + kind + _AXES[axis]
    return f"{kind}·[{', '.join(f'{c:.6g}' for c in direction)}]"


def task_space(robot: Robot, *, constrain_orientation: bool, free_joints: tuple[int, ...] | list[int] = ()
               ) -> TaskSpace:
    """The twist rows ``robot`` controls for a target of this kind (the rule in the module docstring).

    Parameters
    ----------
    constrain_orientation : bool
        False for a position-only target.
    free_joints : sequence of int
        Joints the IK holds fixed (their rates are 0 and they are not solved for).

    Examples
    --------
    >>> from service.kinematics import Joint, Robot
    >>> scara = Robot([Joint("t1", "revolute", 1.0, 0, 0, 0), Joint("t2", "revolute", 0.8, np.pi, 0, 0),
    ...                Joint("d3", "prismatic", 0, 0, 0, 0), Joint("t4", "revolute", 0, 0, 0.2, 0)])
    >>> task_space(scara, constrain_orientation=True).names
    ('vx', 'vy', 'vz', 'wz')
    """
    model = screw_model(robot)
    columns = np.array([i for i in range(robot.dof) if i not in set(free_joints)], dtype=int)
    revolute = [i for i in columns if model.is_revolute[i]]
    prismatic = [i for i in columns if not model.is_revolute[i]]
    identity = np.eye(3)
    u = None
    if revolute:
        first = model.directions[revolute[0]]
        if all(radius_about(first, model.directions[i]) <= GEOMETRY_TOLERANCE * 10 for i in revolute):
            u = -first if first[2] < -1e-12 else first
    linear = identity
    linear_names = [f"v{a}" for a in _AXES]
    if u is not None and all(abs(model.directions[i] @ u) <= GEOMETRY_TOLERANCE * 10 for i in prismatic):
        # two orthonormal vectors normal to u: x and y when u is the z axis
        plane = identity[:2] if abs(abs(u[2]) - 1.0) <= GEOMETRY_TOLERANCE * 10 else rotation_with_z(u)[:, :2].T
        linear, linear_names = plane, [_row_name("v", e) for e in plane]
    rows = [np.concatenate([e, np.zeros(3)]) for e in linear]
    names = list(linear_names)
    if constrain_orientation and revolute:
        angular = identity if u is None else u[None]
        rows += [np.concatenate([np.zeros(3), e]) for e in angular]
        names += [f"w{a}" for a in _AXES] if u is None else [_row_name("w", u)]
    basis = np.array(rows)
    m, k = len(basis), len(columns)
    solve = "exact" if m == k else ("least_squares" if m > k else "minimum_norm")
    target_rows = np.arange(6 if constrain_orientation else 3)
    return TaskSpace(basis, tuple(names), columns, solve, target_rows)


# --------------------------------------------------------------------------
# Inverse rates
# --------------------------------------------------------------------------


def _scales(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """Row scale (6,) and column scale (n,) that make the Jacobian dimensionless."""
    L = robot.characteristic_length
    rows = np.array([1 / L] * 3 + [1.0] * 3)
    columns = np.where(robot.is_revolute, 1.0, L)
    return rows, columns


def task_jacobian(robot: Robot, J: np.ndarray, task: TaskSpace) -> np.ndarray:
    """The scaled task Jacobian ``J_s = B · diag(1/L, 1/L, 1/L, 1, 1, 1) · J[:, cols] · diag(L for slides)``.

    J : (..., 6, n) → (..., m, k).
    """
    rows, columns = _scales(robot)
    return task.basis @ (rows[:, None] * J[..., :, task.columns] * columns[task.columns])


@dataclass(frozen=True)
class JointRates:
    """Joint rates per sample; NaN where they were not asked for or do not exist.

    Attributes
    ----------
    velocities, accelerations : ndarray, shape (N, n)
    distance : ndarray, shape (N,)
        Smallest singular value of the scaled task Jacobian (see module docstring).
    singular : ndarray of bool, shape (N,)
        ``distance < tolerance``.
    damped : ndarray of bool, shape (N,)
        The rates of a singular sample are damped least squares.
    velocity_residual, acceleration_residual : ndarray, shape (N,)
        ``‖diag(1/L…, 1…)(J q̇ − v)‖`` over the target's rows (and the same for
        the acceleration): 0 when the rates reproduce the requested twist, which
        an arm with fewer joints than task rows can only do for twists it can
        produce. NaN where there is no rate.
    """

    velocities: np.ndarray
    accelerations: np.ndarray
    distance: np.ndarray
    singular: np.ndarray
    damped: np.ndarray
    velocity_residual: np.ndarray
    acceleration_residual: np.ndarray


def _check_rates_input(value, name: str, count: int) -> np.ndarray | None:
    if value is None:
        return None
    array = np.asarray(value, dtype=float)
    if array.shape != (count, 6):
        raise InvalidInputError(f"{name} must have shape ({count}, 6), got {array.shape}", location=(name,))
    return array


def joint_rates(robot: Robot, q: np.ndarray, twist: np.ndarray | None, acceleration: np.ndarray | None,
                task: TaskSpace, *, tolerance: float = RATE_SINGULARITY_TOLERANCE,
                damping: float | None = None) -> JointRates:
    """Joint velocities ``q̇ = J⁻¹ v`` and accelerations ``q̈ = J⁻¹ (a − J̇ q̇)``, vectorised over samples.

    Parameters
    ----------
    q : ndarray, shape (N, n)
        Joint positions, one row per sample.
    twist : ndarray, shape (N, 6), or None
        ``[ṗ; ω]`` of the tool origin in the world frame per sample. NaN
        entries are components the caller did not give: a row whose task
        components are NaN gets NaN rates; non-task NaNs are ignored.
    acceleration : ndarray, shape (N, 6), or None
        ``[p̈; ω̇]``, the same way.
    task : TaskSpace
        From :func:`task_space`.
    tolerance : float
        Samples whose distance to a singularity is below this are singular.
    damping : float, optional
        λ of the damped least squares for singular samples; None leaves their
        rates NaN.

    Returns
    -------
    JointRates
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    N, n = q.shape
    twist = _check_rates_input(twist, "twist", N)
    acceleration = _check_rates_input(acceleration, "acceleration", N)
    rows, columns = _scales(robot)
    J = geometric_jacobian(robot, q)  # (N, 6, n)
    Js = task_jacobian(robot, J, task)  # (N, m, k)
    U, S, Vt = np.linalg.svd(Js, full_matrices=False)
    distance = S[:, -1] if S.shape[1] else np.zeros(N)
    singular = distance < tolerance
    damped = singular & (damping is not None)
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = np.where(singular[:, None], 0.0, 1.0 / np.where(S > 0, S, 1.0))
        if damping is not None:
            gain = np.where(singular[:, None], S / (S * S + damping * damping), gain)
    usable = ~singular | damped

    def solve(b6: np.ndarray) -> np.ndarray:
        """Joint rates (N, n) for right-hand sides (N, 6) in world units; NaN entries are missing components."""
        missing = np.isnan(b6)
        b = np.nan_to_num(rows * b6) @ task.basis.T  # (N, m)
        y = np.einsum("nrk,nr->nk", Vt, gain * np.einsum("nmr,nm->nr", U, b))
        out = np.zeros((N, n))
        out[:, task.columns] = y * columns[task.columns]
        needed = (missing.astype(float) @ (task.basis != 0).T.astype(float)).any(axis=1)
        out[~usable | needed] = np.nan
        return out

    velocities = np.full((N, n), np.nan)
    accelerations = np.full((N, n), np.nan)
    if twist is not None:
        velocities = solve(twist)
        if acceleration is not None:
            known = np.nan_to_num(velocities)
            rhs = acceleration - np.einsum("nij,nj->ni", jacobian_derivative(robot, q, known), known)
            accelerations = solve(rhs)
            accelerations[np.isnan(velocities).any(axis=1)] = np.nan
    velocity_residual, acceleration_residual = rate_residuals(robot, q, velocities, accelerations, twist,
                                                              acceleration, task, J=J)
    return JointRates(velocities, accelerations, distance, singular, damped, velocity_residual,
                      acceleration_residual)


def rate_residuals(robot: Robot, q: np.ndarray, velocities: np.ndarray, accelerations: np.ndarray,
                   twist: np.ndarray | None, acceleration: np.ndarray | None, task: TaskSpace, *,
                   J: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """How well joint rates reproduce the requested twist and acceleration, per sample.

    ``‖D (J q̇ − v)‖`` and ``‖D (J q̈ + J̇ q̇ − a)‖`` over the target's rows,
    with D = diag(1/L, 1/L, 1/L, 1, 1, 1); components the caller did not give
    (NaN) are skipped. NaN where a rate is NaN or no twist was given.

    Parameters
    ----------
    q, velocities, accelerations : ndarray, shape (N, n)
    twist, acceleration : ndarray, shape (N, 6), or None
    """
    rows, _ = _scales(robot)
    N = len(q)
    J = geometric_jacobian(robot, q) if J is None else J

    def norm(error: np.ndarray, rates: np.ndarray) -> np.ndarray:
        error = (rows * error)[:, task.target_rows]
        value = np.sqrt(np.nansum(error * error, axis=1))
        return np.where(np.isnan(rates).any(axis=1), np.nan, value)

    nan = np.full(N, np.nan)
    if twist is None:
        return nan, nan.copy()
    known = np.nan_to_num(velocities)
    velocity = norm(np.einsum("nij,nj->ni", J, known) - twist, velocities)
    if acceleration is None:
        return velocity, nan
    produced = (np.einsum("nij,nj->ni", J, np.nan_to_num(accelerations))
                + np.einsum("nij,nj->ni", jacobian_derivative(robot, q, known), known))
    return velocity, norm(produced - acceleration, accelerations)
