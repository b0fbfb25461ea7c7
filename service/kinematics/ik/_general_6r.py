"""Every solution of a general 6R arm, or of a 6-joint arm with one slide: the Raghavan–Roth elimination solved as
Manocha and Canny solve it.

Notation: the screw model ``world_T_tool = G_1(q_1) ⋯ G_6(q_6) · home``, A = world_T_target · home⁻¹. All
lengths are divided by the robot's size, so every coefficient below is of order one.

The 14 equations
    One *arrangement* (chosen per robot, see below) splits the loop into three consecutive joints a, b, c, the
    next joint d, and two joints e, f on the target's side. G_d fixes its own axis line, so with a point c_d and
    the direction ω_d of that line,
        G_a G_b G_c (c_d, ω_d) = Left(q_e, q_f) · A · Right(q_e, q_f) (c_d, ω_d).
    Both sides are a point p (measured from a point o on axis a) and a unit direction l; Raghavan and Roth's
    14 quantities of each side, p, l, p·p, p·l, p×l and l(p·p) − 2p(p·l), are *linear* in the products
    (1, c_b, s_b) ⊗ (1, c_c, s_c) with coefficients linear in (1, c_a, s_a) on the left, and linear in
    (1, c_e, s_e) ⊗ (1, c_f, s_f) on the right: 14 × 9 on each side.
Numerical coefficients
    The left side depends on the robot only: its 14 × 27 coefficients are interpolated once per robot from the
    3 × 3 × 3 grid of angles 0, ±2π/3 (on which the basis is exactly invertible) and checked at random angles,
    so no symbolic algebra is done for any robot. The right side, 14 × 9, is interpolated per target from the
    3 × 3 grid: nine rigid motions of the line and one product with a constant matrix.
Elimination
    The 8 non-constant right-hand monomials are eliminated with the left null space N (6 × 14) of their
    coefficients (an SVD): six equations in q_a, q_b, q_c. Half-angle tangents and a product with x_b give
    12 equations, Σ(x_a) · [x_b^i x_c^j] = 0 (i ≤ 3, j ≤ 2), with Σ quadratic in x_a. det Σ has degree 24: 16
    roots of the arm and the spurious pairs at ±i from the (1 + x_a²) factors. The companion form is a 24 × 24
    eigenproblem, stacked over targets for ``np.linalg.eig``.
Conditioning
    Rows are equilibrated. The half-angle is taken about a shifted origin, q_a = φ + 2 atan y (a Möbius map of
    x_a that fixes ±i), with φ chosen per target so that the leading matrix Σ(φ + π) is well conditioned: a root
    at q_a = π is then an ordinary finite eigenvalue. Of the six arrangements (each joint in turn as q_a: the
    chain read forwards with q_a = q_3, q_2, q_1 or backwards with q_a = q_4, q_5, q_6) the plan keeps the one
    that recovers random configurations most accurately.
One slide (5R1P)
    A slide by d along its unit direction k moves points by d k and turns nothing. As joint b, c, e or f, the
    14 quantities stay linear in the other joints' (1, cos, sin) and become quadratic in d, so the slide's basis
    is (1, d, d²) (interpolated at d = −1, 0, 1) in place of (1, cos q, sin q): Σ's powers of x_b, x_c are then
    d itself for a slide (no half-angle), its value comes back as the ratio of consecutive powers, and e's or
    f's as its linear monomial. As joint a, p = d k + p_0(q_b, q_c) and l does not depend on d, so p, l, p·l and
    p×l are linear in d and p·p and l(p·p) − 2p(p·l) quadratic; only those four rows have a d² part, so Σ's
    leading matrix in d has rank 8 of 12 whatever the scale or origin of d: 8 of the 24 roots are at d → ∞.
    Hence the same Möbius map as for a revolute joint: per target, an interval centre ± w that holds every
    solution's d (:func:`_slide_interval`, from d = k·p_R − k·p_0) is mapped to θ ∈ [−π/2, π/2] by
    d = centre + w tan(θ/2), which makes Σ a quadratic in (1, cos θ, sin θ) like a revolute joint's, and the
    shifts φ ≠ 0 put its leading matrix at a finite d. Roots outside the interval (among them the ones at
    d → ∞, which rounding spreads by ~ε^¼ around θ = π and may make real) are no solution's and are dropped.
    Joint d is never the slide (q_d is recovered as a turn), which leaves five of the six arrangements; as for
    a 6R arm, the plan keeps the most accurate (an arm with two parallel axes among e, f, or among b, c, d, needs
    another arrangement than the slide-first one).
Back-substitution
    q_b, q_c from the eigenvector (runs of three powers give cos and sin, so x → ∞ is just an angle of π);
    q_e, q_f from the linear right-hand monomials; q_d from the remaining rotation. Every root is then polished
    by Newton's method on the screw model's FK, and the shared verification (FK residual, merging) decides what
    is kept.
Completeness
    A target's answer is complete only when the algebra accounts for every solution: the right-hand
    coefficients have full rank 8, the leading matrix is well conditioned, at most 16 roots are real or
    ambiguous, every ambiguous eigenvalue (an imaginary part within :data:`AMBIGUITY_FACTOR` times its first-order
    error bound: a root pair about to merge or split) is accounted for, and (checked after verification) every
    real root gave one distinct verified solution. Both halves of an ambiguous pair are back-substituted from
    their common real part and split along the Jacobian's null motion there: they count when they verify as two
    solutions, or as one double root where the Jacobian is singular (a fold: listed once, and reported).
    Anything else is answered with ``complete: false``. A 6R arm's target farther from axis 1 than the arm's
    reach bound is a certain ``unreachable`` (complete) whatever the conditioning (a slide has no
    such bound).
Singular roots
    Where the Jacobian at a verified root is singular to within :data:`FAMILY_CONDITION`, the target fixes the
    root along the null motion only to about DUPLICATE_TOLERANCE: the singularity is reported (two coaxial
    joints, a self-motion, or a fold where two roots meet), and the root is moved along that motion to the
    reference's value of its leading joint where that still reaches the target, as the closed forms hold a free
    joint (see :meth:`General6RPlan._represent_singular_roots`). Two roots at a fold that Newton's steps left
    within :data:`FOLD_PAIR` of each other are split again; where they meet within DUPLICATE_TOLERANCE they are
    one double root, listed once (on five general arms at det J = 0, before this, 197 of 525 requests went to
    the numeric search, and an exact double root was listed twice, 1e-6…5e-6 apart).

Pieper-class arms (three consecutive axes through one point, or parallel) make Σ singular for every x in some
arrangements (and give double eigenvalues, solutions that share q_a, in others); they are the closed-form
families' and :meth:`General6RPlan.match` refuses them. (The plan's choice of arrangement does solve PUMA- and
UR5-type arms, which a test uses to check the elimination against the closed forms.) Arms within ~1e-5 of a
Pieper arm are accepted; there up to ~1 % of targets meet a near-double eigenvalue (measured on a PUMA 560
perturbed by 1e-5…1e-7: a solution missed on 1–2 targets in 300), and those answers say ``complete: false``.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np

from .._rotations import wrap_angle
from .._tolerances import DUPLICATE_TOLERANCE
from .._forward import JointTrig
from ._screws import chain_motion, invert, joint_motion
from ._structure import Geometry
from ._types import Candidates, LabelCodes, SingularFlags, Singularity, Sealed

#: The plan's structure names: a 6R arm, and one with a slide.
GENERAL_6R = "general_6r"
GENERAL_5R1P = "general_5r1p"
GENERAL_STRUCTURES = (GENERAL_6R, GENERAL_5R1P)


#: A complex root whose angle's imaginary part is within this many times its error bound of the real axis
#: (a pair about to become two real roots, or two real roots split by rounding) is ambiguous.
AMBIGUITY_FACTOR = 100.0
#: Roots y with |1 + y²| below this are the spurious ones at ±i.
SPURIOUS_RADIUS = 1e-2
#: Complex roots whose angle's imaginary part is below this get an error bound. Near a family of solutions the
#: eigenproblem is nearly singular while its matrices look well conditioned: with axes 1 and 3 of an arm 1e-6
#: from coaxial at q2 = 0, the generating root came out as a pair at 0.54 rad from the real axis with a bound of
#: 26 rad. Farther out, towards the spurious roots at ±i, the bound carried to the angle (over |1 + y²|) says
#: nothing (a random pose's pair at 2.1 rad had a bound of 0.09, well conditioned in y).
SUSPECT_IMAGINARY = 1.0
#: Smallest reciprocal condition number of the leading matrix and of the right-hand coefficients accepted.
CONDITION_FLOOR = 1e-9
#: Newton steps on the FK at most, for every root whose error twist (normalised lengths, radians) is above
#: NEWTON_TOLERANCE; the shared verification then accepts at 1e-9.
NEWTON_STEPS = 5
NEWTON_TOLERANCE = 1e-13
#: The worst error (radians) in recovering random configurations before polishing that a plan accepts.
PLAN_ACCURACY = 1e-4
#: An arrangement this accurate on the test configurations is taken without trying the others.
GOOD_ENOUGH = 1e-10

#: A root where the Jacobian's null motion (two joints turned by ±t, or any joint motion) moves the tool by less
#: than this ratio of its largest singular value is singular: the elimination's roots satisfy the loop to about
#: ELIMINATION_RESIDUAL before Newton's steps, which pins them along that motion only to
#: ELIMINATION_RESIDUAL / FAMILY_CONDITION = DUPLICATE_TOLERANCE; below it they land anywhere on a family (on a
#: raw xArm 7 at q2 = 0, four roots 0.004-0.02 rad apart, each verified at ACCEPT_RESIDUAL), or anywhere in the
#: band where two roots meet (on a Jaco 2 at det J = 0, 1e-6…9e-6 from the generating configuration).
ELIMINATION_RESIDUAL = 1e-12
FAMILY_CONDITION = ELIMINATION_RESIDUAL / DUPLICATE_TOLERANCE
#: Two roots of such a family differ along its null motion; across it, by no more than this (radians): the
#: xArm's four differed by 1.4e-5 in q2, where the Jacobian's σ_min is ~1e-8 of σ_max.
SAME_FAMILY = 1e-4
#: A family's representative is reached from a root in steps of at most this (radians) along its null motion.
FAMILY_STEP = 0.2
#: The step (radians) along a singular root's null motion that tells a family (the target still reached, either
#: way) from a fold (reached on one side at most).
FAMILY_PROBE = 1e-3
#: Where two roots at a fold came out as one, Newton's steps (at most SPLIT_NEWTON_STEPS) start this far (radians)
#: either side of them along the null motion, beyond the band (1e-6…9e-6) in which the elimination places them.
SPLIT_STEP = 1e-5
SPLIT_NEWTON_STEPS = 30
#: Two roots at a fold closer than this (radians) are split again: Newton's steps stopped at NEWTON_TOLERANCE leave
#: the two halves of a double root 1e-6…5e-6 apart (a Jaco 2 at det J = 0), both verified.
FOLD_PAIR = 1e-4
#: The split's Newton steps run until the error twist is below SPLIT_TOLERANCE (near rounding), not
#: NEWTON_TOLERANCE, and by the pseudo-inverse (singular values down to SPLIT_RCOND of the largest), not with
#: Newton's damping of 1e-14 on J Jᵀ: at a double root the residual grows with the square of the distance t along
#: the null motion and σ_min of the Jacobian with t, so steps stopped at NEWTON_TOLERANCE, or damped once σ_min² is
#: below 1e-14, leave the two sides 1e-6…5e-6 apart (a Jaco 2), both verified; run on, they meet within
#: DUPLICATE_TOLERANCE.
SPLIT_TOLERANCE = 1e-15
SPLIT_RCOND = 1e-12
#: Joints whose share of a singular root's unit null motion is at least this are named in its report.
SINGULAR_MOTION = 0.1

#: Trigonometric basis (1, cos, sin) sampled at 0, 2π/3, 4π/3: rows are samples.
_GRID = np.array([0.0, 2 * np.pi / 3, 4 * np.pi / 3])
_TRIG = np.stack([np.ones(3), np.cos(_GRID), np.sin(_GRID)], axis=1)  # (3 samples, 3 basis)
#: (1, cos, sin)·(1 + x²) in the powers (1, x, x²).
_HALF = np.array([[1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [0.0, 2.0, 0.0]])
#: Shifts φ of the half-angle origin tried, in order, until the leading matrix is well conditioned.
_SHIFTS = (0.0, 1.0, -1.3, 2.1, -2.6, 0.45)
#: A slide's roots with |tan(θ/2)| above this lie outside the interval that holds every solution's slide value
#: (see :func:`_slide_interval`; the margin covers rounding): among them the spurious ones at d → ∞.
SLIDE_OUTSIDE = 1.0 + 1e-6
#: Slide values (normalised lengths) at which a slide's left coefficients are interpolated, and the basis
#: (1, d, d²) there: rows are samples.
_SLIDE_GRID = np.array([-1.0, 0.0, 1.0])
_POWERS = np.stack([np.ones(3), _SLIDE_GRID, _SLIDE_GRID ** 2], axis=1)


def _cross_matrix(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """[k]× and [k]×² for a unit axis k, memoised by value (an arm has a few axes)."""
    key = tuple(k.tolist())
    pair = _CROSS.get(key)
    if pair is None:
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        pair = (K, K @ K)
        if len(_CROSS) < 4096:
            _CROSS[key] = pair
    return pair


_CROSS: dict[tuple[float, ...], tuple[np.ndarray, np.ndarray]] = {}
_EYE3 = np.eye(3)


def _rodrigues(k: np.ndarray | tuple[np.ndarray, np.ndarray], q: np.ndarray) -> np.ndarray:
    """R(k, q) for q of shape (...,): (..., 3, 3). ``k`` is the unit axis or its pair ([k]×, [k]×²)."""
    K, KK = k if isinstance(k, tuple) else _cross_matrix(k)
    q = np.asarray(q, dtype=float)[..., None, None]
    return _EYE3 + np.sin(q) * K + (1.0 - np.cos(q)) * KK


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b along the last axis (np.cross without its axis bookkeeping)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def _fourteen(p: np.ndarray, l: np.ndarray) -> np.ndarray:
    """Raghavan and Roth's 14 quantities of a point p and unit direction l (..., 3): (..., 14)."""
    pp = np.einsum("...i,...i->...", p, p)[..., None]
    pl = np.einsum("...i,...i->...", p, l)[..., None]
    return np.concatenate([p, l, pp, pl, _cross(p, l), l * pp - 2.0 * p * pl], axis=-1)


