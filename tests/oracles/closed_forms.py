"""Closed-form forward kinematics written out from the textbook, entry by entry.

This module is a test oracle. Every function returns ``base_T_tool``, the
homogeneous pose of the last link frame in the robot's base frame, shape
(4, 4), float64, built one matrix entry at a time from the formulas printed in
``shared/textbook.md``. None of them multiplies link transforms: they must stay
independent of any Denavit-Hartenberg code, the service's or the tests', so that
a product of link transforms can be checked against them.

Where the textbook lists errata (its section 10), the CORRECTED entries are used,
never the misprints:

* Example 3.4 (eq. 3.35): r12, r22 and r32 as corrected in textbook.md §2.4;
* Stanford arm (eq. 3.43): r11 with ``s1`` (not ``d2``) and r22 starting with
  ``+s1[...]`` (textbook.md §2.5);
* file 004, Exercise 3: entry (3,1) is ``-s2*c4`` (not ``-c1*s2``) (textbook.md §5.3).

Conventions shared by every function:

* ``q`` is the robot's joint vector in the order of its DH table, shape (n,):
  radians for revolute joints, the robot's length unit for prismatic joints.
  It is exactly the joint vector of the matching ``robots/<id>.yaml`` file (the
  DH variable, offsets included), except where a docstring says otherwise.
* Length parameters are keyword arguments named as in the textbook; they are in
  the robot's length unit (metres, or millimetres for the Assur SCARA).
* ``ci = cos(q_i)``, ``sij = sin(q_i + q_j)`` and so on, as in textbook.md §0.

``CLOSED_FORMS`` maps a catalogue robot id to a callable ``q -> (4, 4) ndarray``
bound to the concrete lengths of ``ORACLE_PARAMETERS`` (the values of
textbook.md §8, which the robot files also use).

Robots deliberately left out of ``CLOSED_FORMS``, because the textbook does not
print their closed form in full: ``puma560_standard`` (Corke/Paul standard-DH
PUMA 560) and ``ur5``. They are checked through other relations instead (the
PUMA frame alignment and zero-pose checks in ``tests/test_catalogue_data.py``).

Example (Spong Example 3.1 with a1 = 1, a2 = 0.5, at q = (0, 0)):

>>> T = spong_ex3_1_planar_rr([0.0, 0.0], a1=1.0, a2=0.5)
>>> T[:3, 3].tolist()
[1.5, 0.0, 0.0]
"""

from __future__ import annotations

from functools import partial
from typing import Callable

import numpy as np

__all__ = [
    "CLOSED_FORMS",
    "ORACLE_PARAMETERS",
    "assur001_scara_rrp",
    "assur001_scara_rrp_paper_joints",
    "ex004_1_prp",
    "ex004_2_polar_rrp",
    "ex004_3_spherical_rrpr",
    "ex004_4_polar_offset_rrp",
    "puma560_craig",
    "spong_ex3_1_planar_rr",
    "spong_ex3_2_cylindrical_rpp",
    "spong_ex3_3_spherical_wrist_rrr",
    "spong_ex3_4_cylindrical_with_wrist",
    "spong_ex3_5_stanford",
    "spong_ex3_6_scara_rrpr",
    "spong_ex4_3_elbow_with_wrist",
    "spong_sec4_3_elbow_shoulder_offset_with_wrist",
    "spong_sec4_3_spherical_arm_rrp",
    "spong_sec4_3_spherical_arm_table3_4_frames",
]


def _joints(q, n: int) -> np.ndarray:
    """Return ``q`` as a float64 array of shape (n,), or raise ValueError."""
    q = np.asarray(q, dtype=float)
    if q.shape != (n,):
        raise ValueError(f"expected a joint vector of shape ({n},), got {q.shape}")
    return q


def _pose(r11, r12, r13, px, r21, r22, r23, py, r31, r32, r33, pz) -> np.ndarray:
    """Assemble a (4, 4) homogeneous matrix from its twelve non-trivial entries."""
    return np.array(
        [
            [r11, r12, r13, px],
            [r21, r22, r23, py],
            [r31, r32, r33, pz],
            [0.0, 0.0, 0.0, 1.0],
        ],
        dtype=float,
    )


