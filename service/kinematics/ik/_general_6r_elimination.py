"""The general solver's elimination: for one *arrangement* of a 6-joint arm (6R, or with one slide), every
root of the Raghavan–Roth equations for a batch of targets, as Manocha and Canny solve them (a 24 × 24
eigenproblem per target), back-substituted into joint vectors. :mod:`._general_6r` chooses the arrangement per
robot, polishes the roots and decides what is complete.

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
    q_e, q_f from the linear right-hand monomials; q_d from the remaining rotation.
"""

from __future__ import annotations

import numpy as np

from .._forward import cross
from ._screws import axis_frame, chain_motion, chain_rotation, invert, joint_motion

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


def _fourteen(p: np.ndarray, l: np.ndarray) -> np.ndarray:
    """Raghavan and Roth's 14 quantities of a point p and unit direction l (..., 3): (..., 14)."""
    pp = np.einsum("...i,...i->...", p, p)[..., None]
    pl = np.einsum("...i,...i->...", p, l)[..., None]
    return np.concatenate([p, l, pp, pl, cross(p, l), l * pp - 2.0 * p * pl], axis=-1)


class Arrangement:
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
        self.powers = np.kron(_HALF if self.kinds[1] else np.eye(3), _HALF if self.kinds[2] else np.eye(3))
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


class Roots:
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


def solve_arrangement(arr: Arrangement, A: np.ndarray) -> Roots:
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
        condition = _eigenvalue_conditions(vectors[rows])
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
    return Roots(joints, valid, real_count, near, ambiguous_count, rank_ok & lead_ok, shift)


def _slide_interval(arr: Arrangement, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _eigenvalue_conditions(vectors: np.ndarray) -> np.ndarray:
    """Each eigenvalue's condition number ‖l_i‖ ‖v_i‖, shape (R, k), from the right eigenvectors (R, k, k) as
    columns, the left ones being the rows of their inverse. Where a target's eigenvectors are dependent (a
    defective eigenvalue, as a degenerate arm gives: every link 1e-12 long), no eigenvalue of it has a finite
    bound: its conditions are inf, so each complex root near the axis counts as ambiguous."""
    right = np.linalg.norm(vectors, axis=1)
    try:
        return np.linalg.norm(np.linalg.inv(vectors), axis=2) * right
    except np.linalg.LinAlgError:  # one singular matrix fails the whole stack: target by target
        conditions = np.full(right.shape, np.inf)
        for row, matrix in enumerate(vectors):
            try:
                conditions[row] = np.linalg.norm(np.linalg.inv(matrix), axis=1) * right[row]
            except np.linalg.LinAlgError:
                pass
        return conditions


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


def _last_joint(arr: Arrangement, A: np.ndarray, chain: np.ndarray) -> np.ndarray:
    """q_d from the rotation left over once the other five joints are known (chain as read)."""
    q = np.zeros(chain.shape[:-1] + (6,))
    a = arr.first
    for slot, joint in enumerate((a, a + 1, a + 2, a + 3, *arr.rhs)):
        q[..., joint] = chain[..., slot]
    d = a + 3
    before = slice(0, d)
    R_d = np.swapaxes(chain_rotation(arr.directions[before], arr.revolute[before], q[..., before]), -1, -2) \
        @ A[:, None, :3, :3]
    if d < 5:
        after = slice(d + 1, 6)
        R_d = R_d @ np.swapaxes(chain_rotation(arr.directions[after], arr.revolute[after], q[..., after]), -1, -2)
    # the angle about axis d from R_d's turn of the frame's first unit vector
    first, second, _ = axis_frame(arr.directions[d]).T.copy()
    turned = R_d @ first
    return np.arctan2(turned @ second, turned @ first)

