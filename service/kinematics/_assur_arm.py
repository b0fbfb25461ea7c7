"""The paper's SCARA found in a robot: its Assur-group geometry, and the map between its joints and the paper's.

:func:`~._assur.assur_scara_inverse` works in the paper's frame and joint
convention (``textbook.md`` §4.1): the shoulder axis is the Z axis, A is on
it, θ1 is the angle of the arm A→B from +X, ``θ2 = θ1 − θ_BC`` (eq. 15: the
*negative* of the usual counter-clockwise elbow angle), and l3 is the downward
extension, ``z_D = l_OA − l3``. A robot description says the same arm in its
own frame and DH joint variables. This module reads the paper's geometry off
the robot's screw model (so it does not depend on the DH convention or on the
robot's name) and maps joint values, rates and accelerations both ways.

Which robots: three joints R, R, P in that order, with the two revolute axes
and the slide parallel to one direction, the axes apart (l_AB > 0) and the
tool point off the second axis (l_BC > 0). In the catalogue that is
``assur001_scara_rrp``.

The paper's frame, for a robot: the Z axis is the first joint's axis,
pointing up (its direction, or the opposite if that points down, as the IK's
branch labels see it); the origin is the point of that axis nearest the
world origin (moved down the axis if the tool point would be at or below it
at q = 0, since the paper needs l_OA > 0); X is the world X axis projected
on the plane normal to Z (the world Y axis if X is along Z). Then::

    l_AB  distance between the two revolute axes
    l_BC  distance from the second axis to the tool point
    l_OA  height of the tool point at q = 0 (so that l3 = 0 there)

and, with ``s_i = ±1`` the sign of joint i's direction along Z, ``c1`` the
paper's θ1 at q = 0 and ``c2`` its θ_BC − θ1 at q = 0::

    θ1 = s1 q1 + c1        θ2 = −(s2 q2 + c2)        l3 = −s3 q3

For the catalogue's ``assur001_scara_rrp`` (standard DH, ``textbook.md`` §4.1)
s1 = s2 = 1, s3 = −1 and c1 = c2 = 0, so ``q = (θ1, −θ2, l3)``: its second DH
joint is ``q2_DH = −θ2_paper``, as its file says. The same holds for Spong's
SCARA (Example 3.6): ``θ2_Spong = −θ2_paper``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._assur import AssurScaraSolution, assur_scara_inverse
from ._forward import radius_about, screw_model
from ._robot import Robot
from ._angles import wrap_angle
from ._tolerances import GEOMETRY_TOLERANCE, SINGULARITY_TOLERANCE

__all__ = ["AssurScara", "AssurScaraRates", "assur_scara_of"]


@dataclass(frozen=True)
class AssurScaraRates:
    """The group's answer for one assembly mode, per sample, in both joint conventions.

    ``joints``, ``velocities``, ``accelerations`` have shape (N, 3) and hold
    the robot's joint variables; ``paper`` is the group's own solution
    (θ1, θ2, l3 and their derivatives); ``case`` the group's
    :class:`~._assur.RRRCase` per sample. NaN where the group says the
    quantity does not exist.
    """

    joints: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    paper: AssurScaraSolution
    case: np.ndarray


@dataclass(frozen=True)
class AssurScara:
    """The paper's geometry of a robot and the affine map between joint conventions."""

    origin: np.ndarray  # (3,) the paper's O, world frame
    world_R_paper: np.ndarray  # (3, 3) columns X, Y, Z of the paper's frame
    l_OA: float
    l_AB: float
    l_BC: float
    signs: np.ndarray  # (3,) s1, s2, s3
    c1: float
    c2: float

    def to_paper_points(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 3) in the paper's frame."""
        return (np.asarray(points) - self.origin) @ self.world_R_paper

    def to_paper_vectors(self, vectors: np.ndarray) -> np.ndarray:
        """World vectors (velocities, accelerations) (..., 3) in the paper's frame."""
        return np.asarray(vectors) @ self.world_R_paper

    def paper_from_joints(self, q: np.ndarray, qd: np.ndarray | None = None, qdd: np.ndarray | None = None):
        """(θ1, θ2, l3) from the robot's joints (..., 3), and the same map for rates and accelerations."""
        s1, s2, s3 = self.signs
        q = np.asarray(q, dtype=float)
        position = np.stack([s1 * q[..., 0] + self.c1, -(s2 * q[..., 1] + self.c2), -s3 * q[..., 2]], axis=-1)
        linear = np.array([s1, -s2, -s3])
        return (position,
                None if qd is None else np.asarray(qd) * linear,
                None if qdd is None else np.asarray(qdd) * linear)

    def joints_from_paper(self, solution: AssurScaraSolution) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The robot's joints, rates and accelerations (..., 3) from the group's solution."""
        s1, s2, s3 = self.signs
        q = np.stack([s1 * (solution.theta1 - self.c1), -s2 * (solution.theta2 + self.c2), -s3 * solution.l3],
                     axis=-1)
        linear = np.array([s1, -s2, -s3])
        return q, solution.qd * linear, solution.qdd * linear

    def inverse(self, points: np.ndarray, velocities: np.ndarray, accelerations: np.ndarray,
                assembly_mode: int) -> AssurScaraRates:
        """The paper's §3 for tool points, velocities and accelerations (N, 3), world frame.

        Positions, velocities and accelerations of the joints all come from the
        RRR group (:func:`~._assur.assur_scara_inverse`), vectorised over N.
        """
        solution = assur_scara_inverse(self.to_paper_points(points), self.to_paper_vectors(velocities),
                                       self.to_paper_vectors(accelerations), self.l_OA, self.l_AB, self.l_BC,
                                       assembly_mode, tolerance=SINGULARITY_TOLERANCE)
        q, qd, qdd = self.joints_from_paper(solution)
        return AssurScaraRates(q, qd, qdd, solution, solution.case)


def _angle(v: np.ndarray) -> float:
    return float(np.arctan2(v[1], v[0]))


def assur_scara_of(robot: Robot) -> AssurScara | None:
    """The paper's geometry of ``robot``, or None when it is not an RRP SCARA of the paper's kind."""
    if robot.dof != 3 or list(robot.is_revolute) != [True, True, False]:
        return None
    model = screw_model(robot)
    tol = GEOMETRY_TOLERANCE * 10
    d1, d2, d3 = model.directions
    if radius_about(d1, d2) > tol or radius_about(d1, d3) > tol:
        return None
    z = -d1 if d1[2] < -1e-12 else d1
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    if np.linalg.norm(x) <= tol:
        x = np.array([0.0, 1.0, 0.0]) - z[1] * z
    x /= np.linalg.norm(x)
    world_R_paper = np.stack([x, np.cross(z, x), z], axis=1)
    origin = model.points[0] - (model.points[0] @ z) * z  # point of axis 1 nearest the world origin
    to_paper = lambda p: (p - origin) @ world_R_paper  # noqa: E731
    elbow = to_paper(model.points[1])[:2]
    tool = to_paper(model.home[:3, 3])
    scale = GEOMETRY_TOLERANCE * 10 * robot.characteristic_length
    l_AB = float(np.linalg.norm(elbow))
    l_BC = float(np.linalg.norm(tool[:2] - elbow))
    if l_AB <= scale or l_BC <= scale:
        return None
    if tool[2] <= scale:  # the paper needs l_OA > 0: move the origin down the axis (heights are offsets)
        origin = origin - (robot.characteristic_length - tool[2]) * z
        tool = to_paper(model.home[:3, 3])
    signs = np.array([np.sign(d @ z) for d in (d1, d2, d3)])
    c1 = _angle(elbow)
    c2 = _angle(tool[:2] - elbow) - c1
    c2 = wrap_angle(c2)
    return AssurScara(origin, world_R_paper, float(tool[2]), l_AB, l_BC, signs, c1, c2)