# --------------------------------------------------------------------------
# File 000: Spong & Vidyasagar, chapter 3 (textbook.md §2)
# --------------------------------------------------------------------------


def spong_ex3_1_planar_rr(q, *, a1: float, a2: float) -> np.ndarray:
    """Two-link planar arm, eq. 3.25 (textbook.md §2.1).

    q = (theta1, theta2) in rad. Returns T^0_2, shape (4, 4).
    """
    t1, t2 = _joints(q, 2)
    c1, s1 = np.cos(t1), np.sin(t1)
    c12, s12 = np.cos(t1 + t2), np.sin(t1 + t2)
    return _pose(
        c12, -s12, 0.0, a1 * c1 + a2 * c12,
        s12, c12, 0.0, a1 * s1 + a2 * s12,
        0.0, 0.0, 1.0, 0.0,
    )


def spong_ex3_2_cylindrical_rpp(q, *, d1: float) -> np.ndarray:
    """Cylindrical R-P-P robot, eq. 3.28 (textbook.md §2.2).

    q = (theta1 [rad], d2, d3 [length]). Returns T^0_3, shape (4, 4).
    """
    t1, d2, d3 = _joints(q, 3)
    c1, s1 = np.cos(t1), np.sin(t1)
    return _pose(
        c1, 0.0, -s1, -s1 * d3,
        s1, 0.0, c1, c1 * d3,
        0.0, -1.0, 0.0, d1 + d2,
    )


def spong_ex3_3_spherical_wrist_rrr(q, *, d6: float) -> np.ndarray:
    """Spherical wrist alone, eq. 3.32 as reconstructed (textbook.md §2.3).

    q = (theta4, theta5, theta6) in rad. Returns T^3_6, shape (4, 4).
    """
    t4, t5, t6 = _joints(q, 3)
    c4, s4 = np.cos(t4), np.sin(t4)
    c5, s5 = np.cos(t5), np.sin(t5)
    c6, s6 = np.cos(t6), np.sin(t6)
    return _pose(
        c4 * c5 * c6 - s4 * s6, -c4 * c5 * s6 - s4 * c6, c4 * s5, c4 * s5 * d6,
        s4 * c5 * c6 + c4 * s6, -s4 * c5 * s6 + c4 * c6, s4 * s5, s4 * s5 * d6,
        -s5 * c6, s5 * s6, c5, c5 * d6,
    )


def spong_ex3_4_cylindrical_with_wrist(q, *, d1: float, d6: float) -> np.ndarray:
    """Cylindrical robot with spherical wrist, eq. 3.35 CORRECTED (textbook.md §2.4).

    q = (theta1 [rad], d2, d3 [length], theta4, theta5, theta6 [rad]).
    Returns T^0_6, shape (4, 4). r12, r22 and r32 are the corrected entries.
    """
    t1, d2, d3, t4, t5, t6 = _joints(q, 6)
    c1, s1 = np.cos(t1), np.sin(t1)
    c4, s4 = np.cos(t4), np.sin(t4)
    c5, s5 = np.cos(t5), np.sin(t5)
    c6, s6 = np.cos(t6), np.sin(t6)
    r11 = c1 * c4 * c5 * c6 - c1 * s4 * s6 + s1 * s5 * c6
    r21 = s1 * c4 * c5 * c6 - s1 * s4 * s6 - c1 * s5 * c6
    r31 = -s4 * c5 * c6 - c4 * s6
    r12 = -c1 * c4 * c5 * s6 - c1 * s4 * c6 - s1 * s5 * s6
    r22 = -s1 * c4 * c5 * s6 - s1 * s4 * c6 + c1 * s5 * s6
    r32 = s4 * c5 * s6 - c4 * c6
    r13 = c1 * c4 * s5 - s1 * c5
    r23 = s1 * c4 * s5 + c1 * c5
    r33 = -s4 * s5
    dx = c1 * c4 * s5 * d6 - s1 * c5 * d6 - s1 * d3
    dy = s1 * c4 * s5 * d6 + c1 * c5 * d6 + c1 * d3
    dz = -s4 * s5 * d6 + d1 + d2
    return _pose(r11, r12, r13, dx, r21, r22, r23, dy, r31, r32, r33, dz)