class _Arrangement:
    """One way of writing the loop for the elimination (see the module docstring).

    ``reverse`` reads the chain backwards (joints 6…1, axes negated, target A⁻¹); ``first`` (0, 1 or 2) is the
    index, in the chain as read, of joint a. ``order`` maps the chain's joints (a, b, c, d, e, f) to the robot's.
    Any of them but d may be a slide (``revolute`` (6,), as read); ``slide`` tells whether joint a is one.
    """

    def __init__(self, directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, reverse: bool,
                 first: int) -> None:
        if reverse:
            directions, points, revolute = -directions[::-1], points[::-1], revolute[::-1]
        self.reverse, self.first = reverse, first
        self.directions, self.points, self.revolute = directions, points, revolute
        self.cross = [_cross_matrix(k) for k in directions]
        a, d = first, first + 3
        # the target's side: joints (e, f) and where they stand around A
        self.rhs = {2: (0, 1), 1: (0, 5), 0: (5, 4)}[first]
        chain = [a, a + 1, a + 2, d, *self.rhs]
        self.order = np.array([5 - j if reverse else j for j in chain])
        self.kinds = revolute[chain]  # (6,): which of a, b, c, d, e, f turn
        self.slide = not self.kinds[0]
        # a slide's leading matrix at d → ∞ (φ = 0) is singular by construction: its shifts start at the next
        self.shifts = _SHIFTS[1:] if self.slide else _SHIFTS
        # basis(q_b) ⊗ basis(q_c) times (1 + x²) per revolute joint → the powers x_b^i x_c^j (9, 9)
        self.powers = np.kron(_HALF if self.kinds[1] else _EYE3, _HALF if self.kinds[2] else _EYE3)
        self.line_point, self.line_direction = points[d], directions[d]
        # the point o on axis a nearest the other axes' points (any point of the axis keeps the structure)
        k = directions[a]
        centre = points.mean(axis=0)
        self.origin = points[a] + k * (k @ (centre - points[a]))
        self._fit_left()
        self._prepare_right()

    def first_basis(self, q: np.ndarray) -> np.ndarray:
        """Joint a's basis of the left coefficients at its values q (...,): (..., 3)."""
        return _basis(q, self.kinds[0])

    def middle_basis(self, qb: np.ndarray, qc: np.ndarray) -> np.ndarray:
        """basis(q_b) ⊗ basis(q_c): (..., 9), index 3i + j."""
        return _basis2(qb, qc, self.kinds[1], self.kinds[2])

    def _fit_left(self) -> None:
        """The left side's coefficients C (3, 14, 9): F_L = Σ_k C_k basis_k(q_a) · basis(q_b) ⊗ basis(q_c),
        interpolated on the grid of each joint's basis and checked at random values."""
        grids, samples = zip(*(_sampling(kind) for kind in self.kinds[:3]))
        g = np.array(np.meshgrid(*grids, indexing="ij")).reshape(3, -1).T  # (27, 3)
        basis = np.kron(np.kron(samples[0], samples[1]), samples[2])  # (27 samples, 27 basis)
        coefficients = np.linalg.solve(basis, self.left_values(g)).T  # (14, 27)
        self.left = coefficients.reshape(14, 3, 9).transpose(1, 0, 2).copy()
        check = np.random.default_rng(7).uniform(-np.pi, np.pi, (8, 3))
        predicted = np.einsum("kem,nk,nm->ne", self.left, self.first_basis(check[:, 0]),
                              self.middle_basis(check[:, 1], check[:, 2]))
        self.left_fit_error = float(np.abs(predicted - self.left_values(check)).max())

    def left_values(self, q: np.ndarray) -> np.ndarray:
        """The 14 left-hand quantities at (q_a, q_b, q_c) of shape (M, 3): (M, 14)."""
        a = self.first
        T = chain_motion(self.directions[a:a + 3], self.points[a:a + 3], self.revolute[a:a + 3], q)
        p = np.einsum("mij,j->mi", T[:, :3, :3], self.line_point) + T[:, :3, 3] - self.origin
        l = np.einsum("mij,j->mi", T[:, :3, :3], self.line_direction)
        return _fourteen(p, l)

    def _prepare_right(self) -> None:
        """The nine rigid motions Left_k, Right_k of the 3 × 3 sample grid of (q_e, q_f), and the fit matrix."""
        e, f = self.rhs
        (grid_e, samples_e), (grid_f, samples_f) = _sampling(self.kinds[4]), _sampling(self.kinds[5])
        ge, gf = (m.reshape(-1) for m in np.meshgrid(grid_e, grid_f, indexing="ij"))
        Ge = joint_motion(self.directions[e], self.points[e], bool(self.kinds[4]), -ge)  # G_e⁻¹ at the samples
        Gf = joint_motion(self.directions[f], self.points[f], bool(self.kinds[5]), -gf)
        eye = np.broadcast_to(np.eye(4), Ge.shape)
        # G_2⁻¹ G_1⁻¹ A | G_1⁻¹ A G_6⁻¹ | A G_6⁻¹ G_5⁻¹ (chain as read, 0-based joints)
        left, right = {2: (Gf @ Ge, eye), 1: (Ge, Gf), 0: (eye, Ge @ Gf)}[self.first]
        self.sample_left = left[:, :3, :]  # (9, 3, 4)
        self.sample_right_point = np.einsum("kij,j->ki", right[:, :3, :3], self.line_point) + right[:, :3, 3]
        self.sample_right_direction = np.einsum("kij,j->ki", right[:, :3, :3], self.line_direction)
        # B = values · (basis⁻¹)ᵀ: with basis (9 samples, 9 products)
        self.right_fit = np.linalg.inv(np.kron(samples_e, samples_f)).T  # values (.., 9 samples) → coefficients

    def right_coefficients(self, A: np.ndarray) -> np.ndarray:
        """The right side's coefficients B (N, 14, 9) for chain targets A (N, 4, 4) (normalised lengths)."""
        point = np.einsum("nij,kj->nki", A[:, :3, :3], self.sample_right_point) + A[:, None, :3, 3]
        direction = np.einsum("nij,kj->nki", A[:, :3, :3], self.sample_right_direction)
        L = self.sample_left
        p = np.einsum("kij,nkj->nki", L[:, :, :3], point) + L[:, :, 3] - self.origin
        l = np.einsum("kij,nkj->nki", L[:, :, :3], direction)
        values = _fourteen(p, l)  # (N, 9 samples, 14)
        return np.einsum("nse,sm->nem", values, self.right_fit)


