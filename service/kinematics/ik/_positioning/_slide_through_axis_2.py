"""The Stanford and polar arms' shoulder: an intersecting shoulder whose third joint slides normal to axis 2
along a line crossing it, solved together with the shoulder (:class:`SlideThroughAxis2`).

From the reach alone, as the general slide of :class:`~._intersecting_shoulder.IntersectingShoulder` solves it,
the slide's value near the crossing is known only to the square root of the target's rounding, and without its
sign; this frame keeps it to the target's rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._forward import cross
from ..._angles import wrap_angle
from ..._tolerances import ACCEPT_RESIDUAL, GEOMETRY_TOLERANCE, POLISH_RESIDUAL
from .._screws import rotate_about
from .._structure import Geometry, target_error
from .._types import NEAR_SINGULAR, SingularFlags, Singularity
from ..subproblems import subproblem_1
from ._base import PositionerResult, _flag_rows


@dataclass(frozen=True)
class SlideThroughAxis2:
    """The frame of an intersecting shoulder whose third joint slides normal to axis 2 along a line crossing it.

    With c the shoulder's centre, k1 and k2 its axes (angle α between them) and v the slide (world
    frame, q = 0), the point ``w + s v`` is ``c + h k2 + t v`` with ``t = s − foot``. Joint 2 keeps
    ``h k2`` and turns v in the plane normal to k2, spanned by ``n1`` (k1's part in it, unit) and
    ``n2 = k2 × n1``: ``R(k2, q2) v = cos ψ n1 + sin ψ n2`` with ``ψ = q2 + psi0``. Only ``n1`` has a
    part along k1 (``sin α``), so a target y (from c) has ``k1·y = h cos α + t sin α cos ψ`` and
    ``‖y‖² = h² + t²``. The Stanford arm (h = d2, α = 90°) and the polar arms (h = 0).
    """

    height: float  #: h, the crossing's distance from c along k2 (signed)
    foot: float  #: the slide's value at the crossing
    n1: np.ndarray  #: (3,)
    n2: np.ndarray  #: (3,)
    psi0: float  #: ψ at q2 = 0, radians
    cos_alpha: float
    sin_alpha: float

    @classmethod
    def of(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray
           ) -> "SlideThroughAxis2 | None":
        """The frame when joints (i, j, k) are that shoulder and slide and ``point`` (3,) is on the slide's line."""
        i, j, k = joints
        if geometry.model.is_revolute[k]:
            return None
        k1, k2, v = geometry.direction(i), geometry.direction(j), geometry.direction(k)
        offset = point - centre
        crossing_miss = abs(float(offset @ cross(k2, v)))
        if abs(float(v @ k2)) > GEOMETRY_TOLERANCE or crossing_miss > GEOMETRY_TOLERANCE * geometry.length_scale:
            return None
        cos_alpha = float(k1 @ k2)
        n1 = k1 - cos_alpha * k2
        sin_alpha = float(np.linalg.norm(n1))
        n1 = n1 / sin_alpha
        n2 = cross(k2, n1)
        return cls(float(offset @ k2), -float(offset @ v), n1, n2, float(np.arctan2(v @ n2, v @ n1)), cos_alpha,
                   sin_alpha)

    def reach(self, height, radius, rounding) -> tuple:
        """What a target y (from c) gives in this frame, from its ``height`` along axis 1, its ``radius`` from it
        and its ``rounding`` (arrays, or floats for the one-pose path): ``B`` (``along``), ``|h sin α − B cos α|``
        (``inner``), ``a² = radius² − inner²`` (a difference only where ±a meet) and the bands of B and of a²."""
        along = (height - self.height * self.cos_alpha) / self.sin_alpha
        inner = abs(self.height * self.sin_alpha - along * self.cos_alpha)
        across_squared = (radius - inner) * (radius + inner)
        band_along = rounding / self.sin_alpha
        return along, inner, across_squared, band_along, 2 * rounding * (radius + inner + band_along)

    def solve(self, geometry: Geometry, joints: tuple[int, ...], centre: np.ndarray, targets: np.ndarray,
              reference: np.ndarray | None) -> PositionerResult:
        """The shoulder and its slide together (see the class for the frame and the equations): the joints
        (i, j, k) of ``geometry`` about ``centre`` (3,), the shoulder's axes' crossing.

        ``targets`` (N, 3) in the world self. The slide's displacement from the crossing, ``t u`` with
        ``u = R(k2, q2) v``, is ``B n1 + a n2``: ``B`` follows from the target's height along axis 1 (first
        order in t), ``a`` only through ``a² = ‖y‖² − h² − B²`` (the fold where the two shoulder solutions
        ±a meet). Then ``q2 = atan2(a, B) − ψ0`` with ``t = +‖(B, a)‖``, or ``q2 + π`` with ``−t``, and q1
        turns ``h k2 + t u`` onto the target (subproblem 1). Solving t from the reach alone, as the
        general slide does, loses the sign of t and every digit of it below ``√ε`` of the arm's size;
        this keeps B to the target's rounding, and the target does not determine a or B better than
        their rounding bands: where the reference's values lie in those bands they are taken (the
        representative nearest the reference), and where the whole displacement is within them the point
        is on axis 2 and joint 2 is free (reference value or 0).
        """
        g, (i, j, k) = geometry, joints
        k1, n_targets = g.direction(i), len(targets)
        y = targets - centre  # (N, 3)
        height = y @ k1
        radius = np.linalg.norm(y - height[:, None] * k1, axis=-1)  # from axis 1
        h = self.height
        # the target's coordinates carry rounding relative to their size and the arm's, and the arm's own deviation
        # from this frame's relations (a URDF's nine digits: 1e-11) times the same lever: a point that close to
        # axis 1 is on it as far as the frame can tell (its azimuth would come from that error, and the orientation
        # that fixes q1 of a polar arm's pose would be missed)
        rounding = target_error(g, np.linalg.norm(targets, axis=-1))
        along, inner, across_squared, band_along, band_squared = self.reach(height, radius, rounding)  # (N,) each
        met = across_squared <= band_squared  # the two shoulder solutions ±a meet: a = 0 represents them
        free = met & (np.abs(along) <= band_along)  # the point on axis 2: joint 2 does not move it
        # the point within half the acceptance of the centre (an arm without shoulder offset): every q1, q2
        # reaches it, and the position fixes them only to rounding over that distance, worse than the
        # acceptance (≥ rounding / 1e-9 > 1e-5 of the arm's size): it is treated as at the centre, both free
        at_centre = np.linalg.norm(y, axis=-1) <= 0.5 * ACCEPT_RESIDUAL * g.length_scale
        met |= at_centre
        free |= at_centre
        across = np.where(met, 0.0, np.sqrt(np.maximum(across_squared, 0.0)))
        first_sign = np.ones(n_targets)
        free_angle = self.psi0 + (0.0 if reference is None else reference[j])
        if reference is not None:
            t_ref = reference[k] - self.foot
            along_ref, across_ref = t_ref * np.cos(free_angle), t_ref * np.sin(free_angle)
            along = np.where(np.abs(along - along_ref) <= band_along, along_ref, along)
            in_band = np.abs(across_ref * across_ref - across_squared) <= band_squared
            across = np.where(in_band, abs(across_ref), across)
            first_sign = np.where(in_band & (across_ref < 0), -1.0, 1.0)
        across_pair = np.stack([first_sign * across, -first_sign * across], axis=-1)  # (N, 2)
        psi = np.where(free[:, None], free_angle, np.arctan2(across_pair, along[:, None]))  # (N, 2)
        t = along[:, None] * np.cos(psi) + across_pair * np.sin(psi)  # the displacement along u(ψ)
        psi = np.stack([psi, psi + np.pi], axis=-1)  # (N, 2 shoulder, 2 slide signs)
        t = np.stack([t, -t], axis=-1)
        turned = h * g.direction(j) + t[..., None] * (np.cos(psi)[..., None] * self.n1
                                                      + np.sin(psi)[..., None] * self.n2)
        # likewise a point within half the acceptance of axis 1 (every q1 reaches it), or so near it that its
        # azimuth, known to the target's error over that radius, is known worse than the polish can mend: the
        # orientation that fixes q1 of a three-joint arm's pose would be missed
        on_first_axis = np.maximum(rounding / POLISH_RESIDUAL, 0.5 * ACCEPT_RESIDUAL * g.length_scale)
        first = subproblem_1(k1, turned, y[:, None, None, :], free_below=on_first_axis[:, None, None])
        q1 = first.theta[..., 0]
        free_first = first.degenerate | at_centre[:, None, None]  # the target on axis 1 (a polar arm without offset)
        if reference is not None:  # an azimuth seen on a radius r is known to rounding / r
            band_first = rounding[:, None, None] / np.maximum(radius[:, None, None], 1e-300)
            q1 = np.where(free_first | (np.abs(wrap_angle(q1 - reference[i])) <= band_first), reference[i], q1)
        else:
            q1 = np.where(free_first, 0.0, q1)
        joints = np.stack([q1, wrap_angle(psi - self.psi0), self.foot + t], axis=-1)
        # exact to the arm's size (subproblem 1 measures against the point's own, tiny near the centre); a free q1
        # misses by up to twice the point's radius, within its band: the orientation may set it, the FK check
        # judges
        miss = np.linalg.norm(rotate_about(k1, q1, turned) - y[:, None, None, :], axis=-1)
        valid = (miss <= GEOMETRY_TOLERANCE * g.length_scale) | free_first
        valid[:, 1, :] &= ~met[:, None]  # −a is +a
        valid[..., 1] &= ~free[:, None]  # −t with ψ + π is t with ψ when joint 2 is free
        singular = SingularFlags(n_targets)
        both = free & free_first.any(axis=(1, 2))
        _flag_rows(both, Singularity("shoulder", (i, j), "free", "the point is at the shoulder's centre; joints "
                                     "1 and 2 are set to the reference values (or 0)"), singular)
        _flag_rows(free & ~both, Singularity("shoulder", (j,), "free", "the point is on axis 2 (the slide at "
                                             "its nearest reach); joint 2 is set to the reference value (or 0)"),
                   singular)
        _flag_rows(free_first.any(axis=(1, 2)) & ~both, Singularity(
            "shoulder", (i,), "free", "the point is on the first joint's axis; joint 1 is set to the reference "
                                      "value (or 0)"), singular)
        _flag_rows(met & ~free, Singularity("shoulder", (i, j), "boundary", "the two shoulder solutions meet: the "
                                            "point is as near axis 1 as the shoulder allows"), singular)
        _flag_rows(free, Singularity("reach", (k,), "boundary",
                                     "the point is at the nearest reach of the prismatic joint"), singular)
        # q1 is read off the target's radius about axis 1, q2 off the point's distance from axis 2 (the slide's)
        near = NEAR_SINGULAR * g.length_scale
        near_axes = (np.abs(t) <= near) | (radius <= near)[:, None, None]
        return PositionerResult(joints.reshape(n_targets, 4, 3), valid.reshape(n_targets, 4), singular,
                                near_axes.reshape(n_targets, 4))