def spong_ex3_5_stanford(q, *, d2: float, d6: float) -> np.ndarray:
    """Stanford manipulator, eq. 3.43 CORRECTED (textbook.md §2.5).

    q = (theta1, theta2 [rad], d3 [length], theta4, theta5, theta6 [rad]).
    Returns T^0_6, shape (4, 4). r11 uses s1 (the source misprints d2) and r22
    starts with +s1[...] (the source misprints the sign).
    """
    t1, t2, d3, t4, t5, t6 = _joints(q, 6)
    c1, s1 = np.cos(t1), np.sin(t1)
    c2, s2 = np.cos(t2), np.sin(t2)
    c4, s4 = np.cos(t4), np.sin(t4)
    c5, s5 = np.cos(t5), np.sin(t5)
    c6, s6 = np.cos(t6), np.sin(t6)
    r11 = c1 * (c2 * (c4 * c5 * c6 - s4 * s6) - s2 * s5 * c6) - s1 * (s4 * c5 * c6 + c4 * s6)
    r21 = s1 * (c2 * (c4 * c5 * c6 - s4 * s6) - s2 * s5 * c6) + c1 * (s4 * c5 * c6 + c4 * s6)
    r31 = -s2 * (c4 * c5 * c6 - s4 * s6) - c2 * s5 * c6
    r12 = c1 * (-c2 * (c4 * c5 * s6 + s4 * c6) + s2 * s5 * s6) - s1 * (-s4 * c5 * s6 + c4 * c6)
    r22 = s1 * (-c2 * (c4 * c5 * s6 + s4 * c6) + s2 * s5 * s6) + c1 * (-s4 * c5 * s6 + c4 * c6)
    r32 = s2 * (c4 * c5 * s6 + s4 * c6) + c2 * s5 * s6
    r13 = c1 * (c2 * c4 * s5 + s2 * c5) - s1 * s4 * s5
    r23 = s1 * (c2 * c4 * s5 + s2 * c5) + c1 * s4 * s5
    r33 = -s2 * c4 * s5 + c2 * c5
    dx = c1 * s2 * d3 - s1 * d2 + d6 * (c1 * c2 * c4 * s5 + c1 * c5 * s2 - s1 * s4 * s5)
    dy = s1 * s2 * d3 + c1 * d2 + d6 * (c1 * s4 * s5 + c2 * c4 * s1 * s5 + c5 * s1 * s2)
    dz = c2 * d3 + d6 * (c2 * c5 - c4 * s2 * s5)
    return _pose(r11, r12, r13, dx, r21, r22, r23, dy, r31, r32, r33, dz)


def spong_ex3_6_scara_rrpr(q, *, a1: float, a2: float, d4: float) -> np.ndarray:
    """SCARA R-R-P-R, eq. 3.49 (textbook.md §2.6).

    q = (theta1, theta2 [rad], d3 [length], theta4 [rad]). Returns T^0_4, shape (4, 4).
    """
    t1, t2, d3, t4 = _joints(q, 4)
    c1, s1 = np.cos(t1), np.sin(t1)
    c12, s12 = np.cos(t1 + t2), np.sin(t1 + t2)
    c4, s4 = np.cos(t4), np.sin(t4)
    return _pose(
        c12 * c4 + s12 * s4, -c12 * s4 + s12 * c4, 0.0, a1 * c1 + a2 * c12,
        s12 * c4 - c12 * s4, -s12 * s4 - c12 * c4, 0.0, a1 * s1 + a2 * s12,
        0.0, 0.0, -1.0, -d3 - d4,
    )


# --------------------------------------------------------------------------
# File 000: Spong & Vidyasagar, chapter 4 (textbook.md §3)
# --------------------------------------------------------------------------