def _trig(q: np.ndarray) -> np.ndarray:
    """(1, cos q, sin q): (..., 3)."""
    return np.stack([np.ones_like(q), np.cos(q), np.sin(q)], axis=-1)


def _basis(q: np.ndarray, revolute: bool) -> np.ndarray:
    """A joint's basis at its values q (...,): (1, cos q, sin q) for a revolute joint, (1, d, d²) for a slide."""
    return _trig(q) if revolute else np.stack([np.ones_like(q), q, q * q], axis=-1)


def _basis2(q1: np.ndarray, q2: np.ndarray, revolute1: bool, revolute2: bool) -> np.ndarray:
    """basis(q1) ⊗ basis(q2): (..., 9), index 3i + j."""
    return (_basis(q1, revolute1)[..., :, None] * _basis(q2, revolute2)[..., None, :]).reshape(q1.shape + (9,))


def _sampling(revolute: bool) -> tuple[np.ndarray, np.ndarray]:
    """A joint's interpolation grid (3,) and its basis there (3 samples, 3 basis): angles 0, ±2π/3, or a slide's
    values −1, 0, 1 (normalised lengths)."""
    return (_GRID, _TRIG) if revolute else (_SLIDE_GRID, _POWERS)


class _Roots:
    """The real roots of one arrangement for N targets.

    ``joints`` (N, m, 6) in the robot's order and ``valid`` (N, m): the m slots hold each target's real roots
    (m is the largest count in the batch, at least 1). ``real_count`` (N,) counts them before the cut to 16;
    ``ambiguous`` (N,) marks targets with a root neither clearly real nor clearly complex, ``near`` (N, m) the
    slots that hold such roots (back-substituted from their real parts, and valid) and ``ambiguous_count`` (N,)
    counts them before the cut; ``conditioned``
    (N,) that the right-hand coefficients and the leading matrix were well conditioned; ``shift`` (N,) the origin
    φ of the half-angle used for each target.
    """

    def __init__(self, joints: np.ndarray, valid: np.ndarray, real_count: np.ndarray, near: np.ndarray,
                 ambiguous_count: np.ndarray, conditioned: np.ndarray, shift: np.ndarray) -> None:
        self.joints, self.valid, self.real_count = joints, valid, real_count
        self.ambiguous, self.near, self.ambiguous_count = ambiguous_count > 0, near, ambiguous_count
        self.conditioned, self.shift = conditioned, shift


