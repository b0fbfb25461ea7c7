"""Records that IK solvers produce: candidates, singularities and the result."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

Branch = dict[str, str | int]
Status = Literal["ok", "unreachable"]


@dataclass(frozen=True)
class Singularity:
    """A singular condition met by a target.

    ``joints`` are 0-based joint indices. ``relation`` states what is still
    determined: ``"sum"`` or ``"difference"`` (only q_i ± q_j is fixed),
    ``"free"`` (the joint does not affect the target), ``"stretched"`` /
    ``"folded"`` (an elbow at the edge of its range), ``"aligned"`` or
    ``"coincident"`` (the RRR group's special cases).
    """

    kind: str
    joints: tuple[int, ...]
    relation: str
    detail: str = ""


@dataclass
class Candidates:
    """Joint vectors proposed by a solver for a batch of targets.

    ``joints`` has shape (N, m, n): m candidate slots for each of N targets;
    ``valid`` (N, m) says which slots hold a candidate. ``branches`` gives
    the labels of each slot, per target: a list of N lists of m dicts (built
    lazily by the family's labeller). ``singularities`` lists, per target, the
    singular conditions met.
    """

    joints: np.ndarray
    valid: np.ndarray
    branches: list[list[Branch]]
    singularities: list[list[Singularity]]


@dataclass(frozen=True)
class Solution:
    """One verified IK solution."""

    joints: np.ndarray
    branch: Branch
    position_residual: float
    orientation_residual: float
    singular: bool = False


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