def _elbow_rotation_entries(t1, t2, t3, t4, t5, t6):
    """Rotation entries shared by the two elbow manipulators (textbook.md §3.2).

    Returns (r11, r12, r13, r21, r22, r23, r31, r32, r33), dimensionless.
    """
    c1, s1 = np.cos(t1), np.sin(t1)
    c5, s5 = np.cos(t5), np.sin(t5)
    c6, s6 = np.cos(t6), np.sin(t6)
    c234, s234 = np.cos(t2 + t3 + t4), np.sin(t2 + t3 + t4)
    r11 = c1 * (c234 * c5 * c6 - s234 * s6) - s1 * s5 * c6
    r21 = s1 * (c234 * c5 * c6 - s234 * s6) + c1 * s5 * c6
    r31 = s234 * c5 * c6 + c234 * s6
    r12 = -c1 * (c234 * c5 * s6 + s234 * c6) + s1 * s5 * s6
    r22 = -s1 * (c234 * c5 * s6 + s234 * c6) - c1 * s5 * s6
    r32 = -s234 * c5 * s6 + c234 * c6
    r13 = c1 * c234 * s5 + s1 * c5
    r23 = s1 * c234 * s5 - c1 * c5
    r33 = s234 * s5
    return r11, r12, r13, r21, r22, r23, r31, r32, r33


def spong_ex4_3_elbow_with_wrist(
    q, *, d1: float, a2: float, a3: float, d6: float
) -> np.ndarray:
    """Elbow manipulator with spherical wrist, entry list of textbook.md §3.2.

    q = (theta1, ..., theta6) in rad. Returns T^0_6, shape (4, 4).
    """
    t1, t2, t3, t4, t5, t6 = _joints(q, 6)
    r11, r12, r13, r21, r22, r23, r31, r32, r33 = _elbow_rotation_entries(t1, t2, t3, t4, t5, t6)
    c1, s1 = np.cos(t1), np.sin(t1)
    c2, s2 = np.cos(t2), np.sin(t2)
    c23, s23 = np.cos(t2 + t3), np.sin(t2 + t3)
    reach = a2 * c2 + a3 * c23
    ox = c1 * reach + d6 * r13
    oy = s1 * reach + d6 * r23
    oz = d1 + a2 * s2 + a3 * s23 + d6 * r33
    return _pose(r11, r12, r13, ox, r21, r22, r23, oy, r31, r32, r33, oz)


def spong_sec4_3_elbow_shoulder_offset_with_wrist(
    q, *, d1: float, a2: float, a3: float, d: float, d6: float
) -> np.ndarray:
    """Elbow manipulator with shoulder offset d (DH d2 = -d) and wrist (textbook.md §3.3).

    q = (theta1, ..., theta6) in rad. Returns T^0_6, shape (4, 4). The offset
    moves the wrist centre by +d along y0 when theta1 = 0 ("left" of the arm).
    """
    t1, t2, t3, t4, t5, t6 = _joints(q, 6)
    r11, r12, r13, r21, r22, r23, r31, r32, r33 = _elbow_rotation_entries(t1, t2, t3, t4, t5, t6)
    c1, s1 = np.cos(t1), np.sin(t1)
    c2, s2 = np.cos(t2), np.sin(t2)
    c23, s23 = np.cos(t2 + t3), np.sin(t2 + t3)
    reach = a2 * c2 + a3 * c23
    ox = c1 * reach - s1 * d + d6 * r13
    oy = s1 * reach + c1 * d + d6 * r23
    oz = d1 + a2 * s2 + a3 * s23 + d6 * r33
    return _pose(r11, r12, r13, ox, r21, r22, r23, oy, r31, r32, r33, oz)


def spong_sec4_3_spherical_arm_rrp(q, *, d1: float) -> np.ndarray:
    """Spherical arm R-R-P, reconstructed table of textbook.md §3.4 (eq. 4.33 frames).

    q = (theta1, theta2 [rad], d3 [length]). Returns T^0_3, shape (4, 4).
    theta2 = 0 points the arm straight down.
    """
    t1, t2, d3 = _joints(q, 3)
    c1, s1 = np.cos(t1), np.sin(t1)
    c2, s2 = np.cos(t2), np.sin(t2)
    return _pose(
        c1 * c2, s1, c1 * s2, c1 * s2 * d3,
        s1 * c2, -c1, s1 * s2, s1 * s2 * d3,
        s2, 0.0, -c2, d1 - c2 * d3,
    )


