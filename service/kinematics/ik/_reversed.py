"""Solving an arm from its tool end: the reversed chain.

With ``world_T_tool = G_1 ⋯ G_n M`` (G_i = exp([S_i] q_i), M the home pose),
``tool_T_world = M⁻¹ G_n⁻¹ ⋯ G_1⁻¹ = G'_1 ⋯ G'_n M⁻¹``, where joint i' = n − 1 − i
of the reversed chain turns about ``−R_Mᵀ ω_i`` through ``M⁻¹ p_i`` (a screw
moved by the adjoint of M⁻¹, the sign making its angle q_i again). Its world
frame is the tool frame at q = 0. A family that matches the reversed chain
(three parallel axes at the base, say, seen as three parallel axes at the end)
solves the inverse target, and the joint order is turned back.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from .._forward import ScrewModel
from ._screws import invert
from ._structure import Geometry
from ._types import Branch, Candidates, LabelCodes, SingularFlags, Singularity, branches_from_codes


def reversed_geometry(geometry: Geometry) -> Geometry:
    """The geometry of the reversed chain (joint i of the result is joint n − 1 − i of ``geometry``)."""
    model = geometry.model
    home_inverse = invert(model.home)
    R = home_inverse[:3, :3]
    directions = -(model.directions[::-1] @ R.T)
    points = model.points[::-1] @ R.T + home_inverse[:3, 3]
    reversed_model = ScrewModel(np.ascontiguousarray(directions), np.ascontiguousarray(points),
                                model.is_revolute[::-1].copy(), home_inverse)
    return Geometry(reversed_model, geometry.length_scale, up=R @ geometry.up, link_x=None)


class ReversedPlan:
    """A plan of the reversed chain, answering for the arm as described."""

    method = "analytic"

    def __init__(self, inner, structure: str, label_codes: Callable[[np.ndarray], LabelCodes]) -> None:
        self.inner = inner
        self._label_codes = label_codes
        self.structure = structure
        self.generic_count = inner.generic_count
        self.dof = inner.geometry.dof
        self.free_joints = [self.dof - 1 - j for j in inner.free_joints]

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        inner = self.inner.solve(invert(world_T_targets), None if reference is None else reference[::-1])
        singular = SingularFlags(inner.singularities.count)
        n = self.dof
        for mask, flag in inner.singularities.entries:
            singular.add(mask, Singularity(flag.kind, tuple(sorted(n - 1 - j for j in flag.joints)), flag.relation,
                                           f"{flag.detail} (axes numbered from the tool)"))
        return Candidates(inner.joints[..., ::-1], inner.valid, [], singular)

    def labels(self, joints: np.ndarray) -> list[Branch]:
        return branches_from_codes(self.label_codes(joints), len(joints))

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        """Labels computed on the arm as described (the reversed chain's up and sides are the tool's)."""
        return self._label_codes(joints)
