"""A spherical wrist (or any decoupling point, or three parallel axes) at the base: solve the inverse chain.

``world_T_tool = G_1(q_1) ⋯ G_n(q_n) · home`` inverts to
``home · tool_T_world = G_n(q_n)⁻¹ ⋯ G_1(q_1)⁻¹ = G'_1(q_n) ⋯ G'_n(q_1) · I``, where joint
``i' = n − 1 − i`` of the reversed chain has joint i's axis (or slide) negated through the same
point and home pose I. A wrist whose three axes meet at the base is the reversed chain's wrist at
its end, so every decoupled plan (positioner + wrist) applies to it unchanged. Targets are
inverted on the way in; joint vectors, free joints and singular joints are reversed on the way out.
"""

from __future__ import annotations

import re
from typing import Callable

import numpy as np

from .._forward import JointTrig, ScrewModel
from ._decoupled import DecoupledPlan
from ._screws import invert
from ._structure import Geometry
from ._types import Candidates, LabelCodes, SingularFlags, Singularity, Sealed


def reversed_geometry(geometry: Geometry) -> Geometry:
    """The inverse chain's geometry: joints in reverse order, each axis negated, home pose the identity."""
    model = geometry.model
    reversed_model = ScrewModel(-model.directions[::-1].copy(), model.points[::-1].copy(),
                                model.is_revolute[::-1].copy(), np.eye(4))
    return Geometry(reversed_model, geometry.length_scale, up=geometry.up)


class ReversedPlan(Sealed):
    """A plan of the inverse chain (decoupled, or three parallel axes), answering for the chain itself."""

    method = "analytic"

    def __init__(self, inner: DecoupledPlan, home: np.ndarray, dof: int, *, structure: str | None = None,
                 label_codes: Callable[[np.ndarray], LabelCodes] | None = None) -> None:
        """``structure`` names the class when the inner one's name does not read in reverse (default: the
        inner parts in the chain's own order, the wrist at the base first); ``label_codes`` labels joint
        vectors (M, n) of the chain itself where the inner labels would not keep their meaning (default: the
        inner ones)."""
        self.inner = inner
        self.home = home
        self.dof = dof
        self.structure = structure or "+".join(reversed(inner.structure.split("+")))
        self.generic_count = inner.generic_count
        self.own_label_codes = label_codes

    @property
    def free_joints(self) -> list[int]:
        return sorted(self.dof - 1 - j for j in self.inner.free_joints)

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        """Candidates (N, m, n) for targets (N, 4, 4)."""
        inverse_targets = self.home @ invert(world_T_targets)
        inner = self.inner.solve(inverse_targets, None if reference is None else reference[::-1])
        singular = SingularFlags(inner.singularities.count)
        for mask, flag in inner.singularities.entries:
            singular.add(mask, self._renumbered(flag))
        return Candidates(inner.joints[..., ::-1].copy(), inner.valid, singular)

    def _renumbered(self, flag: Singularity) -> Singularity:
        """The inverse chain's singularity with the chain's joint numbers (0-based in ``joints``, 1-based in text)."""
        n = self.dof

        def one_based(match: re.Match) -> str:
            return f"{match.group(1)}{n + 1 - int(match.group(2))}"

        def span(match: re.Match) -> str:  # "axes 2–4" of the inverse chain are "axes 3–5" of the chain
            return f"axes {n + 1 - int(match.group(2))}–{n + 1 - int(match.group(1))}"

        detail = re.sub(r"\baxes (\d+)–(\d+)", span, flag.detail)
        detail = re.sub(r"(\bq|\bjoints? |\baxis )(\d+)", one_based, detail)
        return Singularity(flag.kind, tuple(sorted(n - 1 - j for j in flag.joints)), flag.relation, detail)

    def wrist_volume(self, joints: np.ndarray) -> np.ndarray | None:
        """The inverse chain's :meth:`DecoupledPlan.wrist_volume` at joint vectors (..., n) of the chain itself
        (its wrist at the base)."""
        return self.inner.wrist_volume(joints[..., ::-1])

    def positioning_jacobian(self, joints: np.ndarray, size: float) -> np.ndarray | None:
        """The inverse chain's :meth:`DecoupledPlan.positioning_jacobian` at joint vectors (..., n) of the chain
        itself (its positioning joints are the chain's last three)."""
        return self.inner.positioning_jacobian(joints[..., ::-1], size)

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """The inverse chain's labels (its wrist flip and its positioner's branches) of joint vectors (M, n)."""
        if self.own_label_codes is not None:
            return self.own_label_codes(joints, trig)
        return self.inner.label_codes(joints[:, ::-1])