def spong_sec4_3_spherical_arm_table3_4_frames(q, *, d1: float) -> np.ndarray:
    """Spherical arm with the Stanford (Table 3.4) frames, d2 = 0, base height d1.

    q = (theta1, theta2 [rad], d3 [length]). Returns T^0_3, shape (4, 4).

    The textbook prints the two halves separately: the rotation is the Stanford
    arm's R^0_3 = Rot_z(theta1) Rot_y(theta2) (textbook.md §2.5, IK step 3) and
    the position is o_c = (c1 s2 d3, s1 s2 d3, d1 + c2 d3) (textbook.md §3.4,
    "Caution"). This function writes both out entry by entry.
    """
    t1, t2, d3 = _joints(q, 3)
    c1, s1 = np.cos(t1), np.sin(t1)
    c2, s2 = np.cos(t2), np.sin(t2)
    return _pose(
        c1 * c2, -s1, c1 * s2, c1 * s2 * d3,
        s1 * c2, c1, s1 * s2, s1 * s2 * d3,
        -s2, 0.0, c2, d1 + c2 * d3,
    )


# --------------------------------------------------------------------------
# File 001: Assur-group SCARA (textbook.md §4.1)
# --------------------------------------------------------------------------


def assur001_scara_rrp_paper_joints(
    theta1: float, theta2_paper: float, l3: float, *, l_OA: float, l_AB: float, l_BC: float
) -> np.ndarray:
    """Assur SCARA pose in the PAPER's joint convention (textbook.md §4.1).

    theta1, theta2_paper in rad, with theta2_paper = theta1 - theta_BC (eq. 15);
    l3 and the lengths in mm. Returns base_T_tool, shape (4, 4), tool z pointing down.
    """
    phi = theta1 - theta2_paper  # absolute angle of B->C
    c, s = np.cos(phi), np.sin(phi)
    x_d = l_AB * np.cos(theta1) + l_BC * c
    y_d = l_AB * np.sin(theta1) + l_BC * s
    z_d = l_OA - l3
    return _pose(
        c, s, 0.0, x_d,
        s, -c, 0.0, y_d,
        0.0, 0.0, -1.0, z_d,
    )


def assur001_scara_rrp(q, *, l_OA: float, l_AB: float, l_BC: float) -> np.ndarray:
    """Assur SCARA pose for the catalogue's DH joint vector.

    q = (theta1 [rad], q2_DH [rad], l3 [mm]) where q2_DH = -theta2_paper, the
    variable of the equivalent standard-DH table (textbook.md §4.1).
    Returns base_T_tool, shape (4, 4), in mm.
    """
    theta1, q2_dh, l3 = _joints(q, 3)
    return assur001_scara_rrp_paper_joints(
        theta1, -q2_dh, l3, l_OA=l_OA, l_AB=l_AB, l_BC=l_BC
    )


# --------------------------------------------------------------------------
# File 004: solved exercises (textbook.md §5)
# --------------------------------------------------------------------------


def ex004_1_prp(q) -> np.ndarray:
    """Exercise 1, P-R-P (textbook.md §5.1).

    q = (q1 [length], q2 [rad], q3 [length]). Returns T, shape (4, 4).
    """
    q1, q2, q3 = _joints(q, 3)
    c2, s2 = np.cos(q2), np.sin(q2)
    return _pose(
        c2, 0.0, -s2, -s2 * q3,
        s2, 0.0, c2, c2 * q3,
        0.0, -1.0, 0.0, q1,
    )


def ex004_2_polar_rrp(q, *, l1: float) -> np.ndarray:
    """Exercise 2, polar R-R-P with base height l1 (textbook.md §5.2).

    q = (q1, q2 [rad], q3 [length]). Returns T, shape (4, 4).
    """
    q1, q2, q3 = _joints(q, 3)
    c1, s1 = np.cos(q1), np.sin(q1)
    c2, s2 = np.cos(q2), np.sin(q2)
    return _pose(
        c1 * c2, -s1, -c1 * s2, -q3 * c1 * s2,
        s1 * c2, c1, -s1 * s2, -q3 * s1 * s2,
        s2, 0.0, c2, q3 * c2 + l1,
    )


