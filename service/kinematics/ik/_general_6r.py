"""Every solution of a general 6R arm, or of a 6-joint arm with one slide: the Raghavan–Roth elimination solved as
Manocha and Canny solve it.

The work is in three modules:

* :mod:`._general_6r_elimination`: the Raghavan–Roth equations of one *arrangement* of the loop, their
  elimination to a 24 × 24 eigenproblem per target, and the back-substitution of its real roots;
* :mod:`._general_6r_chain`: the chain in normalised lengths, Newton's steps that polish the roots, and the
  Jacobian's null motion at a singular root;
* this module: the plan, which keeps the arrangement that recovers random configurations most accurately,
  polishes every root by Newton's method on the screw model's FK (the shared verification, FK residual and
  merging, then decides what is kept), and decides what is complete and how a singular root is represented and
  reported.

Completeness
    A target's answer is complete only when the algebra accounts for every solution: the right-hand coefficients
    have full rank 8, the leading matrix is well conditioned, at most 16 roots are real or ambiguous, every
    ambiguous eigenvalue (an imaginary part within :data:`~._general_6r_elimination.AMBIGUITY_FACTOR` times its
    first-order error bound: a root pair about to merge or split) is accounted for, and (checked after verification)
    every real root gave one distinct verified solution. Both halves of an ambiguous pair are back-substituted from
    their common real part and split along the Jacobian's null motion there: they count when they verify as two
    solutions, or as one double root where the Jacobian is singular (a fold: listed once, and reported). Anything
    else is answered with ``complete: false``. A 6R arm's target farther from axis 1 than the arm's reach bound is a
    certain ``unreachable`` (complete) whatever the conditioning (a slide has no such bound).
Singular roots
    Where the Jacobian at a verified root is singular to within :data:`~._general_6r_chain.FAMILY_CONDITION`, the
    target fixes the root along the null motion only to about DUPLICATE_TOLERANCE: the singularity is reported (two
    coaxial joints, a self-motion, or a fold where two roots meet), and the root is moved along that motion to the
    reference's value of its leading joint where that still reaches the target, as the closed forms hold a free
    joint (see :meth:`General6RPlan._represent_singular_roots`). Two roots at a fold that Newton's steps left within
    :data:`FOLD_PAIR` of each other are split again; where they meet within DUPLICATE_TOLERANCE they are one double
    root, listed once (on five general arms at det J = 0, before this, 197 of 525 requests went to the numeric
    search, and an exact double root was listed twice, 1e-6…5e-6 apart).

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

from .._forward import JointTrig
from .._angles import wrap_angle
from .._tolerances import DUPLICATE_TOLERANCE
from ._general_6r_chain import NEWTON_TOLERANCE, chain_twists, error_twist, newton, singular_motion
from ._general_6r_elimination import Arrangement, solve_arrangement
from ._screws import chain_motion, invert
from ._structure import Geometry
from ._types import Candidates, LabelCodes, Sealed, SingularFlags, Singularity

#: The plan's structure names: a 6R arm, and one with a slide.
GENERAL_6R = "general_6r"
GENERAL_5R1P = "general_5r1p"
GENERAL_STRUCTURES = (GENERAL_6R, GENERAL_5R1P)


#: The worst error (radians) in recovering random configurations before polishing that a plan accepts.
PLAN_ACCURACY = 1e-4
#: An arrangement this accurate on the test configurations is taken without trying the others.
GOOD_ENOUGH = 1e-10

#: Two roots of a family (singular roots, see :data:`~._general_6r_chain.FAMILY_CONDITION`) differ along its null
#: motion; across it, by no more than this (radians): the xArm's four differed by 1.4e-5 in q2, where the
#: Jacobian's σ_min is ~1e-8 of σ_max.
SAME_FAMILY = 1e-4
#: A family's representative is reached from a root in steps of at most this (radians) along its null motion.
FAMILY_STEP = 0.2
#: The most such steps: a turn needs fewer (its way is at most π / |its share of the unit motion| ≤ π√6, 39
#: steps); only a slide's way, in normalised lengths, can be longer, and it is taken in longer steps.
MAX_FAMILY_STEPS = 64
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


def _by_target(rows: np.ndarray, chosen: np.ndarray) -> Iterator[tuple[int, np.ndarray]]:
    """The ``chosen`` (K,) roots grouped by target: (target, the indices of its chosen roots), ``rows`` (K,) being
    each root's target."""
    for row in np.unique(rows[chosen]).tolist():
        yield row, np.flatnonzero((rows == row) & chosen)



