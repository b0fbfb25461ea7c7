"""Records that IK solvers produce: candidates, singularities and the result."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

Branch = dict[str, str | int]
Status = Literal["ok", "unreachable", "not_found"]

#: Branch labels as arrays: label name → (its values, codes of shape (M,) indexing them; −1 where the label
#: does not apply to a row, e.g. where its two branches meet).
LabelCodes = dict[str, tuple[tuple[str | int, ...], np.ndarray]]


@dataclass(frozen=True)
class Singularity:
    """A singular condition met by a target.

    ``joints`` are 0-based joint indices. ``relation`` states what is still
    determined: ``"sum"`` or ``"difference"`` (only q_i ± q_j is fixed),
    ``"free"`` (the joint does not affect the target), ``"stretched"`` /
    ``"folded"`` (an elbow at the edge of its range), ``"boundary"`` (two
    solutions meet: a fold), ``"aligned"`` or ``"coincident"`` (the RRR
    group's special cases; ``"aligned"`` also a spherical wrist whose axes
    nearly align, where q_a is fixed only within a band).
    """

    kind: str
    joints: tuple[int, ...]
    relation: str
    detail: str = ""


class SingularFlags:
    """The singular conditions met by a batch of N targets, one boolean mask (N,) per condition.

    Reads like a list of N lists: ``flags[row]`` is the list of distinct
    :class:`Singularity` records met by target ``row``, in the order they
    were added. Solvers add whole masks, so no Python loop runs over targets.
    """

    def __init__(self, count: int) -> None:
        self.count = count
        self.entries: list[tuple[np.ndarray, Singularity]] = []

    def add(self, mask: np.ndarray, singularity: Singularity) -> None:
        """Flag ``singularity`` on every target where ``mask`` (N,) is true."""
        mask = np.asarray(mask, dtype=bool)
        if mask.any():
            self.entries.append((mask, singularity))

    def extend(self, other: "SingularFlags", rows: np.ndarray | None = None) -> None:
        """Add every condition of ``other``; ``rows`` (N,) maps its rows onto these when it has fewer."""
        for mask, singularity in other.entries:
            self.add(mask if rows is None else mask[rows], singularity)

    def take(self, rows: np.ndarray) -> "SingularFlags":
        """The conditions of targets ``rows`` (indices or a boolean mask), renumbered in that order."""
        rows = np.asarray(rows)
        taken = SingularFlags(int(rows.sum()) if rows.dtype == bool else len(rows))
        for mask, singularity in self.entries:
            taken.add(mask[rows], singularity)
        return taken

    @classmethod
    def concat(cls, parts: list["SingularFlags"]) -> "SingularFlags":
        """The conditions of several groups of targets laid end to end."""
        joined = cls(sum(part.count for part in parts))
        offset = 0
        for part in parts:
            for mask, singularity in part.entries:
                full = np.zeros(joined.count, dtype=bool)
                full[offset:offset + part.count] = mask
                joined.add(full, singularity)
            offset += part.count
        return joined

    def any(self) -> np.ndarray:
        """Which targets meet at least one condition, shape (N,)."""
        flagged = np.zeros(self.count, dtype=bool)
        for mask, _ in self.entries:
            flagged |= mask
        return flagged

    def __len__(self) -> int:
        return self.count

    def __getitem__(self, row: int) -> list[Singularity]:
        met: list[Singularity] = []
        for mask, singularity in self.entries:
            if mask[row] and singularity not in met:
                met.append(singularity)
        return met

    def __iter__(self):
        return (self[row] for row in range(self.count))


@dataclass
class Candidates:
    """Joint vectors proposed by a solver for a batch of targets.

    ``joints`` has shape (N, m, n): m candidate slots for each of N targets;
    ``valid`` (N, m) says which slots hold a candidate. ``singularities``
    gives, per target, the singular conditions met (the family's
    ``label_codes`` labels the slots).

    ``complete`` (N,), when a solver gives it, says which targets it can
    promise every solution for; None means every target is complete, as for
    the exact closed-form families (see :mod:`._idealised` and
    :mod:`._general_6r` for the solvers that say less). With
    ``promise_needs_every_slot`` the promise holds only *provided* each valid
    slot then verifies as a distinct solution (the verification checks that
    part): the general solver's valid slots are roots, not least-squares
    candidates.

    ``labels`` are the slots' branch labels (name → (values, codes (N, m))), computed by the family from the
    candidates it proposes, so that nothing about the call stays on the plan. None while a family still labels
    through its plan's ``label_codes``.

    ``near_singular`` (N, m), when a family gives it, marks the slots it solved within :data:`NEAR_SINGULAR` of
    a singular set, where a step reads an angle off a short radius and amplifies the errors of the others: the
    verification checks that each one kept is an isolated solution, and where one is not, on a target the family
    flagged nothing for, the promise is withdrawn (:func:`._verify.not_isolated`).
    """

    joints: np.ndarray
    valid: np.ndarray
    singularities: SingularFlags
    complete: np.ndarray | None = None
    promise_needs_every_slot: bool = False
    labels: LabelCodes | None = None
    near_singular: np.ndarray | None = None


#: How near a singular set a family marks a slot for the isolation check (:attr:`Candidates.near_singular`),
#: relative: a spherical wrist's volume (the sine that aligns its outer axes), a point's distance from the axis
#: that reads an angle off it over the arm's size. Where two singular sets meet, the errors of the steps before
#: over that short radius leave solutions that FK cannot tell apart: the catalogue's PUMA with its shoulder
#: solutions 2.3e-6 rad apart and q5 2.6e-8 from 0 listed one 0.8 rad (in q4 and q6) from the pose's own, the
#: Jacobian's least singular value 2e-16 there; a UR3e folded within 6e-7 rad at q5 1.3e-9 from π, 1.2e-3 rad.
#: The check withdraws a promise only under :data:`._verify.ISOLATED_BELOW`, which a solution near one set alone
#: does not reach.
NEAR_SINGULAR = 1e-3


@dataclass(frozen=True)
class Solution:
    """One verified IK solution."""

    joints: np.ndarray
    branch: Branch
    position_residual: float
    orientation_residual: float


@dataclass
class IKResult:
    """Every solution found for one target, and how they were found."""

    status: Status
    solutions: list[Solution]
    method: Literal["analytic", "numeric"]
    structure: str
    complete: bool
    singularities: list[Singularity] = field(default_factory=list)
    free_joints: list[int] = field(default_factory=list)
    detail: str = ""
    search_exhausted_budget: bool = False


#: The ``targets_per_chunk`` of the lean families (a decoupled plan, and the UR type with axes 2–4 parallel and
#: axes 5 and 6 meeting: a few dozen numbers of temporaries per target), twice :data:`~._closed_form.CHUNK`. On
#: 10,000 and 50,000 targets it answered 10–15 % faster per pose for about 10 % more peak memory; the general 6R,
#: whose elimination matrices are large, ran slower and used 75 % more memory at that size, so it keeps the
#: default, as do the plans not measured (the skew-wrist UR type) and those that wrap another (idealised, reversed,
#: coaxial).
LEAN_CHUNK = 8192


def every(mask: np.ndarray) -> bool:
    """``mask.all()`` at a quarter of its fixed cost (``np.count_nonzero`` skips a reduction's setup): the one-pose
    paths ask it of arrays of one or a few entries, where that cost is all there is."""
    return np.count_nonzero(mask) == mask.size


class Sealed:
    """An object that concurrent requests share once built (a plan and its parts): attributes are set while it
    is built, and :meth:`seal` ends that. Setting one afterwards (per-call state kept on a shared object) raises
    AttributeError. A ``functools.cached_property`` stays allowed: it writes the instance's dict directly, a value
    derived from what was built, the same whichever call computes it first."""

    _sealed = False

    def seal(self):
        """Seal this object and every :class:`Sealed` object it holds (its positioner, wrist, inner plan);
        returns it."""
        if not self._sealed:
            object.__setattr__(self, "_sealed", True)
            for value in vars(self).values():
                if isinstance(value, Sealed):
                    value.seal()
        return self

    def __setattr__(self, name: str, value) -> None:
        if self._sealed:
            raise AttributeError(f"{type(self).__name__} is shared once built: {name!r} cannot be set on it")
        object.__setattr__(self, name, value)