def ex004_3_spherical_rrpr(q) -> np.ndarray:
    """Exercise 3, spherical R-R-P-R, CORRECTED entry (3,1) = -s2*c4 (textbook.md §5.3).

    q = (q1, q2 [rad], q3 [length], q4 [rad]). Returns T, shape (4, 4).
    """
    q1, q2, q3, q4 = _joints(q, 4)
    c1, s1 = np.cos(q1), np.sin(q1)
    c2, s2 = np.cos(q2), np.sin(q2)
    c4, s4 = np.cos(q4), np.sin(q4)
    return _pose(
        c1 * c2 * c4 - s1 * s4, -c1 * c2 * s4 - s1 * c4, c1 * s2, c1 * s2 * q3,
        s1 * c2 * c4 + c1 * s4, -s1 * c2 * s4 + c1 * c4, s1 * s2, s1 * s2 * q3,
        -s2 * c4, s2 * s4, c2, c2 * q3,
    )


def ex004_4_polar_offset_rrp(q, *, l1: float, l2: float) -> np.ndarray:
    """Exercise 4, polar R-R-P with base height l1 and offset l2 (textbook.md §5.4).

    q = (q1, q2 [rad], q3 [length]). Returns T, shape (4, 4).
    """
    q1, q2, q3 = _joints(q, 3)
    c1, s1 = np.cos(q1), np.sin(q1)
    c2, s2 = np.cos(q2), np.sin(q2)
    return _pose(
        c1 * c2, -s1, -c1 * s2, -c1 * s2 * q3 + c1 * c2 * l2,
        s1 * c2, c1, -s1 * s2, -s1 * s2 * q3 + s1 * c2 * l2,
        s2, 0.0, c2, c2 * q3 + s2 * l2 + l1,
    )


# --------------------------------------------------------------------------
# File 002 (supplementary): PUMA 560 in Craig's modified DH (textbook.md §6)
# --------------------------------------------------------------------------


def puma560_craig(q, *, a2: float, a3: float, d3: float, d4: float) -> np.ndarray:
    """PUMA 560, Craig's closed form (textbook.md §6).

    q = (theta1, ..., theta6) in rad, Craig's joint angles (the Khalil table of
    textbook.md §6 uses the same frames and angles). Returns ^0T_6, shape (4, 4).
    """
    t1, t2, t3, t4, t5, t6 = _joints(q, 6)
    c1, s1 = np.cos(t1), np.sin(t1)
    c2, s2 = np.cos(t2), np.sin(t2)
    c4, s4 = np.cos(t4), np.sin(t4)
    c5, s5 = np.cos(t5), np.sin(t5)
    c6, s6 = np.cos(t6), np.sin(t6)
    c23, s23 = np.cos(t2 + t3), np.sin(t2 + t3)
    r11 = c1 * (c23 * (c4 * c5 * c6 - s4 * s6) - s23 * s5 * c6) + s1 * (s4 * c5 * c6 + c4 * s6)
    r21 = s1 * (c23 * (c4 * c5 * c6 - s4 * s6) - s23 * s5 * c6) - c1 * (s4 * c5 * c6 + c4 * s6)
    r31 = -s23 * (c4 * c5 * c6 - s4 * s6) - c23 * s5 * c6
    r12 = c1 * (c23 * (-c4 * c5 * s6 - s4 * c6) + s23 * s5 * s6) + s1 * (c4 * c6 - s4 * c5 * s6)
    r22 = s1 * (c23 * (-c4 * c5 * s6 - s4 * c6) + s23 * s5 * s6) - c1 * (c4 * c6 - s4 * c5 * s6)
    r32 = -s23 * (-c4 * c5 * s6 - s4 * c6) + c23 * s5 * s6
    r13 = -c1 * (c23 * c4 * s5 + s23 * c5) - s1 * s4 * s5
    r23 = -s1 * (c23 * c4 * s5 + s23 * c5) + c1 * s4 * s5
    r33 = s23 * c4 * s5 - c23 * c5
    px = c1 * (a2 * c2 + a3 * c23 - d4 * s23) - d3 * s1
    py = s1 * (a2 * c2 + a3 * c23 - d4 * s23) + d3 * c1
    pz = -a3 * s23 - a2 * s2 - d4 * c23
    return _pose(r11, r12, r13, px, r21, r22, r23, py, r31, r32, r33, pz)


