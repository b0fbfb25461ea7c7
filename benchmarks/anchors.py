"""Adapters for the anchor libraries: EAIK, ik-geo and roboticstoolbox-python.

Each adapter is built from the core's own robot (its DH table or its screw
model), so every library solves the same arm for the same poses. A library
that is not installed, or does not support an arm, is skipped with a reason.
All joint vectors are returned in the core's convention (the DH table's
joint variables), as arrays of shape (m, n).
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from service.kinematics import Robot
from service.kinematics.ik._plan import geometry_of


@dataclass
class Anchor:
    """One library set up for one robot. Missing operations are None."""

    library: str
    ik_single: Callable[[np.ndarray], np.ndarray] | None = None  # (4, 4) -> (m, n)
    ik_batch: Callable[[np.ndarray], list[np.ndarray]] | None = None  # (N, 4, 4) -> N × (m, n)
    #: the batch call with a given number of worker threads, for a library that takes one: (N, 4, 4), k -> N × (m, n)
    ik_batch_threads: Callable[[np.ndarray, int], list[np.ndarray]] | None = None
    fk_single: Callable[[np.ndarray], object] | None = None  # (n,) -> pose
    fk_batch: Callable[[np.ndarray], object] | None = None  # (N, n) -> poses
    notes: list[str] = field(default_factory=list)


LIBRARIES = {"EAIK": "eaik", "ik-geo": "ik_geo", "roboticstoolbox": "roboticstoolbox"}


def installed(library: str) -> bool:
    return importlib.util.find_spec(LIBRARIES[library]) is not None


def _standard_dh(robot: Robot) -> str | None:
    """Why a library that takes a plain standard DH table cannot take this robot, or None if it can."""
    if robot.convention != "standard":
        return "needs a standard DH table"
    if not (np.allclose(robot.world_T_base, np.eye(4)) and np.allclose(robot.flange_T_tool, np.eye(4))):
        return "needs a robot without base or tool transform"
    return None


def eaik(robot: Robot) -> Anchor | str:
    """EAIK (C++): ``DhRobot`` from the DH table; ``IK``, ``IK_batched`` (its default threads) and ``fwdKin``."""
    from eaik.IK_DH import DhRobot

    why = _standard_dh(robot)
    if why:
        return why
    if not robot.is_revolute.all():
        return "DhRobot takes revolute joints only"
    bot = DhRobot(robot.alpha.copy(), robot.a.copy(), robot.d.copy())
    if not bot.hasKnownDecomposition():
        return f"no closed form for this arm ({bot.getKinematicFamily()})"
    offset = robot.theta

    def solutions(result) -> np.ndarray:
        Q = np.asarray(result.Q, dtype=float).reshape(-1, robot.dof)
        return Q[~np.asarray(result.is_LS, dtype=bool)] - offset

    return Anchor(
        "EAIK",
        ik_single=lambda T: solutions(bot.IK(T)),
        ik_batch=lambda Ts: [solutions(r) for r in bot.IK_batched(Ts)],
        ik_batch_threads=lambda Ts, threads: [solutions(r) for r in bot.IK_batched(Ts, threads)],
        fk_single=lambda q: bot.fwdKin(q + offset),
        notes=[f"family {bot.getKinematicFamily()}; IK_batched with its default 4 worker threads"],
    )


def _screw_chain(robot: Robot):
    """The arm's screw model as axis directions h (n, 3), offsets p (n + 1, 3) between consecutive axis points
    (from the world origin to the tool), the home rotation (3, 3) and the geometry: consecutive axes that meet share
    their point, so that the zero offsets a family expects are exact zeros."""
    geometry = geometry_of(robot)
    model = geometry.model
    h = model.directions.copy()
    points = model.points.copy()
    for i in range(len(points) - 1):
        meet = geometry.intersection(i, i + 1)
        if meet is not None:
            points[i] = points[i + 1] = meet
    if robot.dof == 6 and geometry.common_point((3, 4, 5)) is not None:
        points[3] = points[4] = points[5] = geometry.common_point((3, 4, 5))
    tool = model.home[:3, 3]
    p = np.vstack([points[0], np.diff(points, axis=0), tool - points[-1]])
    return h, p, model.home[:3, :3], geometry


def eaik_screws(robot: Robot) -> Anchor | str:
    """EAIK (C++) from the screw model, for an arm that is no plain standard DH table (a Craig table, a base or a
    tool): its ``Robot`` from h, p and the home rotation; ``IK`` and ``IK_batched``."""
    import eaik.pybindings.EAIK as EAIK
    from eaik.IK_HP import HPRobot

    if not robot.is_revolute.all():
        return "EAIK takes revolute joints only"
    h, p, home_R, _ = _screw_chain(robot)
    bot = HPRobot(h, p)
    bot._robot = EAIK.Robot(h.T, p.T, home_R, [], True)  # HPRobot takes no home rotation; the binding does
    if not bot.hasKnownDecomposition():
        return f"no closed form for this arm ({bot.getKinematicFamily()})"

    def solutions(result) -> np.ndarray:
        Q = np.asarray(result.Q, dtype=float).reshape(-1, robot.dof)
        return Q[~np.asarray(result.is_LS, dtype=bool)]

    return Anchor(
        "EAIK",
        ik_single=lambda T: solutions(bot.IK(T)),
        ik_batch=lambda Ts: [solutions(r) for r in bot.IK_batched(Ts)],
        ik_batch_threads=lambda Ts, threads: [solutions(r) for r in bot.IK_batched(Ts, threads)],
        fk_single=lambda q: bot.fwdKin(q),
        notes=[f"family {bot.getKinematicFamily()} (from the screw model); IK_batched with its default 4 worker "
               f"threads"],
    )


def ik_geo(robot: Robot) -> Anchor | str:
    """ik-geo (Rust): a family constructor from the screw model (h, p); ``get_ik`` and ``forward_kinematics``."""
    import ik_geo as lib

    if robot.dof != 6 or not robot.is_revolute.all():
        return "6R arms only"
    h, p, home_R, geometry = _screw_chain(robot)
    if geometry.common_point((3, 4, 5)) is not None and geometry.intersection(0, 1) is not None:
        bot, family = lib.Robot.spherical_two_intersecting(h, p), "spherical_two_intersecting"
    elif geometry.parallel(1, 2) and geometry.parallel(2, 3) and geometry.intersection(4, 5) is not None:
        bot, family = lib.Robot.three_parallel_two_intersecting(h, p), "three_parallel_two_intersecting"
    else:
        return "no ik-geo family matched"

    def solve(T: np.ndarray) -> np.ndarray:
        found = bot.get_ik((T[:3, :3] @ home_R.T).T, T[:3, 3])  # ik-geo reads and writes rotations transposed
        exact = [q for q, least_squares in found if not least_squares]
        return np.array(exact, dtype=float).reshape(-1, 6)

    return Anchor("ik-geo", ik_single=solve, fk_single=lambda q: bot.forward_kinematics(q),
                  notes=[f"family {family}"])


def roboticstoolbox(robot: Robot) -> Anchor | str:
    """roboticstoolbox-python: a ``DHRobot`` from the DH table; ``analytic_ik().solve`` and ``ETS.eval``."""
    from roboticstoolbox import DHRobot, PrismaticDH, RevoluteDH

    why = _standard_dh(robot)
    if why:
        return why
    span = 10 * robot.characteristic_length  # solve() needs a range for prismatic joints; joint_limits=False ignores it
    links = [RevoluteDH(a=a, alpha=alpha, d=d, offset=theta) if revolute else
             PrismaticDH(a=a, alpha=alpha, theta=theta, offset=d, qlim=[-span, span])
             for a, alpha, d, theta, revolute in zip(robot.a, robot.alpha, robot.d, robot.theta, robot.is_revolute)]
    bot = DHRobot(links, name=robot.name)
    ets = bot.ets()
    anchor = Anchor("roboticstoolbox", fk_single=lambda q: ets.eval(q), fk_batch=lambda Q: ets.eval(Q))
    try:
        solver = bot.analytic_ik()  # derives the equations once (seconds); not timed
    except Exception as error:  # noqa: BLE001 - the reason is reported, the FK rows still run
        anchor.notes.append(f"analytic_ik unavailable: {error}")
        return anchor
    anchor.ik_single = lambda T: np.asarray(solver.solve(T, joint_limits=False).q, dtype=float).reshape(-1, robot.dof)
    anchor.notes.append("analytic_ik().solve(T, joint_limits=False)")
    return anchor


BUILDERS = {"EAIK": eaik, "ik-geo": ik_geo, "roboticstoolbox": roboticstoolbox}