def _solve_arrangement(arr: _Arrangement, A: np.ndarray) -> _Roots:
    """Candidates of the elimination for chain targets A (N, 4, 4) in normalised lengths."""
    n = len(A)
    chain_A = invert(A) if arr.reverse else A
    B = arr.right_coefficients(chain_A)  # (N, 14, 9)
    B8, b1 = B[:, :, 1:], B[:, :, 0]
    U, sigma, Vt = np.linalg.svd(B8)  # U (N, 14, 14)
    rank_ok = sigma[:, -1] > CONDITION_FLOOR ** 0.5 * sigma[:, 0]
    null = np.swapaxes(U[:, :, 8:], 1, 2)  # (N, 6, 14)
    E = np.einsum("nre,kem->nkrm", null, arr.left)  # (N, 3, 6, 9)
    E[:, 0, :, 0] -= np.einsum("nre,ne->nr", null, b1)
    if arr.slide:  # powers of d → trigonometric form in θ, d = centre + half_width · tan(θ/2)
        centre, half_width = _slide_interval(arr, B)
        E = _slide_to_angle(E, centre, half_width)
    # Σ for each shift, keep the first shift with a well-conditioned leading matrix
    shift = np.zeros(n)
    pending = np.ones(n, dtype=bool)
    companions = np.zeros((n, 24, 24))
    lead_ok = np.zeros(n, dtype=bool)
    for phi in arr.shifts:
        rows = np.flatnonzero(pending)
        if not len(rows):
            break
        c, s = np.cos(phi), np.sin(phi)
        E0, E1, E2 = E[rows, 0], c * E[rows, 1] + s * E[rows, 2], -s * E[rows, 1] + c * E[rows, 2]
        D = np.stack([E0 + E1, 2.0 * E2, E0 - E1], axis=1) @ arr.powers  # (R, 3, 6, 9): powers 1, y, y²
        D /= np.abs(D).max(axis=(1, 3), keepdims=True)  # row equilibration
        S = np.zeros((len(rows), 3, 12, 12))
        S[:, :, :6, :9] = D
        S[:, :, 6:, 3:] = D
        lead = S[:, 2]
        singular = np.linalg.svd(lead, compute_uv=False)
        good = singular[:, -1] > CONDITION_FLOOR * singular[:, 0]
        if phi == arr.shifts[-1]:
            good[:] = True
        rows, S, lead = rows[good], S[good], lead[good]
        lead_ok[rows] = (singular[good, -1] > CONDITION_FLOOR * singular[good, 0])
        rhs = np.concatenate([S[:, 0], S[:, 1]], axis=2)
        if phi == arr.shifts[-1] and not lead_ok[rows].all():  # no shift helped: least squares, marked incomplete
            tail = np.linalg.pinv(lead) @ rhs
        else:
            tail = np.linalg.solve(lead, rhs)  # (R, 12, 24)
        companions[rows, :12, 12:] = np.eye(12)
        companions[rows, 12:, :12] = -tail[:, :, :12]
        companions[rows, 12:, 12:] = -tail[:, :, 12:]
        shift[rows] = phi
        pending[rows] = False
    finite = np.isfinite(companions).all(axis=(1, 2))
    if not finite.all():  # overflow in a degenerate target: no roots from it, and not complete
        companions[~finite] = 0.0
        lead_ok &= finite
    y, vectors = np.linalg.eig(companions)  # (N, 24), (N, 24, 24)
    with np.errstate(divide="ignore", invalid="ignore"):  # a spurious root exactly at ±i
        angle = 2.0 * np.arctan(y.astype(complex))
        imaginary = np.abs(angle.imag)  # NaN at exactly ±i: never real, never ambiguous, sorted last
    # the spurious roots: for a revolute joint a at ±i (of the (1 + x²) factors, a defective quadruple pair, so
    # rounding spreads them by ~ε^¼: far from real, never ambiguous); for a slide at d → ∞ (θ = π: the d²
    # coefficients have rank 4 at most, so Σ's leading matrix in d is singular), which rounding may make real
    if arr.slide:  # and any root outside the interval that holds every solution
        with np.errstate(invalid="ignore"):
            spurious = ~(np.abs(np.tan(0.5 * (shift[:, None] + angle))) <= SLIDE_OUTSIDE)
        imaginary[spurious] = np.inf
    else:
        spurious = np.abs(1.0 + y * y) < SPURIOUS_RADIUS
    real = (y.imag == 0.0) & ~spurious  # LAPACK returns a real matrix's real eigenvalues with no imaginary part
    real_count = real.sum(axis=1)
    # first-order error bound of each eigenvalue (backward-stable QR: ~ n ε ‖M‖ times its condition number,
    # from the left eigenvectors, the rows of V⁻¹), carried to the angle: dq = 2 dy / |1 + y²|
    with np.errstate(invalid="ignore"):
        suspect = ~real & ~spurious & (imaginary < SUSPECT_IMAGINARY)
    near = np.zeros_like(real)
    rows = np.flatnonzero(suspect.any(axis=1))
    if len(rows):  # the bound needs the left eigenvectors: only for targets with a complex root near the axis
        left_vectors = np.linalg.inv(vectors[rows])
        condition = np.linalg.norm(left_vectors, axis=2) * np.linalg.norm(vectors[rows], axis=1)
        size = np.linalg.norm(companions[rows], axis=(1, 2))[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = 2.0 * 24 * np.finfo(float).eps * size * condition / np.abs(1.0 + y[rows] ** 2)
            near[rows] = suspect[rows] & (imaginary[rows] <= AMBIGUITY_FACTOR * bound)
    ambiguous_count = near.sum(axis=1)
    # back-substitute the real and the ambiguous roots only: m slots, nearest the real axis first
    real = real | near
    m = int(min(max(real.sum(axis=1).max(initial=0), 1), 16))
    order = np.argsort(imaginary, axis=1, kind="stable")[:, :m]
    take = (np.arange(n)[:, None], order)
    valid, near = real[take], near[take]
    y, qa = y[take], shift[:, None] + angle.real[take]
    vectors = np.take_along_axis(vectors, order[:, None, :], axis=2)  # (N, 24, m)
    # monomials x_b^i x_c^j (i ≤ 3, j ≤ 2) of each root, from the block of the eigenvector that is not small
    top, bottom = vectors[:, :12, :], vectors[:, 12:, :]
    monomials = np.where((np.abs(y) <= 1.0)[:, None, :], top, bottom)  # (N, 12, m)
    monomials = np.swapaxes(monomials, 1, 2).reshape(n, m, 4, 3)
    qb = _monomial_value(monomials, arr.kinds[1])
    qc = _monomial_value(np.swapaxes(monomials, -1, -2), arr.kinds[2])
    # right-hand monomials by least squares, then q_e, q_f from the linear ones
    if arr.slide:
        qa = centre[:, None] + half_width[:, None] * np.tan(0.5 * qa)
    left = np.einsum("ntk,kem,ntm->nte", arr.first_basis(qa), arr.left, arr.middle_basis(qb, qc))  # (N, m, 14)
    inverse_sigma = np.where(sigma > CONDITION_FLOOR * sigma[:, :1], 1.0 / np.maximum(sigma, 1e-300), 0.0)
    pinv = np.einsum("nji,nj,nej->nie", Vt, inverse_sigma, U[:, :, :8])  # (N, 8, 14)
    mono = np.einsum("nie,nte->nti", pinv, left - b1[:, None, :])  # (N, m, 8): index m − 1 of 3i + j
    # (c_e, s_e) at m = 3, 6 and (c_f, s_f) at m = 1, 2; a slide's value at m = 3 or 1
    qe = np.arctan2(mono[..., 5], mono[..., 2]) if arr.kinds[4] else mono[..., 2]
    qf = np.arctan2(mono[..., 1], mono[..., 0]) if arr.kinds[5] else mono[..., 0]
    chain = np.stack([qa, qb, qc, np.zeros_like(qa), qe, qf], axis=-1)  # joints (a, b, c, d, e, f)
    chain[..., 3] = _last_joint(arr, chain_A, chain)
    joints = np.empty_like(chain)
    joints[..., arr.order] = chain
    return _Roots(joints, valid, real_count, near, ambiguous_count, rank_ok & lead_ok, shift)


def _slide_interval(arr: _Arrangement, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per target, an interval centre ± half-width (N,) that holds the slide value d of every solution.

    The points agree, d k + p_0(q_b, q_c) = p_R(q_e, q_f) (k the slide's unit direction), so
    d = k·p_R − k·p_0; each is a constant plus monomials of sines and cosines (at most 1 in size) whose
    coefficients bound the rest.
    """
    k = arr.directions[arr.first]
    right = np.einsum("i,nim->nm", k, B[:, :3, :])  # (N, 9)
    left = k @ arr.left[0, :3, :]  # (9,): the d⁰ part of k·p
    centre = right[:, 0] - left[0]
    half_width = np.abs(right[:, 1:]).sum(axis=1) + np.abs(left[1:]).sum()
    return centre, np.maximum(half_width, 1e-3)


def _slide_to_angle(E: np.ndarray, centre: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """Coefficients E (N, 3, …) in the powers (1, d, d²) of a slide → coefficients in (1, cos θ, sin θ) of
    cos²(θ/2) times the same polynomial at d = centre + half_width · tan(θ/2)."""
    c, w = centre[:, None, None], half_width[:, None, None]
    Q0 = E[:, 0] + c * E[:, 1] + c ** 2 * E[:, 2]  # the powers (1, u, u²) of u = tan(θ/2)
    Q1 = w * (E[:, 1] + 2.0 * c * E[:, 2])
    Q2 = w ** 2 * E[:, 2]
    return 0.5 * np.stack([Q0 + Q2, Q0 - Q2, Q1], axis=1)


def _monomial_value(m: np.ndarray, revolute: bool) -> np.ndarray:
    """A joint's value from its powers along the second-last axis, m (..., P ≥ 3, Q) ∝ x^i · (…): the angle of
    :func:`_monomial_angle`, or a slide's d from the runs m_i+1 = d m_i (least squares, the largest entries
    weighing most)."""
    if revolute:
        return _monomial_angle(m)
    low, high = m[..., :-1, :], m[..., 1:, :]
    return (high * low.conj()).real.sum(axis=(-2, -1)) / (np.abs(low) ** 2).sum(axis=(-2, -1))


def _monomial_angle(m: np.ndarray) -> np.ndarray:
    """The angle q with x = tan(q/2) from powers along the second-last axis, m (..., P ≥ 3, Q) ∝ x^i · (…).

    Each run of three consecutive powers (m_i, m_i+1, m_i+2) = m_i (1, x, x²) gives
    (cos q, sin q) ∝ (m_i − m_i+2, 2 m_i+1) / (m_i + m_i+2); summing every run, each weighted by
    |m_i + m_i+2|², uses the largest entries and is exact at x → ∞ (q = π), where only the top power is left.
    """
    low, middle, high = m[..., :-2, :], m[..., 1:-1, :], m[..., 2:, :]
    weight = (low + high).conj()
    cosine = ((low - high) * weight).real.sum(axis=(-2, -1))
    sine = (2.0 * middle * weight).real.sum(axis=(-2, -1))
    return np.arctan2(sine, cosine)


def _last_joint(arr: _Arrangement, A: np.ndarray, chain: np.ndarray) -> np.ndarray:
    """q_d from the rotation left over once the other five joints are known (chain as read)."""
    q = np.zeros(chain.shape[:-1] + (6,))
    a = arr.first
    for slot, joint in enumerate((a, a + 1, a + 2, a + 3, *arr.rhs)):
        q[..., joint] = chain[..., slot]
    q *= arr.revolute  # a slide turns nothing
    d = a + 3
    R_before = _rodrigues(arr.cross[0], q[..., 0])
    for j in range(1, d):
        R_before = R_before @ _rodrigues(arr.cross[j], q[..., j])
    R_d = np.swapaxes(R_before, -1, -2) @ A[:, None, :3, :3]
    if d < 5:
        R_after = _rodrigues(arr.cross[5], q[..., 5])
        for j in range(4, d, -1):
            R_after = _rodrigues(arr.cross[j], q[..., j]) @ R_after
        R_d = R_d @ np.swapaxes(R_after, -1, -2)
    k = arr.directions[d]
    u = _cross(k, np.eye(3)[np.argmin(np.abs(k))])
    u /= np.linalg.norm(u)
    turned = R_d @ u
    return np.arctan2(turned @ _cross(k, u), turned @ u)


def _newton(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, A_targets: np.ndarray,
            q: np.ndarray, steps: int = NEWTON_STEPS, held: np.ndarray | None = None,
            tolerance: float = NEWTON_TOLERANCE, rcond: float | None = None) -> np.ndarray:
    """Newton's method on G_1 ⋯ G_6 = A for candidates q (K, 6) and targets A (K, 4, 4), normalised lengths
    (``revolute`` (6,) tells turns from slides); ``held`` (K,), a joint per candidate that keeps its value
    (Gauss–Newton on the other five).

    Steps the candidates whose error twist is above ``tolerance`` (roots come from the eigenproblem
    to about 1e-12, so one step, or none, usually suffices); singular candidates get a tiny damping instead of a
    failure.
    """
    q = q.copy()
    R_A, p_A = A_targets[:, :3, :3], A_targets[:, :3, 3]
    for _ in range(steps + 1):
        R, p, twists = _chain_twists(directions, points, revolute, q)
        error = _error_twist(R, p, R_A, p_A)
        active = np.abs(error).max(axis=1) > tolerance
        if _ == steps or not active.any():
            break
        J = twists[active]
        fixed = np.zeros(J.shape[:2])
        if held is not None:
            J[np.arange(len(J)), held[active]] = 0.0
            fixed[np.arange(len(J)), held[active]] = 1.0
        if rcond is not None:  # the pseudo-inverse: every singular value above rcond · σ_max counts in full
            q[active] += np.einsum("kij,kj->ki", np.linalg.pinv(np.swapaxes(J, -1, -2), rcond=rcond), error[active])
            continue
        JJt = J @ np.swapaxes(J, -1, -2) + 1e-14 * np.eye(6) + fixed[..., None] * np.eye(6)
        q[active] += np.linalg.solve(JJt, (J @ error[active][..., None]))[..., 0]
    return q


def _error_twist(R: np.ndarray, p: np.ndarray, R_A: np.ndarray, p_A: np.ndarray) -> np.ndarray:
    """The spatial error twist (ω, v) (K, 6) with A ≈ exp([ξ]) T, of T = (R, p) against A = (R_A, p_A)."""
    R_err = R_A @ np.swapaxes(R, -1, -2)
    omega = 0.5 * np.stack([R_err[:, 2, 1] - R_err[:, 1, 2], R_err[:, 0, 2] - R_err[:, 2, 0],
                            R_err[:, 1, 0] - R_err[:, 0, 1]], axis=-1)
    return np.concatenate([omega, p_A - p - _cross(omega, p)], axis=-1)


def _chain_twists(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, q: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """G_1 ⋯ G_6 at q (K, 6) as its rotation (K, 3, 3) and translation (K, 3), and the spatial joint twists
    (K, 6, 6) at q, (ω, v): (ω, p × ω) of a turn through p, (0, k) of a slide along k; normalised lengths."""
    cross = [_cross_matrix(k) for k in directions]
    R = np.broadcast_to(_EYE3, q.shape[:-1] + (3, 3))
    p = np.zeros(q.shape[:-1] + (3,))
    twists = np.zeros(q.shape + (6,))
    for j in range(6):
        axis = R @ directions[j]
        if not revolute[j]:
            twists[:, j, 3:] = axis
            p = p + axis * q[:, j, None]
            continue
        twists[:, j, :3] = axis
        twists[:, j, 3:] = _cross(R @ points[j] + p, axis)
        turn = _rodrigues(cross[j], q[:, j])
        p = p + (R @ (points[j] - turn @ points[j])[..., None])[..., 0]
        R = R @ turn
    return R, p, twists


def _by_target(rows: np.ndarray, chosen: np.ndarray) -> Iterator[tuple[int, np.ndarray]]:
    """The ``chosen`` (K,) roots grouped by target: (target, the indices of its chosen roots), ``rows`` (K,) being
    each root's target."""
    for row in np.unique(rows[chosen]).tolist():
        yield row, np.flatnonzero((rows == row) & chosen)


def _singular_motion(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, q: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Roots q (K, 6) where the twist Jacobian is singular to within :data:`FAMILY_CONDITION` (its smallest
    singular value that small a ratio of its largest): the target fixes them along the null motion only to about
    DUPLICATE_TOLERANCE. There two roots meet (a fold), or a family of solutions passes (two coaxial joints, as
    the xArm's joints 1 and 3 at q2 = 0, or a self-motion over more joints, as a raw xArm 7's shoulder and joint
    5 at its elbow angle q4 = -0.44 with q7 held).

    Returns ``found`` (K,) bool, the unit null motion (K, 6) (largest entry positive) and ``coaxial`` (K,) bool:
    the motion turns two joints only, one by t and the other by ∓t (±1/√2 on the pair)."""
    _, _, J = _chain_twists(directions, points, revolute, q)  # (K, joints, twist)
    u, sigma, _ = np.linalg.svd(J)
    null = u[..., -1]  # (K, 6): the joint motion of the smallest singular value
    largest = np.take_along_axis(null, np.argmax(np.abs(null), axis=-1)[:, None], axis=-1)
    null = null * np.sign(largest)
    top = -np.sort(-np.abs(null), axis=-1)[:, :2]
    coaxial = np.abs(top - np.sqrt(0.5)).max(axis=-1) <= 1e-3
    found = sigma[:, -1] <= FAMILY_CONDITION * sigma[:, 0]
    return found, null, coaxial


class General6RPlan(Sealed):
    """Every solution of a 6-joint arm with no decomposable geometry, 6R or with one slide (5R1P), by the
    elimination of this module."""

    method = "analytic"
    generic_count = 16
    free_joints: list[int] = []

    @classmethod
    def match(cls, geometry: Geometry) -> "General6RPlan | None":
        """The plan for a 6-joint arm of at most one slide, or None for other arms, Pieper-class arms and arms no
        arrangement solves."""
        if geometry.dof != 6 or geometry.kinds().count("P") > 1 or is_pieper(geometry):
            return None
        plan = cls(geometry)
        return plan if plan.arrangement is not None else None

    def __init__(self, geometry: Geometry) -> None:
        model = geometry.model
        self.scale = geometry.length_scale
        self.revolute = model.is_revolute.astype(bool)
        self.structure = GENERAL_6R if self.revolute.all() else GENERAL_5R1P
        self.directions = model.directions / np.linalg.norm(model.directions, axis=1, keepdims=True)
        self.points = model.points / self.scale
        home = model.home.copy()
        home[:3, 3] /= self.scale
        self.home_inverse = invert(home)
        # no tool position is farther than this from the point on axis 1: each turn keeps the distance to a point
        # of its axis, so |x − p_1| ≤ |home − p_6| + Σ |p_i+1 − p_i| (normalised lengths); a slide has no bound
        self.reach = float(np.linalg.norm(home[:3, 3] - self.points[5])
                           + np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum()) \
            if self.revolute.all() else np.inf
        self.arrangement, self.accuracy = self._choose()

    def _choose(self) -> tuple[_Arrangement | None, float]:
        """The arrangement that recovers random configurations best, and its worst error (radians).

        Arrangements are tried in a fixed order and the first that recovers every test configuration to
        :data:`GOOD_ENOUGH` is kept at once (the usual case: planning an inline robot per request stays cheap);
        otherwise the most accurate of the six, if it reaches :data:`PLAN_ACCURACY`.
        """
        rng = np.random.default_rng(20260601)
        q = rng.uniform(-np.pi, np.pi, (6, 6))
        A = chain_motion(self.directions, self.points, self.revolute, q)
        best, best_error = None, np.inf
        for reverse, first in self._arrangements():
            arrangement = _Arrangement(self.directions, self.points, self.revolute, reverse, first)
            if arrangement.left_fit_error > 1e-9:
                continue
            roots = _solve_arrangement(arrangement, A)
            if not roots.conditioned.all():
                continue
            difference = roots.joints - q[:, None, :]
            gap = np.abs(np.where(self.revolute, wrap_angle(difference), difference)).max(axis=-1)
            gap = np.where(roots.valid, gap, np.inf)
            error = float(gap.min(axis=1).max())
            if error < best_error:
                best, best_error = arrangement, error
            if best_error <= GOOD_ENOUGH:
                return best, best_error
        if best_error > PLAN_ACCURACY:
            return None, best_error
        return best, best_error

    def _arrangements(self) -> list[tuple[bool, int]]:
        """(reverse, first) of the arrangements to try: all six, but the ones that make a slide joint d (q_d is
        recovered as a turn about d's axis)."""
        every = [(reverse, first) for reverse in (False, True) for first in (2, 1, 0)]
        slides = np.flatnonzero(~self.revolute)
        return [(reverse, first) for reverse, first in every
                if not len(slides) or (5 - (first + 3) if reverse else first + 3) != slides[0]]

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        n = len(world_T_targets)
        targets = np.array(world_T_targets, dtype=float)
        targets[:, :3, 3] /= self.scale
        A = targets @ self.home_inverse
        roots = _solve_arrangement(self.arrangement, A)
        joints, valid = roots.joints, roots.valid
        rows, slots = np.nonzero(valid)
        if len(rows):
            start = np.nan_to_num(joints[rows, slots])
            joints[rows, slots] = _newton(self.directions, self.points, self.revolute, A[rows], start)
        resolved = self._split_near_pairs(joints, valid, roots.near, A)
        complete = roots.conditioned & (~roots.ambiguous | resolved) & (
            roots.real_count + roots.ambiguous_count <= 16)
        rows, slots = np.nonzero(valid)
        singular = SingularFlags(n)
        if len(rows):  # in normalised lengths, as Newton's steps work
            normalised = None if reference is None else np.where(self.revolute, reference, np.divide(
                reference, self.scale, dtype=float))
            self._represent_singular_roots(joints, valid, rows, slots, A, normalised, singular)
        joints[..., ~self.revolute] *= self.scale
        # out of reach by the bound: certainly no solution, however the eigenproblem was conditioned
        offset = targets[:, :3, 3] - self.points[0]
        beyond = np.einsum("ni,ni->n", offset, offset) > (self.reach * (1.0 + 1e-9)) ** 2
        valid[beyond] = False
        complete[beyond] = True
        return Candidates(joints, valid, singular, complete=complete, promise_needs_every_slot=True)

    def _represent_singular_roots(self, joints: np.ndarray, valid: np.ndarray, rows: np.ndarray, slots: np.ndarray,
                                  A: np.ndarray, reference: np.ndarray | None, singular: SingularFlags) -> None:
        """Roots (``joints[rows, slots]`` of targets ``A``, slides in normalised lengths, as ``reference``) where the
        Jacobian is singular (:func:`_singular_motion`): the target fixes them along the null motion only to about DUPLICATE_TOLERANCE. The condition is reported,
        and the root is represented as the closed forms represent it: with the motion's leading joint at the
        reference value, where Newton's steps with that joint held reach the target; else the root itself.

        * On a family (two coaxial joints, or a self-motion over more: the target is reached a step along the
          motion on both sides) the elimination's roots are arbitrary members (four, 0.004-0.02 rad apart, on a
          raw xArm 7 at q2 = 0): the family has one representative, and its other roots (differing along the
          motion only) are no longer candidates (``valid`` (N, m), in place), so that every valid slot still
          gives a distinct solution (the promise of :meth:`solve` needs it).
        * At a fold two roots meet and stay two slots (the verification merges them if they are one, and the
          promise then falls); the one nearest the reference is moved to it."""
        found, motion, coaxial = _singular_motion(self.directions, self.points, self.revolute, joints[rows, slots])
        if not found.any():
            return
        rows, slots, motion, coaxial = rows[found], slots[found], motion[found], coaxial[found]
        index = np.arange(len(rows))
        pair = np.sort(np.argsort(-np.abs(motion), axis=-1)[:, :2], axis=-1)
        # the leading joint: a coaxial pair's first (as the report says), else the one the motion turns most
        leading = np.where(coaxial, pair[:, 0], np.argmax(np.abs(motion), axis=-1))
        q = joints[rows, slots]
        family = coaxial.copy()
        if not coaxial.all():
            family[~coaxial] = self._on_family(A[rows[~coaxial]], q[~coaxial], motion[~coaxial], leading[~coaxial])
        if not family.all():
            self._split_fold_pairs(joints, valid, rows, slots, A, motion, ~family)
            q = joints[rows, slots]
        if reference is not None:
            along = self._difference(np.asarray(reference, dtype=float)[leading] - q[index, leading],
                                     leading) / motion[index, leading]
            moved = self._along_family(A[rows], q, along[:, None] * motion, leading)
            reached = self._reached(A[rows], moved) & valid[rows, slots]
            # at a fold only the root nearest the reference moves (the other is a root of its own)
            distance = np.abs(self._difference(np.asarray(reference, dtype=float) - q, np.arange(6))).max(axis=1)
            for _, members in _by_target(rows, ~family & valid[rows, slots]):
                reached[members[members != members[np.argmin(distance[members])]]] = False
            joints[rows[reached], slots[reached]] = moved[reached]
        for row, members in _by_target(rows, family):  # one representative per family: the first slot's
            for other, k in itertools.combinations(members.tolist(), 2):
                if not (valid[row, slots[k]] and valid[row, slots[other]]):
                    continue
                step = self._difference(joints[row, slots[k]] - joints[row, slots[other]], np.arange(6))
                across = step - (step @ motion[other]) * motion[other]
                if np.abs(across).max() <= SAME_FAMILY:
                    valid[row, slots[k]] = False
        self._report_singular(singular, rows, motion, coaxial, family, pair, leading)

    def _split_near_pairs(self, joints: np.ndarray, valid: np.ndarray, near: np.ndarray, A: np.ndarray
                          ) -> np.ndarray:
        """Roots neither clearly real nor clearly complex (``near`` (N, m) of ``joints`` (N, m, 6), targets A):
        a conjugate pair about to become two real roots, or two real roots that rounding made complex. Both halves
        were back-substituted from the same real part, so they came out as one point; :meth:`_split_fold_pairs`
        splits them along the Jacobian's null motion there. Returns, per target (N,), whether every such root
        was accounted for: two verified roots apart, or one double root (in place)."""
        rows, slots = np.nonzero(near & valid)
        unresolved = np.zeros(len(near), dtype=bool)
        if len(rows):
            _, motion, _ = _singular_motion(self.directions, self.points, self.revolute, joints[rows, slots])
            done = self._split_fold_pairs(joints, valid, rows, slots, A, motion, np.ones(len(rows), dtype=bool))
            unresolved[rows[~done]] = True
        return ~unresolved

    def _split_fold_pairs(self, joints: np.ndarray, valid: np.ndarray, rows: np.ndarray, slots: np.ndarray,
                          A: np.ndarray, motion: np.ndarray, fold: np.ndarray) -> np.ndarray:
        """Two roots of one target at a fold (``fold`` (K,) of the roots ``joints[rows, slots]``) that came out
        within :data:`FOLD_PAIR` of each other: the elimination and Newton's steps place them only to about
        DUPLICATE_TOLERANCE along the null motion (``motion`` (K, 6)). Newton's steps from :data:`SPLIT_STEP`
        either side of their middle along it, run to :data:`SPLIT_TOLERANCE`, find the two roots where they are
        apart, and replace the pair (in place) when both reach the target and differ by more than
        DUPLICATE_TOLERANCE. Where both reach it within
        DUPLICATE_TOLERANCE of each other the pair is one double root: its middle takes the first slot and the
        second is no longer ``valid`` (N, m), provided the Jacobian is singular there (a simple root's two slots,
        as a near-Pieper arm's two solutions that share q_a give, stay two). Returns which of the K roots were so
        accounted for."""
        every = np.arange(6)
        done = np.zeros(len(rows), dtype=bool)
        for row, members in _by_target(rows, fold):
            for other, k in itertools.combinations(members.tolist(), 2):
                if done[k] or done[other] or not (valid[row, slots[k]] and valid[row, slots[other]]):
                    continue
                first = joints[row, slots[other]]
                step = self._difference(joints[row, slots[k]] - first, every)
                if np.abs(step).max() > FOLD_PAIR:
                    continue
                sides = np.array([[1.0], [-1.0]]) * SPLIT_STEP * motion[other]
                targets = A[[row, row]]
                split = _newton(self.directions, self.points, self.revolute, targets, first + 0.5 * step + sides,
                                steps=SPLIT_NEWTON_STEPS, tolerance=SPLIT_TOLERANCE, rcond=SPLIT_RCOND)
                if not self._reached(targets, split).all():
                    continue
                gap = self._difference(split[0] - split[1], every)
                if np.abs(gap).max() > DUPLICATE_TOLERANCE:
                    joints[row, slots[other]], joints[row, slots[k]] = split
                else:  # one root, and a double one only where the Jacobian is singular: else a root is missing
                    middle = split[1] + 0.5 * gap
                    if not _singular_motion(self.directions, self.points, self.revolute, middle[None])[0][0]:
                        continue
                    joints[row, slots[other]] = middle
                    valid[row, slots[k]] = False
                done[[other, k]] = True
        return done

    def _difference(self, difference: np.ndarray, joints: np.ndarray) -> np.ndarray:
        """Differences of joint values (...,) of ``joints`` (...,): revolute ones wrapped to (−π, π]."""
        return np.where(self.revolute[joints], wrap_angle(difference), difference)

    def _on_family(self, A: np.ndarray, q: np.ndarray, motion: np.ndarray, held: np.ndarray) -> np.ndarray:
        """Which singular roots q (K, 6) lie on a family of solutions: a step of :data:`FAMILY_PROBE` along their
        null motion (K, 6), either way, with joint ``held`` (K,) kept, still reaches the target. At a fold it does
        on one side at most."""
        reached = np.ones(len(q), dtype=bool)
        for sign in (1.0, -1.0):
            moved = _newton(self.directions, self.points, self.revolute, A, q + sign * FAMILY_PROBE * motion,
                            held=held)
            reached &= self._reached(A, moved)
        return reached

    def _reached(self, A: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Whether joint vectors q (K, 6) reach their targets A (K, 4, 4) to Newton's tolerance (with margin)."""
        R, p, _ = _chain_twists(self.directions, self.points, self.revolute, q)
        return np.abs(_error_twist(R, p, A[:, :3, :3], A[:, :3, 3])).max(axis=1) <= 10 * NEWTON_TOLERANCE

    def _along_family(self, A: np.ndarray, q: np.ndarray, change: np.ndarray, held: np.ndarray) -> np.ndarray:
        """Roots q (K, 6) moved by ``change`` (K, 6) along their null motion, in steps of at most
        :data:`FAMILY_STEP` radians, each followed by Newton's steps with joint ``held`` (K,) kept (a family's
        path curves away from its tangent)."""
        steps = max(1, int(np.ceil(np.abs(change).max(initial=0.0) / FAMILY_STEP)))
        for _ in range(steps):
            q = _newton(self.directions, self.points, self.revolute, A, q + change / steps, held=held)
        return q

    @staticmethod
    def _report_singular(singular: SingularFlags, rows: np.ndarray, motion: np.ndarray, coaxial: np.ndarray,
                         family: np.ndarray, pair: np.ndarray, leading: np.ndarray) -> None:
        """The conditions of :meth:`_represent_singular_roots` per target: two coaxial joints (only their sum or
        difference is fixed), a self-motion (relation ``free``) or a fold (``boundary``), with the joints the
        null motion turns."""
        for i, j in {(int(a), int(b)) for a, b in pair[coaxial]}:
            for relation, sign in (("sum", "+"), ("difference", "−")):
                chosen = coaxial & (pair[:, 0] == i) & (pair[:, 1] == j) & (
                    (np.sign(motion[:, i]) != np.sign(motion[:, j])) == (relation == "sum"))
                if chosen.any():
                    singular.add(_rows_mask(singular.count, rows[chosen]), Singularity(
                        "coaxial", (i, j), relation, f"joints {i + 1} and {j + 1} are coaxial here: only "
                        f"q{i + 1} {sign} q{j + 1} is determined; q{i + 1} is set to the reference value where "
                        f"the family reaches the target"))
        moving = np.abs(motion) >= SINGULAR_MOTION
        other = ~coaxial
        for joints, k, on_family in {(tuple(np.flatnonzero(m).tolist()), int(k), bool(f))
                                     for m, k, f in zip(moving[other], leading[other], family[other])}:
            chosen = other & (leading == k) & (family == on_family) & (
                moving == np.isin(np.arange(6), joints)).all(axis=1)
            names = ", ".join(f"q{j + 1}" for j in joints)
            what = (f"a family of solutions passes here (a self-motion of {names})" if on_family else
                    f"the Jacobian is singular here (its null motion turns {names}: two solutions meet, or a family "
                    f"nearly passes), and the target fixes the solution along that motion only to about "
                    f"{DUPLICATE_TOLERANCE:g} rad")
            singular.add(_rows_mask(singular.count, rows[chosen]), Singularity(
                "jacobian", joints, "free" if on_family else "boundary",
                f"{what}; q{k + 1} is set to the reference value where that reaches the target"))

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        return {}


def _rows_mask(count: int, rows: np.ndarray) -> np.ndarray:
    """A boolean mask (count,) true at ``rows``."""
    mask = np.zeros(count, dtype=bool)
    mask[rows] = True
    return mask


def is_pieper(geometry: Geometry) -> bool:
    """Whether three consecutive axes meet in one point or are parallel (Pieper's condition)."""
    for start in range(geometry.dof - 2):
        triple = (start, start + 1, start + 2)
        if geometry.common_point(triple) is not None:
            return True
        if geometry.parallel(start, start + 1) and geometry.parallel(start, start + 2):
            return True
    return False