class General6RPlan(Sealed):
    """Every solution of a 6-joint arm with no decomposable geometry, 6R or with one slide (5R1P), by the
    elimination of this module."""

    method = "analytic"
    generic_count = 16
    free_joints: list[int] = []
    #: ~0.3–0.6 ms a target in a batch: chunks of 256 keep each under ~0.15 s (the request's budget is checked
    #: between chunks) and spread a few hundred targets over the threads (2,000 targets of the xArm 6 on two
    #: threads: 0.30 ms a target against 0.62 in one chunk of 2,000; 6,000: 0.27 against 0.25 in two of 3,000)
    targets_per_chunk = 256

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

    def _choose(self) -> tuple[Arrangement | None, float]:
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
            arrangement = Arrangement(self.directions, self.points, self.revolute, reverse, first)
            if arrangement.left_fit_error > 1e-9:
                continue
            roots = solve_arrangement(arrangement, A)
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
        roots = solve_arrangement(self.arrangement, A)
        joints, valid = roots.joints, roots.valid
        rows, slots = np.nonzero(valid)
        if len(rows):
            start = np.nan_to_num(joints[rows, slots])
            joints[rows, slots] = newton(self.directions, self.points, self.revolute, A[rows], start)
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
        Jacobian is singular (:func:`~._general_6r_chain.singular_motion`): the target fixes them along the null
        motion only to about DUPLICATE_TOLERANCE. The condition is reported, and the root is represented as the
        closed forms represent it: with the motion's leading joint at the reference value, where Newton's steps
        with that joint held reach the target; else the root itself.

        * On a family (two coaxial joints, or a self-motion over more: the target is reached a step along the
          motion on both sides) the elimination's roots are arbitrary members (four, 0.004-0.02 rad apart, on a
          raw xArm 7 at q2 = 0): the family has one representative, and its other roots (differing along the
          motion only) are no longer candidates (``valid`` (N, m), in place), so that every valid slot still
          gives a distinct solution (the promise of :meth:`solve` needs it).
        * At a fold two roots meet and stay two slots (the verification merges them if they are one, and the
          promise then falls); the one nearest the reference is moved to it."""
        found, motion, coaxial = singular_motion(self.directions, self.points, self.revolute, joints[rows, slots])
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
            _, motion, _ = singular_motion(self.directions, self.points, self.revolute, joints[rows, slots])
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
        # the pairs as the scan meets them: both valid, within FOLD_PAIR (a pair whose root an earlier pair
        # replaced is skipped below, so each pair's roots and step are as the scan would find them)
        pairs = []
        for row, members in _by_target(rows, fold):
            for other, k in itertools.combinations(members.tolist(), 2):
                if valid[row, slots[k]] and valid[row, slots[other]]:
                    step = self._difference(joints[row, slots[k]] - joints[row, slots[other]], every)
                    if np.abs(step).max() <= FOLD_PAIR:
                        pairs.append((row, other, k, step))
        if not pairs:
            return done
        # Newton's steps from both sides of every pair's middle in one run (each candidate's steps are its own)
        pair_rows = np.array([row for row, *_ in pairs])
        middles = np.array([joints[row, slots[other]] + 0.5 * step for row, other, _, step in pairs])
        sides = SPLIT_STEP * motion[[other for _, other, _, _ in pairs]]
        starts = np.stack([middles + sides, middles - sides], axis=1).reshape(-1, 6)
        targets = A[np.repeat(pair_rows, 2)]
        split = newton(self.directions, self.points, self.revolute, targets, starts, steps=SPLIT_NEWTON_STEPS,
                       tolerance=SPLIT_TOLERANCE, rcond=SPLIT_RCOND)
        reached = self._reached(targets, split).reshape(-1, 2).all(axis=1)
        for (row, other, k, _), halves, both_reached in zip(pairs, split.reshape(-1, 2, 6), reached.tolist()):
            if done[k] or done[other] or not both_reached:
                continue
            gap = self._difference(halves[0] - halves[1], every)
            if np.abs(gap).max() > DUPLICATE_TOLERANCE:
                joints[row, slots[other]], joints[row, slots[k]] = halves
            else:  # one root, and a double one only where the Jacobian is singular: else a root is missing
                middle = halves[1] + 0.5 * gap
                if not singular_motion(self.directions, self.points, self.revolute, middle[None])[0][0]:
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
            moved = newton(self.directions, self.points, self.revolute, A, q + sign * FAMILY_PROBE * motion,
                            held=held)
            reached &= self._reached(A, moved)
        return reached

    def _reached(self, A: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Whether joint vectors q (K, 6) reach their targets A (K, 4, 4) to Newton's tolerance (with margin)."""
        R, p, _ = chain_twists(self.directions, self.points, self.revolute, q)
        return np.abs(error_twist(R, p, A[:, :3, :3], A[:, :3, 3])).max(axis=1) <= 10 * NEWTON_TOLERANCE

    def _along_family(self, A: np.ndarray, q: np.ndarray, change: np.ndarray, held: np.ndarray) -> np.ndarray:
        """Roots q (K, 6) moved by ``change`` (K, 6) along their null motion, in steps of at most
        :data:`FAMILY_STEP` radians, each followed by Newton's steps with joint ``held`` (K,) kept (a family's
        path curves away from its tangent), and at most :data:`MAX_FAMILY_STEPS` of them: a longer way (a slide's
        reference far along the motion, as an arm of 1e-11 links with a slide metres out asks) is taken in longer
        steps, and where they miss the target the caller keeps the root. A change that is not finite moves
        nothing."""
        change = np.where(np.isfinite(change).all(axis=1, keepdims=True), change, 0.0)
        steps = min(max(1, int(np.ceil(np.abs(change).max(initial=0.0) / FAMILY_STEP))), MAX_FAMILY_STEPS)
        for _ in range(steps):
            q = newton(self.directions, self.points, self.revolute, A, q + change / steps, held=held)
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
