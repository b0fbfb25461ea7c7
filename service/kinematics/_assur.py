"""RRR Assur group and the SCARA inverse kinematics built on it.

Implements Noriega González, García Martínez and Muñiz Calvente (Univ. Oviedo),
*Resolución del problema cinemático inverso en un robot SCARA mediante grupos
de Assur* (file 001 of the course texts; digest in ``textbook.md`` §4).
Function names follow the paper so that a reader can map code to equations:

* :func:`angle_function`: the paper's Fig. 2, the angle of a plane vector and
  its first two time derivatives (in :mod:`._assur_functions`, re-exported).
* :func:`distance_function`: the paper's Fig. 3, the distance between two moving
  points and its first two time derivatives (likewise).
* :func:`rrr_group`: the paper's §2, eqs. 1-10, the RRR dyad (position,
  velocity, acceleration) with its singular cases classified per sample.
* :func:`assur_scara_inverse`: the paper's §3, eqs. 11-15, the SCARA's inverse
  kinematics for position, velocity and acceleration.
* :func:`assur_scara_forward`: the forward position map in the paper's joint
  convention, for round trips.

Three misprints of the paper are corrected here (``textbook.md`` §10, items
7-9):

7. Fig. 2: the numerator of θ'' contains ``(y''x - yx'')``, not ``(y'x - yx')``;
   in the ``x = 0`` branch the paper's ``y < 0`` formulas have the wrong sign and
   its θ'' lacks the factor 2. The general formula is used for every non-null
   vector: at ``x = 0`` it reduces to the correct ``θ' = -x'/y`` and
   ``θ'' = -x''/y + 2x'y'/y²`` for both signs of ``y``, so no branch is needed.
8. Eq. 4: ``P'' = 2(l'_AB² + l_AB·l''_AB)``; the paper prints ``2(l_AB² + ...)``.
9. §3: θ_BC is given by the angle function (Fig. 2, not Fig. 3) applied to the
   vector from the elbow B to the point C (not to A and B).

The paper calls the numerator and denominator of the cosine in eq. 1 ``A`` and
``B``; they are ``P`` and ``Q`` here, to avoid a clash with the point names.

Conventions
-----------
Angles are in radians, measured counter-clockwise from +X. Lengths are in the
caller's length unit (the paper uses mm) and time in seconds; a suffix ``d``
is a first time derivative and ``dd`` a second one (``xd`` is x', ``Cdd`` is
C''). Every input may carry leading batch dimensions, shape ``(..., 2)`` for
plane points (``(N, 2)`` for N samples) and ``(...,)`` for scalars; the inputs
are broadcast against each other and every output has the broadcast batch
shape. Nothing loops over samples in Python.

Singular cases are never raised: each sample carries its own classification
(:class:`RRRCase`) and the quantities that do not exist there are NaN.
Invalid input (wrong shape, non-finite values, non-positive lengths, unknown
assembly mode) raises :class:`~service.kinematics._errors.InvalidInputError`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from ._assur_functions import (
    AngleFunctionResult,
    DistanceFunctionResult,
    _check_assembly_mode,
    _check_finite_array,
    _check_length,
    _check_tolerance,
    angle_function,
    distance_function,
)
from ._angles import wrap_angle
from ._tolerances import SINGULARITY_TOLERANCE

__all__ = [
    "AngleFunctionResult",
    "AssurScaraSolution",
    "DistanceFunctionResult",
    "RRRCase",
    "RRRGroupSolution",
    "angle_function",
    "assur_scara_forward",
    "assur_scara_inverse",
    "distance_function",
    "rrr_group",
]


# --------------------------------------------------------------------------
# Paper §2: the RRR group
# --------------------------------------------------------------------------


class RRRCase(enum.IntEnum):
    """Per-sample classification of an RRR group (paper §2, ``textbook.md`` §4.2 item 6).

    REGULAR
        ``|P/Q| < 1``: C and its derivatives exist.
    ALIGNED
        ``P/Q = ±1`` within the tolerance: A, B and C are aligned (β = 0 or π).
        C exists, but β', β'' (and so φ', φ'', C', C'') do not: they are NaN.
        A singular configuration.
    COINCIDENT
        A ≡ B and ``l_AC = l_BC``: the group can be assembled, but C is
        undefined (singularity with increased mobility). Everything but the
        distance A-B is NaN.
    UNREACHABLE
        ``P/Q ∉ [-1, 1]`` beyond the tolerance (or A ≡ B with unequal lengths):
        the group cannot be assembled. Everything but the distance and angle
        A→B is NaN.
    """

    REGULAR = 0
    ALIGNED = 1
    COINCIDENT = 2
    UNREACHABLE = 3


class _CaseFlags:
    """Boolean views of a ``case`` array, shared by the solution records."""

    case: np.ndarray

    @property
    def regular(self) -> np.ndarray:
        """True where the sample is regular (everything defined)."""
        return self.case == RRRCase.REGULAR

    @property
    def aligned(self) -> np.ndarray:
        """True where A, B, C are aligned: position defined, derivatives NaN."""
        return self.case == RRRCase.ALIGNED

    @property
    def coincident(self) -> np.ndarray:
        """True where A ≡ B with equal lengths: C undefined (increased mobility)."""
        return self.case == RRRCase.COINCIDENT

    @property
    def unreachable(self) -> np.ndarray:
        """True where the group cannot be assembled."""
        return self.case == RRRCase.UNREACHABLE

    @property
    def singular(self) -> np.ndarray:
        """True where the group is assembled but singular (aligned or coincident)."""
        return self.aligned | self.coincident


@dataclass(frozen=True)
class RRRGroupSolution(_CaseFlags):
    """Solution of the RRR group for one assembly mode, per sample.

    All arrays share the broadcast batch shape ``(...)`` of the inputs; points
    have a trailing axis of 2. Angles are in rad, lengths in the caller's unit,
    ``d`` marks a first and ``dd`` a second time derivative.

    Attributes
    ----------
    C, Cd, Cdd : ndarray, shape (..., 2)
        The unknown joint C, its velocity and acceleration (eqs. 6-8).
    phi, phid, phidd : ndarray, shape (...)
        Angle φ of the link A→C from +X and its derivatives (eqs. 9-10).
        φ = θ ± β is not wrapped: it lies in (-π, 2π] for mode 1 and in
        (-2π, π] for mode 2.
    beta, betad, betadd : ndarray, shape (...)
        Angle β at A between A→B and A→C, in [0, π] (eqs. 1-3).
    theta, thetad, thetadd : ndarray, shape (...)
        Angle θ of the vector A→B from +X (angle function, Fig. 2).
    l_AB, l_ABd, l_ABdd : ndarray, shape (...)
        Distance A-B and its derivatives (distance function, Fig. 3).
    cos_beta : ndarray, shape (...)
        ``P/Q`` before clipping, the cosine of β; ``|P/Q| > 1`` means
        unreachable. NaN where A ≡ B.
    case : ndarray of int8, shape (...)
        :class:`RRRCase` value of each sample. The properties ``regular``,
        ``aligned``, ``coincident``, ``unreachable`` and ``singular`` give
        boolean masks.
    """

    C: np.ndarray
    Cd: np.ndarray
    Cdd: np.ndarray
    phi: np.ndarray
    phid: np.ndarray
    phidd: np.ndarray
    beta: np.ndarray
    betad: np.ndarray
    betadd: np.ndarray
    theta: np.ndarray
    thetad: np.ndarray
    thetadd: np.ndarray
    l_AB: np.ndarray
    l_ABd: np.ndarray
    l_ABdd: np.ndarray
    cos_beta: np.ndarray
    case: np.ndarray


def rrr_group(
    A,
    Ad,
    Add,
    B,
    Bd,
    Bdd,
    l_AC: float,
    l_BC: float,
    assembly_mode: int,
    *,
    tolerance: float = SINGULARITY_TOLERANCE,
) -> RRRGroupSolution:
    """Position, velocity and acceleration of the RRR group's middle joint C.

    The paper's §2 (``textbook.md`` §4.2), eqs. 1-10, with the misprint of
    eq. 4 corrected. The outer joints A and B are known; C is at ``l_AC``
    from A and ``l_BC`` from B. With θ the angle of A→B (Fig. 2) and l_AB the
    distance A-B (Fig. 3)::

        P = l_AC² + l_AB² - l_BC²      P'  = 2·l_AB·l'_AB
                                       P'' = 2(l'_AB² + l_AB·l''_AB)  (eq. 4, corrected)
        Q = 2·l_AC·l_AB                Q'  = 2·l_AC·l'_AB
                                       Q'' = 2·l_AC·l''_AB            (eq. 5)
        u = P/Q,  u' = (P'Q - PQ')/Q²,
        u'' = [(P''Q - PQ'')Q² - 2(P'Q - PQ')QQ'] / Q⁴
        β   = arccos(u)                                         (eq. 1)
        β'  = -u' / sqrt(1 - u²)                                (eq. 2)
        β'' = -[u·u'²/(1 - u²) + u''] / sqrt(1 - u²)            (eq. 3)
        φ = θ ± β,  φ' = θ' ± β',  φ'' = θ'' ± β''              (eqs. 9, 10)
        C   = A + l_AC(cos φ, sin φ)                            (eq. 6)
        C'  = A' + l_AC·φ'·(-sin φ, cos φ)                      (eq. 7)
        C'' = A'' + l_AC[-φ'²(cos φ, sin φ) + φ''(-sin φ, cos φ)]  (eq. 8)

    Classification (:class:`RRRCase`), with ``tol = tolerance`` and the
    characteristic length ``L = l_AC + l_BC``:

    * ``l_AB <= tol·L``: A ≡ B. COINCIDENT if ``|l_AC - l_BC| <= tol·L``,
      else UNREACHABLE.
    * otherwise UNREACHABLE if ``|u| > 1 + tol``, ALIGNED if
      ``||u| - 1| <= tol`` (u is clipped to ±1, β = 0 or π), REGULAR if
      ``|u| < 1 - tol``. Since ``1 - |u| ≈ β²/2`` near alignment, the default
      tolerance flags ``β`` (or ``π - β``) below about 4.5e-4 rad, where the
      derivatives would be amplified by more than about 2000.

    Parameters
    ----------
    A, B : array-like, shape (..., 2)
        Known joints [length]; ``(N, 2)`` for N samples, ``(2,)`` for one.
    Ad, Bd : array-like, shape (..., 2)
        Their velocities [length/s].
    Add, Bdd : array-like, shape (..., 2)
        Their accelerations [length/s²].
    l_AC, l_BC : float
        Link lengths A-C and B-C, positive [length].
    assembly_mode : {1, 2}
        1: φ = θ + β (C counter-clockwise from A→B); 2: φ = θ - β.
    tolerance : float, optional (default: SINGULARITY_TOLERANCE)
        Dimensionless tolerance of the classification above.

    Returns
    -------
    solution : RRRGroupSolution
        Arrays of the broadcast batch shape; quantities that do not exist for
        a sample's case are NaN.

    Raises
    ------
    InvalidInputError
        If a point is not of shape (..., 2) or not finite, a length is not
        positive, or the assembly mode is not 1 or 2.

    Examples
    --------
    A 3-4-5 triangle: A at the origin, B at (5, 0) moving up at 1 unit/s,
    l_AC = 3, l_BC = 4; mode 1 puts C above A→B.

    >>> s = rrr_group([0, 0], [0, 0], [0, 0], [5, 0], [0, 1], [0, 0], 3.0, 4.0, 1)
    >>> print(s.C.round(6), s.Cd.round(6), RRRCase(int(s.case)).name)
    [1.8 2.4] [-0.48  0.36] REGULAR
    >>> s = rrr_group([0, 0], [0, 0], [0, 0], [7, 0], [0, 1], [0, 0], 3.0, 4.0, 1)
    >>> print(s.C.round(6), s.Cd, RRRCase(int(s.case)).name)
    [3. 0.] [nan nan] ALIGNED
    """
    names = ("A", "Ad", "Add", "B", "Bd", "Bdd")
    A, Ad, Add, B, Bd, Bdd = np.broadcast_arrays(
        *(_check_finite_array(v, n, 2) for v, n in zip((A, Ad, Add, B, Bd, Bdd), names))
    )
    l_AC = _check_length(l_AC, "l_AC")
    l_BC = _check_length(l_BC, "l_BC")
    sign = 1.0 if _check_assembly_mode(assembly_mode) == 1 else -1.0
    tol = _check_tolerance(tolerance, "tolerance")
    length_tol = tol * (l_AC + l_BC)

    # Fig. 3 and Fig. 2 on A -> B.
    dist = distance_function(A, Ad, Add, B, Bd, Bdd, tolerance=length_tol)
    d, dd, ddd = B - A, Bd - Ad, Bdd - Add
    ang = angle_function(
        d[..., 0], d[..., 1], dd[..., 0], dd[..., 1], ddd[..., 0], ddd[..., 1], tolerance=length_tol
    )
    l, ld, ldd = dist.l, dist.ld, dist.ldd

    # Classification.
    same_point = dist.is_zero | ang.is_null
    equal_lengths = np.full(l.shape, abs(l_AC - l_BC) <= length_tol)
    l_safe = np.where(same_point, 1.0, l)

    # Eqs. 4 and 5 (P'' corrected), and u = P/Q with its derivatives.
    P = l_AC**2 + l_safe**2 - l_BC**2
    Pd = 2.0 * l_safe * ld
    Pdd = 2.0 * (ld**2 + l_safe * ldd)
    Q = 2.0 * l_AC * l_safe
    Qd = 2.0 * l_AC * ld
    Qdd = 2.0 * l_AC * ldd
    u = P / Q
    ud = (Pd * Q - P * Qd) / Q**2
    udd = ((Pdd * Q - P * Qdd) * Q**2 - 2.0 * (Pd * Q - P * Qd) * Q * Qd) / Q**4

    excess = np.abs(u) - 1.0
    coincident = same_point & equal_lengths
    unreachable = (same_point & ~equal_lengths) | (~same_point & (excess > tol))
    aligned = ~same_point & (np.abs(excess) <= tol)
    regular = ~same_point & (excess < -tol)

    case = np.select(
        (aligned, coincident, unreachable),
        (RRRCase.ALIGNED, RRRCase.COINCIDENT, RRRCase.UNREACHABLE),
        RRRCase.REGULAR,
    ).astype(np.int8)

    # Eqs. 1-3.
    assembled = regular | aligned
    # Aligned: beta is exactly 0 (P/Q = +1) or pi (P/Q = -1), as in the paper.
    beta = np.where(regular, np.arccos(np.clip(u, -1.0, 1.0)), np.where(u > 0.0, 0.0, np.pi))
    beta = np.where(assembled, beta, np.nan)
    one_minus_u2 = np.where(regular, 1.0 - u * u, 1.0)
    root = np.sqrt(one_minus_u2)
    betad = np.where(regular, -ud / root, np.nan)
    betadd = np.where(regular, -(u * ud**2 / one_minus_u2 + udd) / root, np.nan)

    # Eqs. 9 and 10 (theta is NaN where A == B, so phi is NaN there too).
    phi = ang.theta + sign * beta
    phid = ang.thetad + sign * betad
    phidd = ang.thetadd + sign * betadd

    # Eqs. 6-8.
    e = np.stack((np.cos(phi), np.sin(phi)), axis=-1)  # unit vector A -> C
    n = np.stack((-np.sin(phi), np.cos(phi)), axis=-1)  # e rotated by +90 deg
    C = A + l_AC * e
    Cd = Ad + l_AC * phid[..., None] * n
    Cdd = Add + l_AC * (-(phid**2)[..., None] * e + phidd[..., None] * n)

    return RRRGroupSolution(
        C=C,
        Cd=Cd,
        Cdd=Cdd,
        phi=phi,
        phid=phid,
        phidd=phidd,
        beta=beta,
        betad=betad,
        betadd=betadd,
        theta=ang.theta,
        thetad=ang.thetad,
        thetadd=ang.thetadd,
        l_AB=l,
        l_ABd=ld,
        l_ABdd=ldd,
        cos_beta=np.where(same_point, np.nan, u),
        case=case,
    )


# --------------------------------------------------------------------------
# Paper §3: SCARA inverse kinematics with the group
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class AssurScaraSolution(_CaseFlags):
    """SCARA joint trajectory from the RRR group, per sample (paper §3).

    All arrays share the batch shape ``(...)`` of the tool-point input.
    Joint variables follow the paper: θ1 is the angle of the arm A→B from +X,
    ``θ2 = θ1 - θ_BC`` (eq. 15), l3 the downward prismatic extension.

    Attributes
    ----------
    theta1, theta1d, theta1dd : ndarray, shape (...)
        θ1 [rad], θ1' [rad/s], θ1'' [rad/s²]; θ1 = φ of the group, not
        wrapped (as in the paper), in (-π, 2π] for mode 1 and (-2π, π] for
        mode 2.
    theta2, theta2d, theta2dd : ndarray, shape (...)
        θ2 wrapped to (-π, π], and its derivatives.
    l3, l3d, l3dd : ndarray, shape (...)
        l3 = l_OA - z_D [length] and its derivatives (eq. 14).
    B, Bd, Bdd : ndarray, shape (..., 2)
        The elbow B projected on XOY, its velocity and acceleration.
    theta_BC, theta_BCd, theta_BCdd : ndarray, shape (...)
        Absolute angle of B→C from +X and its derivatives.
    case : ndarray of int8, shape (...)
        :class:`RRRCase` of the group; boolean masks via ``regular``,
        ``aligned``, ``coincident``, ``unreachable``, ``singular``.
    """

    theta1: np.ndarray
    theta1d: np.ndarray
    theta1dd: np.ndarray
    theta2: np.ndarray
    theta2d: np.ndarray
    theta2dd: np.ndarray
    l3: np.ndarray
    l3d: np.ndarray
    l3dd: np.ndarray
    B: np.ndarray
    Bd: np.ndarray
    Bdd: np.ndarray
    theta_BC: np.ndarray
    theta_BCd: np.ndarray
    theta_BCdd: np.ndarray
    case: np.ndarray

    @property
    def q(self) -> np.ndarray:
        """Joint vector (θ1, θ2, l3), shape (..., 3)."""
        return np.stack((self.theta1, self.theta2, self.l3), axis=-1)

    @property
    def qd(self) -> np.ndarray:
        """Joint velocities (θ1', θ2', l3'), shape (..., 3)."""
        return np.stack((self.theta1d, self.theta2d, self.l3d), axis=-1)

    @property
    def qdd(self) -> np.ndarray:
        """Joint accelerations (θ1'', θ2'', l3''), shape (..., 3)."""
        return np.stack((self.theta1dd, self.theta2dd, self.l3dd), axis=-1)


def assur_scara_inverse(
    D,
    Dd,
    Ddd,
    l_OA: float,
    l_AB: float,
    l_BC: float,
    assembly_mode: int,
    *,
    tolerance: float = SINGULARITY_TOLERANCE,
) -> AssurScaraSolution:
    """SCARA inverse kinematics (position, velocity, acceleration) via the RRR group.

    The paper's §3, eqs. 11-15 (``textbook.md`` §4.1 and §4.3). Geometry:
    O = (0, 0, 0), the fixed shoulder A = (0, 0, l_OA), the elbow
    B = A + l_AB(cos θ1, sin θ1, 0), the wrist C = B + l_BC(cos θ_BC,
    sin θ_BC, 0) and the tool point D = C - (0, 0, l3).

    In the plane XOY the robot is an RRR group whose known joints are the
    group's "A" = the robot's A (fixed: zero velocity and acceleration) and
    the group's "B" = the robot's C = (x_D, y_D) with D's planar derivatives
    (eq. 13); its unknown joint is the robot's elbow B, with ``l_AC = l_AB`` and
    ``l_BC = l_BC``. Then::

        θ1 = φ,  θ1' = φ',  θ1'' = φ''                 (group, eqs. 9-10)
        θ_BC, θ_BC', θ_BC'' = angle function of B→C    (Fig. 2; erratum 9)
        θ2 = θ1 - θ_BC (wrapped to (-π, π]), θ2' = θ1' - θ_BC',
        θ2'' = θ1'' - θ_BC''                            (eq. 15)
        l3 = l_OA - z_D,  l3' = -z_D',  l3'' = -z_D''  (eq. 14)

    Assembly mode 1 gives θ2 > 0 (elbow counter-clockwise from the line A→C),
    mode 2 gives θ2 < 0. Singular samples follow the group (:class:`RRRCase`):
    stretched ``|AC| = l_AB + l_BC`` or folded ``|AC| = |l_AB - l_BC|`` is
    ALIGNED (joint positions returned, their derivatives NaN); the tool above
    the shoulder axis with ``l_AB = l_BC`` is COINCIDENT (θ1 free, all NaN
    except l3); outside the annulus is UNREACHABLE.

    **Relation to standard DH.** θ2 here is the *negative* of the usual
    counter-clockwise relative elbow angle. The same robot in standard DH
    (``textbook.md`` §4.1) is::

        link  a     alpha  d     theta
        1     l_AB  0      l_OA  θ1*
        2     l_BC  180°   0     -θ2*
        3     0     0      l3*   0

    so the DH joint vector is ``(θ1, -θ2, l3)``; it is also Spong's SCARA
    (Example 3.6) with ``θ2_Spong = -θ2``. The tool frame of that table has
    its z axis pointing down; the paper defines no tool orientation.

    Parameters
    ----------
    D : array-like, shape (..., 3)
        Tool point (x_D, y_D, z_D) [mm], e.g. ``(N, 3)`` along a trajectory.
    Dd : array-like, shape (..., 3)
        Its velocity [mm/s].
    Ddd : array-like, shape (..., 3)
        Its acceleration [mm/s²].
    l_OA, l_AB, l_BC : float
        Shoulder height and the two arm lengths, positive [mm].
    assembly_mode : {1, 2}
        1: θ1 = θ + β (θ2 > 0); 2: θ1 = θ - β (θ2 < 0).
    tolerance : float, optional (default: SINGULARITY_TOLERANCE)
        Passed to :func:`rrr_group`.

    Returns
    -------
    solution : AssurScaraSolution
        Joint positions, velocities, accelerations and the group's case.

    Raises
    ------
    InvalidInputError
        If D or its derivatives are not of shape (..., 3) or not finite, a
        length is not positive, or the assembly mode is not 1 or 2.

    Examples
    --------
    The paper's robot (l_OA = 150, l_AB = 80, l_BC = 50 mm) at t = 1 s of its
    spiral (eq. 16), mode 1 (``textbook.md`` §4.4):

    >>> pi = np.pi
    >>> s = assur_scara_inverse([120, 0, 60], [0, 10 * pi, 10], [-5 * pi**2, 0, 0],
    ...                         150.0, 80.0, 50.0, 1)
    >>> for name, row in (("q", s.q), ("qd", s.qd), ("qdd", s.qdd)):
    ...     print(name, " ".join(f"{v:z.6f}" for v in row))
    q 0.307395 0.812756 90.000000
    qd 0.261799 0.000000 -10.000000
    qdd 0.619384 1.698881 0.000000
    """
    D = _check_finite_array(D, "D", 3)
    Dd = _check_finite_array(Dd, "Dd", 3)
    Ddd = _check_finite_array(Ddd, "Ddd", 3)
    D, Dd, Ddd = np.broadcast_arrays(D, Dd, Ddd)
    l_OA = _check_length(l_OA, "l_OA")
    # Checked here so that errors name the robot's lengths, not the group's.
    l_AB = _check_length(l_AB, "l_AB")
    l_BC = _check_length(l_BC, "l_BC")
    assembly_mode = _check_assembly_mode(assembly_mode)

    # Eqs. 11-13: the group's known joints.
    zero = np.zeros_like(D[..., :2])
    group = rrr_group(
        zero, zero, zero, D[..., :2], Dd[..., :2], Ddd[..., :2],
        l_AB, l_BC, assembly_mode, tolerance=tolerance,
    )

    # Fig. 2 on the vector from the elbow B to C = (x_D, y_D) (erratum 9).
    BC = D[..., :2] - group.C
    BCd = Dd[..., :2] - group.Cd
    BCdd = Ddd[..., :2] - group.Cdd
    # |BC| = l_BC wherever the group is assembled, so no null vector arises
    # there; where the group gives NaN the angle is NaN too (masked below).
    components = (BC[..., 0], BC[..., 1], BCd[..., 0], BCd[..., 1], BCdd[..., 0], BCdd[..., 1])
    bc = angle_function(*(np.nan_to_num(v, nan=0.0) for v in components))
    nan_pos = np.isnan(group.C[..., 0])
    nan_vel = np.isnan(group.Cd[..., 0])
    nan_acc = np.isnan(group.Cdd[..., 0])
    theta_BC = np.where(nan_pos, np.nan, bc.theta)
    theta_BCd = np.where(nan_pos | nan_vel, np.nan, bc.thetad)
    theta_BCdd = np.where(nan_pos | nan_vel | nan_acc, np.nan, bc.thetadd)

    # Eqs. 14 and 15.
    return AssurScaraSolution(
        theta1=group.phi,
        theta1d=group.phid,
        theta1dd=group.phidd,
        theta2=wrap_angle(group.phi - theta_BC),
        theta2d=group.phid - theta_BCd,
        theta2dd=group.phidd - theta_BCdd,
        l3=l_OA - D[..., 2],
        l3d=-Dd[..., 2],
        l3dd=-Ddd[..., 2],
        B=group.C,
        Bd=group.Cd,
        Bdd=group.Cdd,
        theta_BC=theta_BC,
        theta_BCd=theta_BCd,
        theta_BCdd=theta_BCdd,
        case=group.case,
    )


def assur_scara_forward(theta1, theta2, l3, l_OA: float, l_AB: float, l_BC: float) -> np.ndarray:
    """Tool point D of the SCARA from its joints, in the paper's convention.

    ``textbook.md`` §4.1::

        x_D = l_AB·cos θ1 + l_BC·cos(θ1 - θ2)
        y_D = l_AB·sin θ1 + l_BC·sin(θ1 - θ2)
        z_D = l_OA - l3

    Parameters
    ----------
    theta1, theta2 : array-like, shape (...)
        Joint angles [rad], θ2 = θ1 - θ_BC.
    l3 : array-like, shape (...)
        Prismatic extension, downward [mm].
    l_OA, l_AB, l_BC : float
        Shoulder height and arm lengths, positive [mm].

    Returns
    -------
    D : ndarray, shape (..., 3)
        Tool point [mm].

    Examples
    --------
    >>> print(np.round(assur_scara_forward(0.5, -0.7, 100.0, 150.0, 80.0, 50.0), 4))
    [88.3245 84.956  50.    ]
    """
    theta1, theta2, l3 = np.broadcast_arrays(
        _check_finite_array(theta1, "theta1", None),
        _check_finite_array(theta2, "theta2", None),
        _check_finite_array(l3, "l3", None),
    )
    l_OA = _check_length(l_OA, "l_OA")
    l_AB = _check_length(l_AB, "l_AB")
    l_BC = _check_length(l_BC, "l_BC")
    theta_BC = theta1 - theta2
    return np.stack(
        (
            l_AB * np.cos(theta1) + l_BC * np.cos(theta_BC),
            l_AB * np.sin(theta1) + l_BC * np.sin(theta_BC),
            l_OA - l3,
        ),
        axis=-1,
    )
