"""Forward kinematics, link frames, joint screws and the geometric Jacobian.

Frames: ``world`` is the frame poses are given in; ``base`` is the robot's
frame 0 (``world_T_base``); frame i is the DH frame attached after joint i;
``flange`` is frame n and ``tool`` is ``flange_T_tool`` after it. For a robot
built from screws (URDF chains too) frame i is ``F_0 · M(q_1) · F_1 ⋯ M(q_i) · F_i``:
like a standard DH frame it carries the axis of joint i + 1 as its z axis, and
frame n is the flange (see :meth:`Robot.from_screws`).

Every function takes joint values ``q`` with shape (n,) or a batch (N, n) and
vectorises over N: there is no Python loop over configurations. The one
exception is :func:`tool_columns_scalar_rows`, the same chain on a few joint
vectors in plain floats, for which array operations cost more than they save
(:func:`forward_kinematics` of up to :data:`SCALAR_ROWS` rows takes it).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from ._cache import memo
from ._conventions import link_transforms
from ._robot import Robot


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
    columns = link_frame_columns(robot, q.reshape(-1, robot.dof))  # (n + 1, 12, N)
    frames = np.empty((len(columns), columns.shape[2], 4, 4))
    frames[:, :, :3, :] = columns.reshape(len(columns), 4, 3, -1).transpose(0, 3, 2, 1)
    frames[:, :, 3, :3] = 0.0
    frames[:, :, 3, 3] = 1.0
    return np.moveaxis(frames, 0, 1).reshape(q.shape[:-1] + (robot.dof + 1, 4, 4))


def link_frame_columns(robot: Robot, q: np.ndarray) -> np.ndarray:
    """:func:`link_frames` laid out for batch arithmetic: frame by frame, each frame's top 3 × 4 by columns.

    Parameters
    ----------
    q : ndarray, shape (N, n)

    Returns
    -------
    ndarray, shape (n + 1, 12, N)
        Row f holds ``world_T_frame[f][:3, :]`` column after column: x (3 rows), y, z, then the origin p.
    """
    program = frames_program(robot)
    qt = np.asarray(q, dtype=float).T
    columns = np.empty((robot.dof + 1, 12, qt.shape[1]))
    for begin in range(0, qt.shape[1], _FRAMES_BLOCK):
        block = columns[:, :, begin:begin + _FRAMES_BLOCK]
        for frame, (x, y, z, p) in enumerate(_run(program, qt[:, begin:begin + _FRAMES_BLOCK], program.frame_ends)):
            block[frame, 0:3], block[frame, 3:6], block[frame, 6:9], block[frame, 9:12] = x, y, z, p
    return columns


#: Configurations per run of the frames program: the run's temporaries then stay in cache (measured on 100,000
#: PUMA configurations: 40 ms in blocks of 1,024 to 16,384, 58 ms in one run).
_FRAMES_BLOCK = 4096


def _matrix_frames(robot: Robot, q: np.ndarray) -> np.ndarray:
    """:func:`link_frames` of a DH robot as products of its 4 × 4 link transforms, shape (..., n + 1, 4, 4).

    The joint screws (:func:`joint_screws`, and so the IK plans' screw model and the Jacobian) are read from these
    products; they differ from the column operations of :func:`link_frames` (which give the plans' link x
    directions) in the last bits only, and the IK plans' near-singular behaviour is held by tests on these bits.
    """
    theta = robot.theta + np.where(robot.is_revolute, q, 0.0)
    d = robot.d + np.where(robot.is_revolute, 0.0, q)
    # joints first: each joint's transforms, and each frame, one contiguous block
    per_joint = (-1,) + (1,) * (q.ndim - 1)
    prev_T_link = link_transforms(robot.convention, robot.a.reshape(per_joint), robot.alpha.reshape(per_joint),
                                  np.moveaxis(d, -1, 0), np.moveaxis(theta, -1, 0))
    frames = np.empty((robot.dof + 1,) + q.shape[:-1] + (4, 4))
    frames[0] = robot.world_T_base
    for i in range(robot.dof):
        np.matmul(frames[i], prev_T_link[i], out=frames[i + 1])
    return np.moveaxis(frames, 0, -3)


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
    count = math.prod(q.shape[:-1])  # joint vectors: 1 for q of shape (n,)
    if 0 < count <= SCALAR_ROWS:
        try:
            tools = tool_columns_scalar_rows(robot, [q.tolist()] if q.ndim == 1 else
                                             q.reshape(count, q.shape[-1]).tolist())
        except ValueError:  # an infinite value (math.cos refuses it): the arrays give NaN there
            tools = None
        if tools is not None:
            if q.ndim == 1:  # one configuration: its matrix as it comes
                return np.array(_rows_of(tools[0]))
            return np.array([_rows_of(tool) for tool in tools]).reshape(q.shape[:-1] + (4, 4))
    rows = q.reshape(-1, q.shape[-1])
    x, y, z, p = tool_columns(robot, rows)
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


# The operations of a chain program (:func:`_chain_program`); each acts on the frame's columns x, y, z, p.
_TURN = 0  # a turn about z by a joint's angle: (_TURN, joint, constant angle)
_SLIDE = 1  # a move along z by a joint's value: (_SLIDE, joint, constant offset)
_MOVE_Z = 2  # a fixed move along z: (_MOVE_Z, -1, distance)
_MOVE_X = 3  # a fixed move along x: (_MOVE_X, -1, distance)
_TWIST = 4  # a fixed turn about x: (_TWIST, -1, (cos, sin))
_FIXED = 5  # a fixed rigid motion: (_FIXED, -1, its columns x, y, z, t flattened (12 floats))
_TURN_BY = 6  # a fixed turn about z (a prismatic joint's theta): (_TURN_BY, -1, (cos, sin))
_QUARTER = 7  # a fixed turn about x by ±90°: (_QUARTER, -1, ±1.0), a _TWIST with cos 0 and sin ±1


class ChainProgram(NamedTuple):
    """``world_T_tool`` as a start frame and the column operations that follow, built once per robot.

    Post-multiplying a frame by Rz(θ) mixes its x and y columns, by Rx(α) its
    y and z columns, and a translation adds multiples of its columns to the
    position; terms that are zero for this robot (a = 0, d = 0, α = 0, an
    identity tool) are left out. :func:`tool_columns` runs it on a batch,
    :func:`tool_columns_scalar_rows` on a few joint vectors: the same operations.
    """

    start: tuple[float, ...]  # world_T_base (· F_0 for a screws robot's tool program): columns x, y, z, p
    operations: tuple[tuple[int, int, object], ...]
    joint_steps: tuple[int, ...]  # per joint, the index of the operation that reads its value
    frame_ends: tuple[int, ...]  # per link frame 0 … n, the number of operations done when it is reached


def chain_program(robot: Robot) -> ChainProgram:
    """The robot's :class:`ChainProgram` to the tool (memoised on the robot)."""
    return memo(robot, "chain_program", lambda: _chain_program(robot, to_tool=True))


def frames_program(robot: Robot) -> ChainProgram:
    """The robot's :class:`ChainProgram` through its link frames to the flange, without folding fixed motions
    across a frame (memoised on the robot)."""
    return memo(robot, "frames_program", lambda: _chain_program(robot, to_tool=False))


def _columns(T: np.ndarray) -> tuple[float, ...]:
    return tuple(T[:3, :].T.ravel().tolist())


def _chain_program(robot: Robot, *, to_tool: bool) -> ChainProgram:
    """The column operations to the tool (``to_tool``: fixed motions folded together where no frame is read), or
    through every link frame to the flange."""
    operations: list[tuple[int, int, object]] = []
    frame_ends = [0]
    tool = robot.flange_T_tool if to_tool else _IDENTITY
    if robot.chain_transforms is not None:  # base · F_0, then per joint its motion about local z and F_i
        chain = robot.chain_transforms
        if not to_tool:
            operations.append((_FIXED, -1, _columns(chain[0])))
        for i in range(robot.dof):
            operations.append((_TURN, i, 0.0) if robot.is_revolute[i] else (_SLIDE, i, 0.0))
            fixed = chain[i + 1] @ tool if i == robot.dof - 1 else chain[i + 1]
            operations.append((_FIXED, -1, _columns(fixed)))
            frame_ends.append(len(operations))
        start = robot.world_T_base @ chain[0] if to_tool else robot.world_T_base
        return _program(_columns(start), operations, frame_ends)
    standard = robot.convention == "standard"
    for i, step in enumerate(_chain_steps(robot)):
        if step.revolute:
            about_z = [(_TURN, i, step.theta)] + ([(_MOVE_Z, -1, step.d)] if step.d != 0.0 else [])
        else:
            about_z = [(_SLIDE, i, step.d)]
            if step.theta != 0.0:
                about_z.append((_TURN_BY, -1, (math.cos(step.theta), math.sin(step.theta))))
        about_x = [(_MOVE_X, -1, step.a)] if step.a != 0.0 else []
        if step.twisted:
            about_x.append((_QUARTER, -1, step.sin_alpha) if step.cos_alpha == 0.0 and abs(step.sin_alpha) == 1.0
                           else (_TWIST, -1, (step.cos_alpha, step.sin_alpha)))
        # standard DH: A = Rz(θ) Tz(d) Tx(a) Rx(α); Craig and Khalil: T = Rx(α) Tx(a) Rz(θ) Tz(d). Either way the
        # row's operations end at its frame.
        operations += about_z + about_x if standard else about_x + about_z
        frame_ends.append(len(operations))
    if not np.array_equal(tool, _IDENTITY):
        operations.append((_FIXED, -1, _columns(tool)))
    return _program(_columns(robot.world_T_base), operations, frame_ends)


def _program(start: tuple[float, ...], operations: list[tuple[int, int, object]],
             frame_ends: list[int]) -> ChainProgram:
    joint_steps = tuple(i for i, (kind, _, _) in enumerate(operations) if kind in (_TURN, _SLIDE))
    return ChainProgram(start, tuple(operations), joint_steps, tuple(frame_ends))


class JointTrig:
    """cos and sin of each joint column of q (..., n), each computed once, when first asked for: the FK check and
    a family's branch labels turn the same joints, the labels several times. ``trig[i]`` is (cos q_i, sin q_i).
    A float array ``q`` is kept as it is (not copied): :meth:`renew` re-reads the rows the caller changed in it."""

    def __init__(self, q: np.ndarray) -> None:
        self.q = np.asarray(q, dtype=float)
        self._pairs: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def __getitem__(self, joint: int) -> tuple[np.ndarray, np.ndarray]:
        pair = self._pairs.get(joint)
        if pair is None:
            angle = self.q[..., joint]
            pair = self._pairs[joint] = (np.cos(angle), np.sin(angle))
        return pair

    def take(self, rows: np.ndarray) -> "JointTrig":
        """The rows ``rows`` of q (M, n) with the pairs computed so far: a new object, q and pairs copied."""
        taken = JointTrig(self.q[rows])
        taken._pairs = {joint: (cos[rows], sin[rows]) for joint, (cos, sin) in self._pairs.items()}
        return taken

    def renew(self, rows: np.ndarray) -> None:
        """Recompute the pairs kept so far at ``rows`` of q (M, n), whose values the caller has changed."""
        for joint, (cos, sin) in self._pairs.items():
            angle = self.q[rows, joint]
            cos[rows], sin[rows] = np.cos(angle), np.sin(angle)


def tool_columns(robot: Robot, q: np.ndarray, trig: JointTrig | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``world_T_tool`` for a batch of joint vectors, as its four columns (:class:`ChainProgram`, each operation
    a few elementwise operations over the whole batch).

    Parameters
    ----------
    q : ndarray, shape (N, n)
    trig : the cos and sin of q's columns, when shared with the caller's other steps

    Returns
    -------
    x, y, z, p : ndarrays, shape (3, N)
        The rotation's columns and the position of the tool, in the world frame.
    """
    program = chain_program(robot)
    *_, tool = _run(program, np.asarray(q, dtype=float).T, (), trig)
    return tool


def _run(program: ChainProgram, qt: np.ndarray, frame_ends: tuple[int, ...], trig: JointTrig | None = None) -> list:
    """Run ``program`` on joint values ``qt`` (n, N): the frame (x, y, z, p columns, each (3, N)) after each count
    of operations in ``frame_ends``, then the last one. The arrays are never written in place, so a frame handed
    out stays as it was. ``trig`` (of qt's transpose) gives the cos and sin of the joints turned with no offset."""
    count = qt.shape[1]
    start = np.array(program.start).reshape(4, 3, 1)
    x, y, z, p = (np.repeat(column, count, axis=1) for column in start)
    frames = []
    ends = iter(frame_ends)
    end = next(ends, -1)
    for index, (kind, joint, value) in enumerate(program.operations):
        while index == end:
            frames.append((x, y, z, p))
            end = next(ends, -1)
        if kind == _TURN:
            if value == 0.0 and trig is not None:
                c, s = trig[joint]
            else:
                angle = qt[joint] + value if value != 0.0 else qt[joint]
                c, s = np.cos(angle), np.sin(angle)
            x, y = x * c + y * s, y * c - x * s
        elif kind == _SLIDE:
            p = p + z * (qt[joint] + value)
        elif kind == _MOVE_Z:
            p = p + z * value
        elif kind == _MOVE_X:
            p = p + x * value
        elif kind == _TWIST:
            c, s = value
            y, z = y * c + z * s, z * c - y * s
        elif kind == _QUARTER:
            y, z = (z, -y) if value > 0 else (-z, y)
        elif kind == _TURN_BY:
            c, s = value
            x, y = x * c + y * s, y * c - x * s
        else:
            a0, a1, a2, b0, b1, b2, c0, c1, c2, t0, t1, t2 = value
            p = p + x * t0 + y * t1 + z * t2
            x, y, z = x * a0 + y * a1 + z * a2, x * b0 + y * b1 + z * b2, x * c0 + y * c1 + z * c2
    frames.append((x, y, z, p))
    return frames


_IDENTITY = np.eye(4)


def tool_columns_scalar_rows(robot: Robot, rows: list[list[float]]) -> list[tuple[tuple[float, float, float], ...]]:
    """:func:`tool_columns` for a few joint vectors (lists of floats), in scalar arithmetic: the same
    :class:`ChainProgram`, without the fixed cost of array operations (:class:`ScalarChain`). A row that shares its
    first joints' values with the row before it (as the IK solutions of one branch of the arm do) starts from the
    frame those joints gave it: the same operations on the same numbers, done once.

    Returns, per row, the columns x, y, z, p of ``world_T_tool`` as tuples of three floats.
    """
    chain = scalar_chain(robot)
    start, run = chain.start, chain.run
    frames: list[tuple[float, ...]] = []  # frames[j]: the frame before the operations of joint j, last row
    previous: list[float] = []
    out = []
    for q in rows:
        shared = 0
        for a, b in zip(q, previous):
            if a != b:
                break
            shared += 1
        if shared < len(frames):
            frame = frames[shared]
            del frames[shared:]
            out.append(run(q, frames, shared + 1, *frame))
        else:
            frames.clear()
            out.append(run(q, frames, 0, *start))
        previous = q
    return out


class ScalarChain(NamedTuple):
    """A robot's :class:`ChainProgram` on one joint vector of floats, as straight-line arithmetic (no loop over
    operations, none dispatched by kind). ``run(q, frames, segment, x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1,
    p2)`` runs the operations from ``segment`` on (0: from ``start``, every one; j + 1: from joint j's, on the
    frame before it), appends the frame before each joint it turns or slides to ``frames`` (for a later row that
    shares those joints) and returns the tool's columns x, y, z, p."""

    start: tuple[float, ...]
    run: Callable


def scalar_chain(robot: Robot) -> ScalarChain:
    """The robot's :class:`ScalarChain` (memoised on the robot). The code is compiled once per shape of program
    (the operations' kinds and joints, :func:`_chain_code`): a robot binds its own constants to it."""
    return memo(robot, "scalar_chain", lambda: _scalar_chain(chain_program(robot)))


def _scalar_chain(program: ChainProgram) -> ScalarChain:
    constants = [_constants(kind, value) for kind, _, value in program.operations]
    shape = tuple((kind, joint, _shape_of(kind, value), len(numbers))
                  for (kind, joint, value), numbers in zip(program.operations, constants))
    bound = [number for numbers in constants for number in numbers]
    return ScalarChain(program.start, _chain_code(shape, program.joint_steps)(math.cos, math.sin, *bound))


def _shape_of(kind: int, value) -> bool | None:
    """What of an operation's constant its code depends on: a quarter turn's sign; nothing for the others, whose
    constants are bound, not written (a joint's offset, where it is zero, is not bound: :func:`_constants`)."""
    return value > 0 if kind == _QUARTER else None


def _constants(kind: int, value) -> tuple[float, ...]:
    """The constants an operation's code reads, in the order :func:`_operation_lines` names them."""
    if kind in (_TURN, _SLIDE):
        return (value,) if value != 0.0 else ()
    if kind in (_MOVE_X, _MOVE_Z):
        return (value,)
    if kind in (_TWIST, _TURN_BY, _FIXED):
        return tuple(value)
    return ()


_FRAME = "x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2"


def _operation_lines(kind: int, joint: int, positive: bool | None, names: list[str]) -> list[str]:
    """One operation as lines of float arithmetic on the frame's columns (the same as :func:`_run` does on
    arrays), its constants read from ``names`` (as :func:`_constants` lists them; a joint's offset only where it
    is not zero); ``positive``: a quarter turn's sign."""
    if kind in (_TURN, _SLIDE):
        value = f"q[{joint}] + {names[0]}" if names else f"q[{joint}]"
        if kind == _SLIDE:
            return [f"frames.append(({_FRAME}))", f"d = {value}", "p0, p1, p2 = p0 + z0 * d, p1 + z1 * d, p2 + z2 * d"]
        return [f"frames.append(({_FRAME}))", f"angle = {value}", "c, s = cos(angle), sin(angle)",
                "x0, x1, x2, y0, y1, y2 = (x0 * c + y0 * s, x1 * c + y1 * s, x2 * c + y2 * s, "
                "y0 * c - x0 * s, y1 * c - x1 * s, y2 * c - x2 * s)"]
    if kind == _QUARTER:  # a twist of ±90°: the y and z columns swap (a sign changes)
        return ["y0, y1, y2, z0, z1, z2 = z0, z1, z2, -y0, -y1, -y2" if positive
                else "y0, y1, y2, z0, z1, z2 = -z0, -z1, -z2, y0, y1, y2"]
    if kind in (_MOVE_X, _MOVE_Z):
        column, (k,) = ("x" if kind == _MOVE_X else "z"), names
        return [f"p0, p1, p2 = p0 + {column}0 * {k}, p1 + {column}1 * {k}, p2 + {column}2 * {k}"]
    if kind == _TWIST:
        c, s = names
        return [f"y0, y1, y2, z0, z1, z2 = (y0 * {c} + z0 * {s}, y1 * {c} + z1 * {s}, y2 * {c} + z2 * {s}, "
                f"z0 * {c} - y0 * {s}, z1 * {c} - y1 * {s}, z2 * {c} - y2 * {s})"]
    if kind == _TURN_BY:
        c, s = names
        return [f"x0, x1, x2, y0, y1, y2 = (x0 * {c} + y0 * {s}, x1 * {c} + y1 * {s}, x2 * {c} + y2 * {s}, "
                f"y0 * {c} - x0 * {s}, y1 * {c} - x1 * {s}, y2 * {c} - x2 * {s})"]
    a0, a1, a2, b0, b1, b2, c0, c1, c2, t0, t1, t2 = names
    return [f"p0, p1, p2 = (p0 + x0 * {t0} + y0 * {t1} + z0 * {t2}, p1 + x1 * {t0} + y1 * {t1} + z1 * {t2}, "
            f"p2 + x2 * {t0} + y2 * {t1} + z2 * {t2})",
            f"x0, x1, x2, y0, y1, y2, z0, z1, z2 = ("
            f"x0 * {a0} + y0 * {a1} + z0 * {a2}, x1 * {a0} + y1 * {a1} + z1 * {a2}, x2 * {a0} + y2 * {a1} + z2 * {a2}, "
            f"x0 * {b0} + y0 * {b1} + z0 * {b2}, x1 * {b0} + y1 * {b1} + z1 * {b2}, x2 * {b0} + y2 * {b1} + z2 * {b2}, "
            f"x0 * {c0} + y0 * {c1} + z0 * {c2}, x1 * {c0} + y1 * {c1} + z1 * {c2}, x2 * {c0} + y2 * {c1} + z2 * {c2})"]


@functools.lru_cache(maxsize=256)
def _chain_code(shape: tuple[tuple[int, int, bool | None, int], ...], joint_steps: tuple[int, ...]) -> Callable:
    """The operations of ``shape`` ((kind, joint, :func:`_shape_of`, how many constants) each) compiled to one
    function: a factory that takes cos, sin and the constants (:func:`_constants` of each operation, in order) and
    returns the ``run`` :class:`ScalarChain` describes. Segment 0 holds the operations before the first joint's,
    segment j + 1 those from joint j's to the next joint's (``joint_steps``); each runs where ``segment`` is at
    most its number. Only the kinds' fixed lines, joint indices and generated names enter the source; the numbers
    are bound as arguments."""
    bounds = [0, *joint_steps, len(shape)]
    lines, names = [], []
    for number, (first, end) in enumerate(zip(bounds[:-1], bounds[1:])):
        body = []
        for kind, joint, positive, count in shape[first:end]:
            own = [f"k{len(names) + i}" for i in range(count)]
            names += own
            body += _operation_lines(kind, joint, positive, own)
        lines += [f"if segment <= {number}:", *(f"    {line}" for line in body or ["pass"])]
    source = (f"def factory(cos, sin{''.join(', ' + name for name in names)}):\n"
              f"    def run(q, frames, segment, {_FRAME}):\n"
              + "".join(f"        {line}\n" for line in lines) +
              "        return (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2)\n"
              "    return run\n")
    namespace: dict = {}
    exec(compile(source, "<scalar chain>", "exec"), namespace)
    return namespace["factory"]


#: Up to this many joint vectors, :func:`forward_kinematics` and :func:`geometric_jacobian` run the scalar chain on
#: each (:func:`tool_columns_scalar_rows`, the array chain's values bit for bit): the arrays' fixed cost is that of
#: about a dozen rows on floats (FK of a UR5 rounded as CAD exports round: 6 µs a row, against 71 µs for the arrays
#: at one row and 76 at eight). Gauss–Newton's steps on one pose's few candidates, and on the last rows of a search
#: still converging, take it. (The FK check's residuals of a few candidates, computed on floats without building
#: arrays, pay off up to more rows: ``ik._goals.SCALAR_CANDIDATES``.)
SCALAR_ROWS = 12

_BOTTOM_ROW = (0.0, 0.0, 0.0, 1.0)


def _rows_of(columns: tuple[tuple[float, float, float], ...]) -> tuple[tuple[float, ...], ...]:
    """The rows of ``world_T_tool`` (4 × 4) from its columns x, y, z, p (three floats each)."""
    (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2) = columns
    return (x0, y0, z0, p0), (x1, y1, z1, p1), (x2, y2, z2, p2), _BOTTOM_ROW


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
    frames = _matrix_frames(robot, q)
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
    q = np.asarray(q, dtype=float)
    rows = q.reshape(-1, q.shape[-1])
    if 0 < len(rows) <= SCALAR_ROWS:
        jacobians = _jacobians_scalar(robot, rows.tolist())
        if jacobians is not None:
            return jacobians.reshape(q.shape[:-1] + (6, robot.dof))
    directions, points, world_T_tool = joint_screws(robot, q)
    tool_position = world_T_tool[..., None, :3, 3]
    revolute = robot.is_revolute[:, None]
    linear = np.where(revolute, cross(directions, tool_position - points), directions)
    angular = np.where(revolute, directions, 0.0)
    return np.concatenate([np.swapaxes(linear, -1, -2), np.swapaxes(angular, -1, -2)], axis=-2)


def _jacobians_scalar(robot: Robot, rows: list[list[float]]) -> np.ndarray | None:
    """:func:`geometric_jacobian` (K, 6, n) of a few joint vectors on the scalar chain (:class:`ScalarChain`): each
    joint's axis is the z column of the frame the chain reaches just before the joint's motion, and that frame's
    origin a point on it; the tool point is where the chain ends. The same columns as :func:`joint_screws` gives
    to rounding (it multiplies the link matrices; a point other than its frame's origin, on the same axis, where
    a Craig table's d_i lies between them). None when a value is infinite (``math.cos`` refuses it)."""
    chain = scalar_chain(robot)
    start, run = chain.start, chain.run
    revolute = robot.is_revolute.tolist()
    jacobians = []
    for q in rows:
        frames: list[tuple[float, ...]] = []
        try:
            *_, (t0, t1, t2) = run(q, frames, 0, *start)
        except ValueError:
            return None
        columns = []
        for turns, (*_, z0, z1, z2, p0, p1, p2) in zip(revolute, frames):
            if turns:  # [z × (tool − p); z]
                d0, d1, d2 = t0 - p0, t1 - p1, t2 - p2
                columns.append((z1 * d2 - z2 * d1, z2 * d0 - z0 * d2, z0 * d1 - z1 * d0, z0, z1, z2))
            else:  # [z; 0]
                columns.append((z0, z1, z2, 0.0, 0.0, 0.0))
        jacobians.append(columns)
    return np.ascontiguousarray(np.array(jacobians).reshape(len(rows), len(revolute), 6).transpose(0, 2, 1))


#: Up to this many values (a few hundred vectors), :func:`cross` gathers the rotated components (a copy each),
#: which costs less than slicing them out one by one; past it the slices' views win.
_FEW_CROSSES = 768
_NEXT, _AFTER = np.array([1, 2, 0]), np.array([2, 0, 1])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b along the last axis, shapes (..., 3) broadcast together: np.cross's values without its axis
    bookkeeping (a third of its time on small batches; the Jacobian, the rates and the general solver's Newton
    steps call it often). Two 3-vectors (a plan's axes, built once per geometry) are multiplied as floats: the same
    products, a thirtieth of np.cross's time at that size."""
    if a.ndim == 1 and b.ndim == 1:
        (a0, a1, a2), (b0, b1, b2) = a.tolist(), b.tolist()
        return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))
    if max(a.size, b.size) <= _FEW_CROSSES:  # the same products, rotated components gathered: four calls, not 16
        return a.take(_NEXT, axis=-1) * b.take(_AFTER, axis=-1) - a.take(_AFTER, axis=-1) * b.take(_NEXT, axis=-1)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def radius_about(axis: np.ndarray, v: np.ndarray) -> np.ndarray:
    """‖axis × v‖ along the last axis, v (..., 3) → (...): the distance of the point v from the line through the
    origin along the unit vector ``axis`` (of a point p from the line through c, ``radius_about(axis, p − c)``), or
    for a unit v the sine of the angle between the two."""
    return np.linalg.norm(cross(axis, v), axis=-1)
