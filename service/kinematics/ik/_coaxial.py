"""Coaxial joints: two consecutive revolute joints on one line turn the rest of the chain as one joint.

With ``S_i = ±S_j`` (j = i + 1, the same line, the same or the opposite sense),
``exp([S_i] q_i) exp([S_j] q_j) = exp([S_i] (q_i ± q_j))``: a target fixes only the
sum (or, for reversed axes, the difference) ``σ = q_i ± q_j``, never the split. As
for the free joints of a redundant arm (:mod:`._redundant`), locking joint j at 0
removes it (the locked arm is the same for every value, since joint i carries the
same motion), the locked arm goes to the ordinary plan dispatch, and each of its
solutions ``σ`` is split back with joint j at the reference value (or 0):
``q_j = v``, ``q_i = σ ∓ v``. The answer is complete up to that relation, which
every row reports (kind ``"coaxial"``, relation ``"sum"`` or ``"difference"``), and
joint j is listed among the free joints. A 7-joint arm whose one degree of redundancy
is such a pair is answered the same way, not as a family sampled over a free joint
(``coaxial_redundancy`` in :mod:`._answer`).
"""

from __future__ import annotations

import re

import numpy as np

from .._forward import JointTrig
from .._angles import wrap_angle
from ._structure import Geometry
from ._types import Candidates, LabelCodes, SingularFlags, Singularity, Sealed


def coaxial_pair(geometry: Geometry) -> tuple[int, int, str] | None:
    """The first two consecutive revolute joints (i, i + 1) whose axes are one line, and ``"sum"`` when they point
    the same way (``"difference"`` when opposite); None when there are none."""
    model = geometry.model
    for i in range(geometry.dof - 1):
        j = i + 1
        if not (model.is_revolute[i] and model.is_revolute[j]):
            continue
        if geometry.parallel(i, j) and geometry.on_axis(i, geometry.point(j)):
            same = float(geometry.direction(i) @ geometry.direction(j)) > 0
            return i, j, "sum" if same else "difference"
    return None


def without_joint(geometry: Geometry, joint: int) -> Geometry:
    """The screw model with ``joint`` removed (held at 0: every other screw and the home pose stay as they are)."""
    model = geometry.model
    kept = [k for k in range(geometry.dof) if k != joint]
    reduced = type(model)(model.directions[kept].copy(), model.points[kept].copy(), model.is_revolute[kept].copy(),
                          model.home.copy())
    return Geometry(reduced, geometry.length_scale, up=geometry.up,
                    link_x=None if geometry.link_x is None else geometry.link_x[kept].copy())


def held_split(joints: np.ndarray, pair: tuple[int, int, str], reference: np.ndarray | None) -> np.ndarray:
    """Joint vectors (..., n) with the same ``σ = q_i ± q_j`` and joint j at the reference value (or 0)."""
    first, second, relation = pair
    sign = 1.0 if relation == "sum" else -1.0
    held = 0.0 if reference is None else float(reference[second])
    split = np.array(joints, dtype=float)
    split[..., first] = wrap_angle(joints[..., first] + sign * (joints[..., second] - held))
    split[..., second] = held
    return split


def coaxial_report(pair: tuple[int, int, str]) -> Singularity:
    """The relation a coaxial pair leaves, as every answer of the arm reports it."""
    first, second, relation = pair
    i, j = first + 1, second + 1
    return Singularity("coaxial", (first, second), relation,
                       f"axes {i} and {j} are one line: the target fixes only the {relation} of q{i} and q{j}; q{j} "
                       f"is set to the reference value (or 0)")


class CoaxialPlan(Sealed):
    """The plan of the arm with the second of two coaxial joints removed, answering for the arm itself.

    ``pair`` is ``(i, j, relation)`` of :func:`coaxial_pair`; ``inner`` plans the arm without joint j (n − 1
    joints, joint i carrying ``σ = q_i ± q_j``).
    """

    method = "analytic"

    def __init__(self, inner, pair: tuple[int, int, str], dof: int) -> None:
        self.inner = inner
        self.first, self.second, self.relation = pair
        self.sign = 1.0 if self.relation == "sum" else -1.0
        self.dof = dof
        i, j = self.first + 1, self.second + 1
        self.structure = f"{self._renumbered(inner.structure)} with q{j} free (coaxial with q{i})"
        self.generic_count = inner.generic_count
        self.report = coaxial_report(pair)

    @property
    def free_joints(self) -> list[int]:
        return sorted([self._full_index(k) for k in self.inner.free_joints] + [self.second])

    @property
    def coaxial_held(self) -> list[int]:
        """The joints held at the reference value (or 0) because the target fixes only a coaxial pair's relation:
        joint j, and those of the pairs the inner plan holds (an arm with more than one pair)."""
        return sorted([self._full_index(k) for k in getattr(self.inner, "coaxial_held", [])] + [self.second])

    def _full_index(self, k: int) -> int:
        return k + 1 if k >= self.second else k

    def _reduced(self, joints: np.ndarray) -> np.ndarray:
        """Joint vectors (..., n) of the arm as those (..., n − 1) of the arm without joint j: joint i takes σ."""
        reduced = np.delete(joints, self.second, axis=-1)
        reduced[..., self.first] = wrap_angle(joints[..., self.first] + self.sign * joints[..., self.second])
        return reduced

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        """Candidates (N, m, n) for targets (N, 4, 4): the inner ones with joint j at the reference (or 0)."""
        inner = self.inner.solve(world_T_targets, None if reference is None else self._reduced(reference))
        joints = held_split(np.insert(inner.joints, self.second, 0.0, axis=-1), (self.first, self.second,
                                                                                  self.relation), reference)
        singular = SingularFlags(inner.singularities.count)
        for mask, flag in inner.singularities.entries:
            singular.add(mask, Singularity(flag.kind, tuple(self._full_index(k) for k in flag.joints), flag.relation,
                                           self._renumbered(flag.detail)))
        singular.add(np.ones(singular.count, dtype=bool), self.report)
        return Candidates(joints, inner.valid, singular, inner.complete, inner.promise_needs_every_slot)

    def _renumbered(self, detail: str) -> str:
        """The inner plan's words with the arm's joint numbers (1-based: those from j + 1 on move up by one)."""
        def one_based(match: re.Match) -> str:
            number = int(match.group(2))
            return f"{match.group(1)}{number + 1 if number > self.second else number}"

        return re.sub(r"(\bq|\bjoints? |\baxis |\baxes |\band )(\d+)", one_based, detail)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """The inner plan's labels of joint vectors (M, n)."""
        return self.inner.label_codes(self._reduced(joints))

