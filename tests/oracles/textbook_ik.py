"""Inverse kinematics written out from the textbook, formula by formula, every branch.

This module is a test oracle, independent of the service: it uses neither the
service's solver nor any DH product, only the closed-form IK formulas of
``shared/textbook.md``, with the errata of its section 10 CORRECTED:

* §3.2–§3.3 (eqs. 4.29–4.31, 4.50–4.51): ``zc − d1`` in place of ``zc``;
* §2.6 (eq. 4.62): ``d3 = −oz − d4``, not ``oz + d4``;
* §3.4 (eq. 4.33): valid only for the reconstructed frames; the Table 3.4
  frames use ``θ2 = atan2(±r, s)``;
* §5.1–§5.4: atan2 with explicit branches in place of the one-argument
  arctan, q3 ≥ 0, and ``(pz − l1)²`` in §5.4;
* §0: every ``A tan(x, y)`` of the source is ``atan2(y, x)`` here.

Every solver returns a list of :class:`TextbookBranch`, one per branch the
textbook writes down (and, where the textbook mentions it, the branch a
retracting slide would add, flagged ``negative_slide``). Joint vectors are in
the order and units of the matching ``robots/<id>.yaml`` (radians, the robot's
length unit).

Branch names are the textbook's, mapped to the service's label vocabulary:

* ``shoulder``: the textbook's "front" (θ1 = atan2(yc, xc): the wrist centre
  lies along x1) and "left arm" (§3.3: θ1 = φ − α, reach u = +u0 along x1)
  are ``left``; "back" and "right arm" are ``right``. §5.2 (a), §5.3 and
  §5.4 (a) use the same formula θ1 = atan2(y, x) with the point along x1, so
  they are front too.
* ``elbow``: §3.2 front: θ3 < 0 is up; back: θ3 > 0 is up. §3.3 left arm:
  θ3 < 0 is up; right arm: θ3 > 0 is up. For the PUMA (§6), whose joint zero
  differs, the textbook's geometric definition is applied: the elbow is up
  when it lies above the line from the shoulder to the wrist centre, in the
  arm's plane.
* ``wrist``: the ZYZ ``+`` root (s5 > 0) is ``no_flip``; the flip is
  (θ4 + π, −θ5, θ6 + π).
* ``assembly_mode`` (file 001, §4.2–§4.3): mode 1 is φ = θ + β, which gives
  the paper's θ2 > 0, i.e. the catalogue's DH variable q2 = −θ2_paper < 0.

Where the textbook does not name a branch (§2.1, §2.2, §2.4's arm, §2.6,
§5.1), the label dict has no entry for it, except the two analogies stated in
the functions' docstrings (§2.1 elbow, §2.6 assembly mode).

Example (Spong Example 4.1, the Stanford arm):

>>> H = np.array([[0, 1, 0, -0.154], [0, 0, 1, 0.763], [1, 0, 0, 0], [0, 0, 0, 1.0]])
>>> [(b.labels, b.singular) for b in stanford(H, d2=0.154, d6=0.263)]  # doctest: +NORMALIZE_WHITESPACE
[({'shoulder': 'left'}, ('wrist',)), ({'shoulder': 'right', 'wrist': 'no_flip'}, ()),
 ({'shoulder': 'right', 'wrist': 'flip'}, ())]
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Callable

import numpy as np

__all__ = [
    "TEXTBOOK_IK",
    "TextbookBranch",
    "assur_scara",
    "cylindrical_rpp",
    "cylindrical_with_wrist",
    "elbow_offset_with_wrist",
    "elbow_with_wrist",
    "ex004_1_prp",
    "ex004_2_polar_rrp",
    "ex004_3_spherical_rrpr",
    "ex004_4_polar_offset_rrp",
    "planar_rr",
    "puma560_craig",
    "scara_rrpr",
    "spherical_arm_eq4_33",
    "spherical_arm_table3_4",
    "spherical_wrist",
    "stanford",
    "zyz",
]

#: Below this, a quantity the textbook divides by or takes atan2 of is treated as zero (singular case).
SINGULAR = 1e-9


@dataclass(frozen=True)
class TextbookBranch:
    """One branch of a textbook IK: the joint vector and the textbook's name for it.

    ``joints`` shape (n,); ``labels`` maps the service's label names (shoulder,
    elbow, wrist, assembly_mode) to the textbook's branch, for the labels the
    textbook defines; ``name`` is the textbook's own wording; ``negative_slide``
    marks a branch that needs a prismatic joint below zero (the textbook
    mentions but discards it); ``singular`` names a singular case met, e.g.
    ``"wrist"`` when s5 = 0 and only θ4 ± θ6 is determined (θ4 = 0 is chosen
    then, as the textbook's scripts do).
    """

    joints: np.ndarray
    labels: dict = field(default_factory=dict)
    name: str = ""
    negative_slide: bool = False
    singular: tuple[str, ...] = ()


def _pose(target) -> tuple[np.ndarray, np.ndarray]:
    T = np.asarray(target, dtype=float)
    return T[:3, :3], T[:3, 3]


# --------------------------------------------------------------------------
# §1.4: ZYZ Euler angles, the spherical wrist's inverse
# --------------------------------------------------------------------------


def zyz(R) -> list[tuple[np.ndarray, dict, tuple[str, ...]]]:
    """Both ZYZ solutions of textbook.md §1.4 for a rotation R (3, 3).

    Returns ``[(angles, labels, singular), …]`` with angles = (φ, θ, ψ):
    the ``+`` root (s_θ > 0, ``no_flip``) then the ``−`` root (``flip``). In the
    singular case r13 = r23 = 0 there is one family; φ = 0 represents it (as in
    the textbook's scripts) and only φ + ψ (r33 = 1) or φ − ψ (r33 = −1) is
    determined.

    >>> [np.round(a, 6).tolist() for a, _, _ in zyz(np.eye(3))]
    [[0.0, 0.0, 0.0]]
    """
    R = np.asarray(R, dtype=float)
    r13, r23, r33 = R[0, 2], R[1, 2], R[2, 2]
    if np.hypot(r13, r23) <= SINGULAR:
        if r33 > 0:
            return [(np.array([0.0, 0.0, np.arctan2(R[1, 0], R[0, 0])]), {}, ("wrist",))]
        # phi - psi = atan2(-r12, -r11), phi = 0
        return [(np.array([0.0, np.pi, -np.arctan2(-R[0, 1], -R[0, 0])]), {}, ("wrist",))]
    root = np.sqrt(max(0.0, 1.0 - r33 ** 2))
    plus = np.array([np.arctan2(r23, r13), np.arctan2(root, r33), np.arctan2(R[2, 1], -R[2, 0])])
    minus = np.array([np.arctan2(-r23, -r13), np.arctan2(-root, r33), np.arctan2(-R[2, 1], R[2, 0])])
    return [(plus, {"wrist": "no_flip"}, ()), (minus, {"wrist": "flip"}, ())]


def _with_wrist(arm: np.ndarray, R03: np.ndarray, R: np.ndarray, labels: dict, name: str,
                negative_slide: bool = False) -> list[TextbookBranch]:
    """Decoupling step 3 (§3.1): ZYZ of R^3_6 = (R^0_3)ᵀ R appended to the arm joints."""
    out = []
    for angles, wrist_labels, singular in zyz(R03.T @ R):
        out.append(TextbookBranch(np.concatenate([arm, angles]), {**labels, **wrist_labels},
                                  f"{name}, wrist {wrist_labels.get('wrist', 'singular')}", negative_slide,
                                  singular))
    return out


# --------------------------------------------------------------------------
# §2: Spong chapter 3 robots
# --------------------------------------------------------------------------


def planar_rr(position, *, a1: float, a2: float) -> list[TextbookBranch]:
    """§2.1, two-link planar arm: D = (x² + y² − a1² − a2²)/(2 a1 a2), θ2 = atan2(±√(1 − D²), D).

    θ1 = atan2(y, x) − atan2(a2 s2, a1 + a2 c2). §2.1 does not name the two
    branches; the arm is the plane of §3.2's elbow arm in its front
    configuration, whose rule (θ3 < 0 is elbow up) is applied here to θ2,
    with the plane's y axis drawn up.
    """
    x, y = float(position[0]), float(position[1])
    D = (x * x + y * y - a1 * a1 - a2 * a2) / (2 * a1 * a2)
    if abs(D) > 1:
        return []
    out = []
    for sign in (+1, -1):
        t2 = np.arctan2(sign * np.sqrt(1 - D * D), D)
        t1 = np.arctan2(y, x) - np.arctan2(a2 * np.sin(t2), a1 + a2 * np.cos(t2))
        out.append(TextbookBranch(np.array([t1, t2]), {"elbow": "up" if t2 < 0 else "down"},
                                  f"theta2 = atan2({'+' if sign > 0 else '-'}sqrt(1 - D^2), D)"))
    return out


def cylindrical_rpp(position, *, d1: float) -> list[TextbookBranch]:
    """§2.2, cylindrical R–P–P: θ1 = atan2(−x, y), d3 = +√(x² + y²), d2 = z − d1.

    The second branch θ1 = atan2(x, −y), d3 = −√(x² + y²) needs a slide that
    retracts through zero.
    """
    x, y, z = (float(v) for v in position[:3])
    r = np.hypot(x, y)
    return [
        TextbookBranch(np.array([np.arctan2(-x, y), z - d1, r]), {}, "d3 = +sqrt(x^2 + y^2)"),
        TextbookBranch(np.array([np.arctan2(x, -y), z - d1, -r]), {}, "d3 = -sqrt(x^2 + y^2)",
                       negative_slide=True),
    ]


def spherical_wrist(target, *, d6: float) -> list[TextbookBranch]:
    """§2.3, the spherical wrist alone: (θ4, θ5, θ6) are the ZYZ angles of the rotation block (§1.4)."""
    R, _ = _pose(target)
    return [TextbookBranch(angles, labels, f"ZYZ {labels.get('wrist', 'singular')}", False, singular)
            for angles, labels, singular in zyz(R)]


def cylindrical_with_wrist(target, *, d1: float, d6: float) -> list[TextbookBranch]:
    """§2.4, cylindrical robot with spherical wrist, by decoupling.

    o_c = o − d6 a; θ1 = atan2(−xc, yc), d3 = √(xc² + yc²), d2 = zc − d1;
    R^0_3 = [[c1, 0, −s1], [s1, 0, c1], [0, −1, 0]]; ZYZ of (R^0_3)ᵀ R. The
    arm's retracting branch of §2.2 (θ1 = atan2(xc, −yc), d3 < 0) is included,
    flagged.
    """
    R, o = _pose(target)
    xc, yc, zc = o - d6 * R[:, 2]
    r = np.hypot(xc, yc)
    out = []
    for t1, d3, negative in ((np.arctan2(-xc, yc), r, False), (np.arctan2(xc, -yc), -r, True)):
        c1, s1 = np.cos(t1), np.sin(t1)
        R03 = np.array([[c1, 0, -s1], [s1, 0, c1], [0, -1, 0]])
        out += _with_wrist(np.array([t1, zc - d1, d3]), R03, R, {}, f"d3 = {d3:+.6g}", negative)
    return out


def stanford(target, *, d2: float, d6: float) -> list[TextbookBranch]:
    """§2.5, Stanford arm, by decoupling (4 branches with d3 ≥ 0).

    ρ = ±√(xc² + yc² − d2²) (``+`` is the left arm, as in the shoulder-offset
    arm of §3.3), θ1 = atan2(yc, xc) − atan2(d2, ρ), θ2 = atan2(ρ, zc),
    d3 = √(ρ² + zc²); R^0_3 = Rot_z(θ1) Rot_y(θ2); ZYZ of (R^0_3)ᵀ R.
    """
    R, o = _pose(target)
    xc, yc, zc = o - d6 * R[:, 2]
    squared = xc * xc + yc * yc - d2 * d2
    if squared < 0:
        return []
    out = []
    for sign, shoulder in ((+1, "left"), (-1, "right")):
        rho = sign * np.sqrt(squared)
        t1 = np.arctan2(yc, xc) - np.arctan2(d2, rho)
        t2 = np.arctan2(rho, zc)
        d3 = np.hypot(rho, zc)
        c1, s1, c2, s2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
        R03 = np.array([[c1 * c2, -s1, c1 * s2], [s1 * c2, c1, s1 * s2], [-s2, 0, c2]])
        out += _with_wrist(np.array([t1, t2, d3]), R03, R, {"shoulder": shoulder}, f"{shoulder} arm")
    return out


def scara_rrpr(target, *, a1: float, a2: float, d4: float) -> list[TextbookBranch]:
    """§2.6 / Example 4.4, SCARA, with erratum 3 fixed (d3 = −oz − d4).

    Only a rotation of the form of eq. 4.56, [[cα, sα, 0], [sα, −cα, 0], [0, 0, −1]],
    is reachable (returns [] otherwise). α = atan2(r12, r11);
    c2 = (ox² + oy² − a1² − a2²)/(2 a1 a2); θ2 = atan2(±√(1 − c2²), c2);
    θ1 = atan2(oy, ox) − atan2(a2 s2, a1 + a2 c2); θ4 = θ1 + θ2 − α.

    §2.6 does not name the branches. It is the same structure as the Assur
    SCARA of §4 (both DH tables have α2 = 180° and θ2 about the upward axis),
    so §4.3's rule is applied: assembly mode 1 ⇔ q2_DH < 0.
    """
    R, o = _pose(target)
    alpha = np.arctan2(R[0, 1], R[0, 0])
    expected = np.array([[np.cos(alpha), np.sin(alpha), 0], [np.sin(alpha), -np.cos(alpha), 0], [0, 0, -1]])
    if np.abs(R - expected).max() > 1e-9:
        return []
    c2 = (o[0] ** 2 + o[1] ** 2 - a1 * a1 - a2 * a2) / (2 * a1 * a2)
    if abs(c2) > 1:
        return []
    out = []
    for sign in (+1, -1):
        t2 = np.arctan2(sign * np.sqrt(1 - c2 * c2), c2)
        t1 = np.arctan2(o[1], o[0]) - np.arctan2(a2 * np.sin(t2), a1 + a2 * np.cos(t2))
        out.append(TextbookBranch(np.array([t1, t2, -o[2] - d4, t1 + t2 - alpha]),
                                  {"assembly_mode": 1 if t2 < 0 else 2}, f"theta2 sign {sign:+d}"))
    return out


# --------------------------------------------------------------------------
# §3: Spong chapter 4, elbow and spherical arms
# --------------------------------------------------------------------------


def _elbow_wrist(t1: float, t23: float, R: np.ndarray) -> list[tuple[np.ndarray, str]]:
    """§3.2 eqs. 4.39–4.44 / 4.52–4.54: (θ4, θ5, θ6) for both roots, with the wrist label.

    c5 = s1 r13 − c1 r23; θ4 = atan2(−c1 s23 r13 − s1 s23 r23 + c23 r33, c1 c23 r13 + s1 c23 r23 + s23 r33);
    θ6 = atan2(s1 r12 − c1 r22, −s1 r11 + c1 r21); the − root negates both arguments of both.
    At s5 = 0 the §1.4 singular case on R^3_6 is used, with θ4 = 0.
    """
    c1, s1, c23, s23 = np.cos(t1), np.sin(t1), np.cos(t23), np.sin(t23)
    c5 = s1 * R[0, 2] - c1 * R[1, 2]
    y4 = -c1 * s23 * R[0, 2] - s1 * s23 * R[1, 2] + c23 * R[2, 2]
    x4 = c1 * c23 * R[0, 2] + s1 * c23 * R[1, 2] + s23 * R[2, 2]
    y6 = s1 * R[0, 1] - c1 * R[1, 1]
    x6 = -s1 * R[0, 0] + c1 * R[1, 0]
    if np.hypot(x4, y4) <= SINGULAR:
        R03 = np.array([[c1 * c23, -c1 * s23, s1], [s1 * c23, -s1 * s23, -c1], [s23, c23, 0]])
        return [(angles, "singular") for angles, _, _ in zyz(R03.T @ R)]
    root = np.sqrt(max(0.0, 1 - c5 * c5))
    return [(np.array([np.arctan2(y4, x4), np.arctan2(root, c5), np.arctan2(y6, x6)]), "no_flip"),
            (np.array([np.arctan2(-y4, -x4), np.arctan2(-root, c5), np.arctan2(-y6, -x6)]), "flip")]


def _elbow_arm(xc, yc, zc, *, d1, a2, a3, d, shoulders) -> list[TextbookBranch]:
    """Arm joints of §3.2/§3.3 for the given shoulder choices [(θ1, u, shoulder label, θ3 sign that is up)]."""
    D = (xc * xc + yc * yc - d * d + (zc - d1) ** 2 - a2 * a2 - a3 * a3) / (2 * a2 * a3)
    if abs(D) > 1:
        return []
    out = []
    for t1, u, shoulder, up_sign in shoulders:
        for sign in (+1, -1):
            t3 = np.arctan2(sign * np.sqrt(1 - D * D), D)
            t2 = np.arctan2(zc - d1, u) - np.arctan2(a3 * np.sin(t3), a2 + a3 * np.cos(t3))
            elbow = "up" if np.sign(t3) == up_sign else "down"
            out.append(TextbookBranch(np.array([t1, t2, t3]), {"shoulder": shoulder, "elbow": elbow},
                                      f"{shoulder}, elbow {elbow}"))
    return out


def elbow_with_wrist(target, *, d1: float, a2: float, a3: float, d6: float) -> list[TextbookBranch]:
    """§3.2, Examples 4.2–4.3, with the d1 correction (erratum 4): 8 branches.

    Front: θ1 = atan2(yc, xc), u = +√(xc² + yc²); back: θ1 + π, u = −√(…).
    D = (xc² + yc² + (zc − d1)² − a2² − a3²)/(2 a2 a3), θ3 = atan2(±√(1 − D²), D),
    θ2 = atan2(zc − d1, u) − atan2(a3 s3, a2 + a3 c3). Front: θ3 < 0 is up; back: θ3 > 0 is up.
    """
    R, o = _pose(target)
    xc, yc, zc = o - d6 * R[:, 2]
    phi, r = np.arctan2(yc, xc), np.hypot(xc, yc)
    arms = _elbow_arm(xc, yc, zc, d1=d1, a2=a2, a3=a3, d=0.0,
                      shoulders=[(phi, r, "left", -1), (phi + np.pi, -r, "right", +1)])
    return _elbow_family(arms, R)


def elbow_offset_with_wrist(target, *, d1: float, a2: float, a3: float, d: float,
                            d6: float) -> list[TextbookBranch]:
    """§3.3, elbow arm with shoulder offset d (DH d2 = −d): 8 branches.

    u0 = √(xc² + yc² − d²), φ = atan2(yc, xc), α = atan2(d, u0). Left arm:
    θ1 = φ − α, u = +u0; right arm: θ1 = φ + atan2(−d, −u0), u = −u0.
    D = (xc² + yc² − d² + (zc − d1)² − a2² − a3²)/(2 a2 a3). Left: θ3 < 0 is up; right: θ3 > 0 is up.
    """
    R, o = _pose(target)
    xc, yc, zc = o - d6 * R[:, 2]
    squared = xc * xc + yc * yc - d * d
    if squared < 0:
        return []
    u0, phi = np.sqrt(squared), np.arctan2(yc, xc)
    arms = _elbow_arm(xc, yc, zc, d1=d1, a2=a2, a3=a3, d=d,
                      shoulders=[(phi - np.arctan2(d, u0), u0, "left", -1),
                                 (phi + np.arctan2(-d, -u0), -u0, "right", +1)])
    return _elbow_family(arms, R)


def _elbow_family(arms: list[TextbookBranch], R: np.ndarray) -> list[TextbookBranch]:
    out = []
    for arm in arms:
        t1, t2, t3 = arm.joints
        for wrist, label in _elbow_wrist(t1, t2 + t3, R):
            labels = dict(arm.labels)
            singular: tuple[str, ...] = ()
            if label == "singular":
                singular = ("wrist",)
            else:
                labels["wrist"] = label
            out.append(TextbookBranch(np.concatenate([arm.joints, wrist]), labels, f"{arm.name}, wrist {label}",
                                      False, singular))
    return out


def spherical_arm_eq4_33(position, *, d1: float) -> list[TextbookBranch]:
    """§3.4, spherical arm, reconstructed frames where eq. 4.33 holds.

    r = √(xc² + yc²), s = zc − d1, d3 = √(r² + s²); front: θ1 = atan2(yc, xc),
    θ2 = atan2(s, r) + π/2; back: θ1 = π + atan2(yc, xc), θ2 = atan2(s, −r) + π/2.
    """
    xc, yc, zc = (float(v) for v in position[:3])
    r, s = np.hypot(xc, yc), zc - d1
    d3 = np.hypot(r, s)
    phi = np.arctan2(yc, xc)
    return [TextbookBranch(np.array([phi, np.arctan2(s, r) + np.pi / 2, d3]), {"shoulder": "left"}, "front"),
            TextbookBranch(np.array([phi + np.pi, np.arctan2(s, -r) + np.pi / 2, d3]), {"shoulder": "right"},
                           "back")]


def spherical_arm_table3_4(position, *, d1: float) -> list[TextbookBranch]:
    """§3.4 "Caution": the Stanford Table 3.4 frames (d2 = 0, base height d1).

    o_c = (c1 s2 d3, s1 s2 d3, d1 + c2 d3): front θ1 = atan2(yc, xc),
    θ2 = atan2(r, s); back θ1 + π, θ2 = atan2(−r, s); d3 = √(r² + s²).
    """
    xc, yc, zc = (float(v) for v in position[:3])
    r, s = np.hypot(xc, yc), zc - d1
    d3 = np.hypot(r, s)
    phi = np.arctan2(yc, xc)
    return [TextbookBranch(np.array([phi, np.arctan2(r, s), d3]), {"shoulder": "left"}, "front"),
            TextbookBranch(np.array([phi + np.pi, np.arctan2(-r, s), d3]), {"shoulder": "right"}, "back")]


# --------------------------------------------------------------------------
# §4: file 001, the Assur-group SCARA
# --------------------------------------------------------------------------


def assur_scara(position, *, l_OA: float, l_AB: float, l_BC: float) -> list[TextbookBranch]:
    """§4.2–§4.3, position of the Assur SCARA by the RRR group, both assembly modes.

    The group's known points are the robot's A (projected, the origin) and the
    target's projection C; θ = atan2(yC, xC), β = arccos(P/Q) with
    P = l_AB² + |AC|² − l_BC², Q = 2 l_AB |AC|. Mode 1: φ = θ + β; mode 2: θ − β.
    The elbow is B = l_AB (cos φ, sin φ); θ_BC = atan2 of B→C; the paper's
    θ2 = θ1 − θ_BC; l3 = l_OA − z_D. Joints are returned in the catalogue's
    convention (θ1, q2_DH = −θ2_paper, l3).
    """
    x, y, z = (float(v) for v in position[:3])
    ac = np.hypot(x, y)
    P, Q = l_AB ** 2 + ac ** 2 - l_BC ** 2, 2 * l_AB * ac
    if Q <= 0 or abs(P / Q) > 1:
        return []
    theta, beta = np.arctan2(y, x), np.arccos(P / Q)
    out = []
    for mode, phi in ((1, theta + beta), (2, theta - beta)):
        bx, by = l_AB * np.cos(phi), l_AB * np.sin(phi)
        theta_bc = np.arctan2(y - by, x - bx)
        theta2_paper = phi - theta_bc
        out.append(TextbookBranch(np.array([phi, -theta2_paper, l_OA - z]), {"assembly_mode": mode},
                                  f"assembly mode {mode}"))
    return out


# --------------------------------------------------------------------------
# §5: file 004 exercises (position only)
# --------------------------------------------------------------------------


def ex004_1_prp(position) -> list[TextbookBranch]:
    """§5.1: q1 = z, q2 = atan2(−x, y), q3 = √(x² + y²); retracting: q2 = atan2(x, −y), q3 = −√(…)."""
    x, y, z = (float(v) for v in position[:3])
    r = np.hypot(x, y)
    return [TextbookBranch(np.array([z, np.arctan2(-x, y), r]), {}, "q3 = +sqrt"),
            TextbookBranch(np.array([z, np.arctan2(x, -y), -r]), {}, "q3 = -sqrt", negative_slide=True)]


def ex004_2_polar_rrp(position, *, l1: float) -> list[TextbookBranch]:
    """§5.2 correct branches: ρ = √(px² + py²), h = pz − l1, q3 = √(ρ² + h²).

    (a) q1 = atan2(py, px), q2 = atan2(−ρ, h); (b) q1 + π, q2 = atan2(ρ, h).
    """
    x, y, z = (float(v) for v in position[:3])
    rho, h = np.hypot(x, y), z - l1
    q3 = np.hypot(rho, h)
    q1 = np.arctan2(y, x)
    return [TextbookBranch(np.array([q1, np.arctan2(-rho, h), q3]), {"shoulder": "left"}, "(a)"),
            TextbookBranch(np.array([q1 + np.pi, np.arctan2(rho, h), q3]), {"shoulder": "right"}, "(b)")]


def ex004_3_spherical_rrpr(target) -> list[TextbookBranch]:
    """§5.3 (4 DOF, pose): q1 = atan2(y, x), q2 = atan2(ρ, z), or q1 + π, q2 = atan2(−ρ, z);

    q3 = √(x² + y² + z²); q4 = atan2(r32/s2, −r31/s2) (the derived extra).
    """
    R, (x, y, z) = _pose(target)
    rho = np.hypot(x, y)
    q3 = np.sqrt(x * x + y * y + z * z)
    out = []
    for q1, q2, shoulder in ((np.arctan2(y, x), np.arctan2(rho, z), "left"),
                             (np.arctan2(y, x) + np.pi, np.arctan2(-rho, z), "right")):
        s2 = np.sin(q2)
        q4 = np.arctan2(R[2, 1] / s2, -R[2, 0] / s2)
        out.append(TextbookBranch(np.array([q1, q2, q3, q4]), {"shoulder": shoulder}, shoulder))
    return out


def ex004_4_polar_offset_rrp(position, *, l1: float, l2: float) -> list[TextbookBranch]:
    """§5.4 correct branches: q3 = +√(ρ² + h² − l2²) (erratum 13 fixed).

    (a) q1 = atan2(py, px), ρs = +ρ; (b) q1 + π, ρs = −ρ;
    q2 = atan2(h l2 − q3 ρs, h q3 + l2 ρs).
    """
    x, y, z = (float(v) for v in position[:3])
    rho, h = np.hypot(x, y), z - l1
    squared = rho * rho + h * h - l2 * l2
    if squared < 0:
        return []
    q3 = np.sqrt(squared)
    out = []
    for q1, rho_s, shoulder, name in ((np.arctan2(y, x), rho, "left", "(a)"),
                                      (np.arctan2(y, x) + np.pi, -rho, "right", "(b)")):
        q2 = np.arctan2(h * l2 - q3 * rho_s, h * q3 + l2 * rho_s)
        out.append(TextbookBranch(np.array([q1, q2, q3]), {"shoulder": shoulder}, name))
    return out


# --------------------------------------------------------------------------
# §6: PUMA 560, Craig's IK
# --------------------------------------------------------------------------


def puma560_craig(target, *, a2: float, a3: float, d3: float, d4: float) -> list[TextbookBranch]:
    """§6, Craig's PUMA 560 IK, 8 branches (textbook.md §6 steps 1–4).

    θ1 = atan2(py, px) − atan2(d3, ±√(px² + py² − d3²)) (``+`` is the left
    arm, as in §3.3: the reach c1 px + s1 py is then positive);
    K = (px² + py² + pz² − a2² − a3² − d3² − d4²)/(2 a2),
    θ3 = atan2(a3, d4) − atan2(K, ±√(a3² + d4² − K²)); θ23 and the wrist as
    printed; flip = (θ4 + π, −θ5, θ6 + π). Elbow labels by the geometric
    definition of §3.2 (elbow above the shoulder–wrist line, in the arm plane);
    wrist labels by the sign of s5.
    """
    R, (px, py, pz) = _pose(target)
    (r11, r12, r13), (r21, r22, r23), (r31, r32, r33) = R
    squared = px * px + py * py - d3 * d3
    K = (px * px + py * py + pz * pz - a2 * a2 - a3 * a3 - d3 * d3 - d4 * d4) / (2 * a2)
    elbow_squared = a3 * a3 + d4 * d4 - K * K
    if squared < 0 or elbow_squared < 0:
        return []
    out = []
    for shoulder_sign, shoulder in ((+1, "left"), (-1, "right")):
        t1 = np.arctan2(py, px) - np.arctan2(d3, shoulder_sign * np.sqrt(squared))
        c1, s1 = np.cos(t1), np.sin(t1)
        for elbow_sign in (+1, -1):
            t3 = np.arctan2(a3, d4) - np.arctan2(K, elbow_sign * np.sqrt(elbow_squared))
            c3, s3 = np.cos(t3), np.sin(t3)
            reach = c1 * px + s1 * py
            t23 = np.arctan2((-a3 - a2 * c3) * pz - reach * (d4 - a2 * s3),
                             (a2 * s3 - d4) * pz + (a3 + a2 * c3) * reach)
            t2 = t23 - t3
            c2, s2, c23, s23 = np.cos(t2), np.sin(t2), np.cos(t23), np.sin(t23)
            # elbow above the shoulder–wrist line, in the arm plane (u along (c1, s1), v = z)
            elbow_u, elbow_v = a2 * c2, -a2 * s2
            wrist_u, wrist_v = a2 * c2 + a3 * c23 - d4 * s23, pz
            above = np.sign(wrist_u) * (elbow_v * wrist_u - elbow_u * wrist_v)
            elbow = "up" if above > 0 else "down"
            y4 = -r13 * s1 + r23 * c1
            x4 = -r13 * c1 * c23 - r23 * s1 * c23 + r33 * s23
            singular: tuple[str, ...] = ()
            t4 = np.arctan2(y4, x4)
            if np.hypot(x4, y4) <= SINGULAR:
                t4, singular = 0.0, ("wrist",)
            c4, s4 = np.cos(t4), np.sin(t4)
            s5 = -(r13 * (c1 * c23 * c4 + s1 * s4) + r23 * (s1 * c23 * c4 - c1 * s4) - r33 * s23 * c4)
            c5 = -r13 * c1 * s23 - r23 * s1 * s23 - r33 * c23
            t5 = np.arctan2(s5, c5)
            c5, s5 = np.cos(t5), np.sin(t5)
            s6 = -r11 * (c1 * c23 * s4 - s1 * c4) - r21 * (s1 * c23 * s4 + c1 * c4) + r31 * s23 * s4
            c6 = (r11 * ((c1 * c23 * c4 + s1 * s4) * c5 - c1 * s23 * s5)
                  + r21 * ((s1 * c23 * c4 - c1 * s4) * c5 - s1 * s23 * s5)
                  - r31 * (s23 * c4 * c5 + c23 * s5))
            t6 = np.arctan2(s6, c6)
            arm = np.array([t1, t2, t3])
            first = np.concatenate([arm, [t4, t5, t6]])
            branches = [first] if singular else [first, np.concatenate([arm, [t4 + np.pi, -t5, t6 + np.pi]])]
            for q in branches:
                labels = {"shoulder": shoulder, "elbow": elbow}
                if not singular:
                    labels["wrist"] = "no_flip" if np.sin(q[4]) > 0 else "flip"
                out.append(TextbookBranch(q, labels, f"{shoulder}, elbow {elbow}", False, singular))
    return out


# --------------------------------------------------------------------------
# Bindings to the catalogue
# --------------------------------------------------------------------------

#: robot id -> (target kind, oracle bound to the §8 lengths of the robot file).
#: "pose" oracles take a (4, 4) target, "position" oracles a (3,) position.
TEXTBOOK_IK: dict[str, tuple[str, Callable[..., list[TextbookBranch]]]] = {
    "spong_ex3_1_planar_rr": ("position", partial(planar_rr, a1=1.0, a2=0.5)),
    "spong_ex3_2_cylindrical_rpp": ("position", partial(cylindrical_rpp, d1=1.0)),
    "spong_ex3_3_spherical_wrist_rrr": ("pose", partial(spherical_wrist, d6=0.2)),
    "spong_ex3_4_cylindrical_with_wrist": ("pose", partial(cylindrical_with_wrist, d1=1.0, d6=0.2)),
    "spong_ex3_5_stanford": ("pose", partial(stanford, d2=0.154, d6=0.263)),
    "spong_ex3_6_scara_rrpr": ("pose", partial(scara_rrpr, a1=1.0, a2=0.8, d4=0.2)),
    "spong_ex4_3_elbow_with_wrist": ("pose", partial(elbow_with_wrist, d1=0.5, a2=1.0, a3=0.8, d6=0.2)),
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": (
        "pose", partial(elbow_offset_with_wrist, d1=0.5, a2=1.0, a3=0.8, d=0.2, d6=0.2)),
    "spong_sec4_3_spherical_arm_rrp": ("position", partial(spherical_arm_eq4_33, d1=0.5)),
    "spong_sec4_3_spherical_arm_table3_4_frames": ("position", partial(spherical_arm_table3_4, d1=0.5)),
    "assur001_scara_rrp": ("position", partial(assur_scara, l_OA=150.0, l_AB=80.0, l_BC=50.0)),
    "ex004_1_prp": ("position", ex004_1_prp),
    "ex004_2_polar_rrp": ("position", partial(ex004_2_polar_rrp, l1=1.0)),
    "ex004_3_spherical_rrpr": ("pose", ex004_3_spherical_rrpr),
    "ex004_4_polar_offset_rrp": ("position", partial(ex004_4_polar_offset_rrp, l1=1.0, l2=0.3)),
    "puma560_modified": ("pose", partial(puma560_craig, a2=0.4318, a3=0.0203, d3=0.15005, d4=0.4318)),
    "puma560_khalil": ("pose", partial(puma560_craig, a2=0.4318, a3=0.0203, d3=0.15005, d4=0.4318)),
}