# --------------------------------------------------------------------------
# Bindings to the catalogue
# --------------------------------------------------------------------------

#: Concrete lengths of textbook.md §8 (metres; millimetres for the Assur SCARA).
#: The matching robots/<id>.yaml files state the same values under ``parameters``.
ORACLE_PARAMETERS: dict[str, dict[str, float]] = {
    "spong_ex3_1_planar_rr": {"a1": 1.0, "a2": 0.5},
    "spong_ex3_2_cylindrical_rpp": {"d1": 1.0},
    "spong_ex3_3_spherical_wrist_rrr": {"d6": 0.2},
    "spong_ex3_4_cylindrical_with_wrist": {"d1": 1.0, "d6": 0.2},
    "spong_ex3_5_stanford": {"d2": 0.154, "d6": 0.263},
    "spong_ex3_6_scara_rrpr": {"a1": 1.0, "a2": 0.8, "d4": 0.2},
    "spong_ex4_3_elbow_with_wrist": {"d1": 0.5, "a2": 1.0, "a3": 0.8, "d6": 0.2},
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": {
        "d1": 0.5, "a2": 1.0, "a3": 0.8, "d": 0.2, "d6": 0.2,
    },
    "spong_sec4_3_spherical_arm_rrp": {"d1": 0.5},
    "spong_sec4_3_spherical_arm_table3_4_frames": {"d1": 0.5},
    "ex004_1_prp": {},
    "ex004_2_polar_rrp": {"l1": 1.0},
    "ex004_3_spherical_rrpr": {},
    "ex004_4_polar_offset_rrp": {"l1": 1.0, "l2": 0.3},
    "assur001_scara_rrp": {"l_OA": 150.0, "l_AB": 80.0, "l_BC": 50.0},
    "puma560_modified": {"a2": 0.4318, "a3": 0.0203, "d3": 0.15005, "d4": 0.4318},
    "puma560_khalil": {"a2": 0.4318, "a3": 0.0203, "d3": 0.15005, "d4": 0.4318},
}

_FUNCTIONS: dict[str, Callable[..., np.ndarray]] = {
    "spong_ex3_1_planar_rr": spong_ex3_1_planar_rr,
    "spong_ex3_2_cylindrical_rpp": spong_ex3_2_cylindrical_rpp,
    "spong_ex3_3_spherical_wrist_rrr": spong_ex3_3_spherical_wrist_rrr,
    "spong_ex3_4_cylindrical_with_wrist": spong_ex3_4_cylindrical_with_wrist,
    "spong_ex3_5_stanford": spong_ex3_5_stanford,
    "spong_ex3_6_scara_rrpr": spong_ex3_6_scara_rrpr,
    "spong_ex4_3_elbow_with_wrist": spong_ex4_3_elbow_with_wrist,
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": spong_sec4_3_elbow_shoulder_offset_with_wrist,
    "spong_sec4_3_spherical_arm_rrp": spong_sec4_3_spherical_arm_rrp,
    "spong_sec4_3_spherical_arm_table3_4_frames": spong_sec4_3_spherical_arm_table3_4_frames,
    "ex004_1_prp": ex004_1_prp,
    "ex004_2_polar_rrp": ex004_2_polar_rrp,
    "ex004_3_spherical_rrpr": ex004_3_spherical_rrpr,
    "ex004_4_polar_offset_rrp": ex004_4_polar_offset_rrp,
    "assur001_scara_rrp": assur001_scara_rrp,
    # Khalil's frames are Craig's frames (textbook.md §1.3): one closed form serves both.
    "puma560_modified": puma560_craig,
    "puma560_khalil": puma560_craig,
}

#: robot id -> callable(q) returning base_T_tool, shape (4, 4), at the §8 lengths.
CLOSED_FORMS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    robot_id: partial(function, **ORACLE_PARAMETERS[robot_id])
    for robot_id, function in _FUNCTIONS.items()
}
