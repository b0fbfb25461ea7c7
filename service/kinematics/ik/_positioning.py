"""Positioning arms: the first joints of a chain placing one point.

Each positioner solves ``x = exp([S_1] q_1) ⋯ exp([S_k] q_k) · w`` for the
joint values that carry a point ``w`` (given at q = 0, world frame) to
targets ``x`` (N, 3), by reducing it to geometric subproblems. Each class is
named after the family it solves and states its equations. Results are
vectorised over the N targets: candidate slots of shape (N, m, k) with a
validity mask, plus per-target singular flags.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .._tolerances import (ACCEPT_RESIDUAL, DUPLICATE_TOLERANCE, FOLD_TOLERANCE, GEOMETRY_TOLERANCE,
                          RECOGNITION_TOLERANCE, ROUNDING_TOLERANCE)
from .._rotations import wrap_angle
from ._screws import chain_motion, chain_rotation, move_point, rotate_about
from ._structure import Geometry
from .subproblems import (
    prismatic_to_distance,
    prismatic_to_plane,
    subproblem_1,
    subproblem_2_chain,
    subproblem_3,
    subproblem_4,
    subproblem_5,
    subproblem_5_prismatic,
)
from ._types import LabelCodes, SingularFlags, Singularity


@dataclass
class PositionerResult:
    """Candidate joint values for the positioning joints.

    ``joints`` (N, m, k); ``valid`` (N, m); ``singularities`` a list of N lists.
    """

    joints: np.ndarray
    valid: np.ndarray
    singularities: SingularFlags = field(default_factory=lambda: SingularFlags(0))


def _unit(v: np.ndarray) -> np.ndarray | None:
    norm = np.linalg.norm(v)
    return v / norm if norm > GEOMETRY_TOLERANCE else None


def side_codes(side: np.ndarray, size: np.ndarray) -> np.ndarray:
    """One label code per row (M,) from the sign of ``side`` (M,): 0 (the label's first value) when above 0, else 1.

    Where ``|side| <= DUPLICATE_TOLERANCE * size`` the row sits where its two
    branches meet (a stretched or folded elbow, aligned Assur links, a wrist
    point at the shoulder's boundary): the label does not apply (−1).
    """
    codes = np.where(side > 0, 0, 1).astype(np.int8)
    codes[np.abs(side) <= DUPLICATE_TOLERANCE * size] = -1
    return codes


def _flag_rows(flags: np.ndarray, template: Singularity, rows: SingularFlags) -> None:
    rows.add(flags, template)


class Positioner:
    """Base class: the joints it moves, its generic solution count and its labels."""

    name: str = ""
    generic_count: int = 0
    #: joints the target never determines (structurally free): set to the reference value or 0
    free_joints: tuple[int, ...] = ()

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> None:
        self.geometry = geometry
        self.joints = joints
        self.point = np.asarray(point, dtype=float)
        self.model = geometry.model

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        raise NotImplementedError

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        """The same labels as arrays: name → (values, codes (M,), −1 where the label is left out)."""
        return {}

    def _moved(self, q: np.ndarray, upto: int, x: np.ndarray) -> np.ndarray:
        """exp([S_1] q_1) ⋯ exp([S_upto] q_upto) applied to the point x (3,), for joint values (..., n)."""
        m = self.model
        return move_point(m.directions[:upto], m.points[:upto], m.is_revolute[:upto], q[..., :upto], x)

    def _motion(self, q: np.ndarray, upto: int) -> np.ndarray:
        """exp([S_1] q_1) ⋯ exp([S_upto] q_upto) for joint values (..., n)."""
        m = self.model
        return chain_motion(m.directions[:upto], m.points[:upto], m.is_revolute[:upto], q[..., :upto])


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
        crossing_miss = abs(float(offset @ np.cross(k2, v)))
        if abs(float(v @ k2)) > GEOMETRY_TOLERANCE or crossing_miss > GEOMETRY_TOLERANCE * geometry.length_scale:
            return None
        cos_alpha = float(k1 @ k2)
        n1 = k1 - cos_alpha * k2
        sin_alpha = float(np.linalg.norm(n1))
        n1 = n1 / sin_alpha
        n2 = np.cross(k2, n1)
        return cls(float(offset @ k2), -float(offset @ v), n1, n2, float(np.arctan2(v @ n2, v @ n1)), cos_alpha,
                   sin_alpha)


class IntersectingShoulder(Positioner):
    """Revolute joints 1 and 2 with intersecting axes, then a revolute or prismatic joint 3.

    The elbow arm (with or without shoulder offset), the Stanford and polar
    arms, and the PUMA's first three joints. With c the intersection point,
    joint 2 turns about an axis through c, so ``‖x − c‖ = ‖exp([S_3] q_3) w − c‖``
    depends on q_3 alone: subproblem 3 (revolute) or a quadratic (prismatic),
    up to 2 roots. Then ``R(ω1, q1) R(ω2, q2) (w_3 − c) = x − c`` is
    subproblem 2, up to 2 roots: 4 in all.

    When joint 3 turns about an axis through the point or through c (the
    spherical wrist placing its tool point), subproblem 3 is degenerate for
    every target: q_3 does not change ‖w_3 − c‖, the target does not determine
    it, and it is a free joint (reference value or 0); 2 solutions remain.

    A slide normal to axis 2 whose line crosses it (the Stanford and polar arms) is solved together with
    the shoulder instead (:meth:`_solve_slide_through_axis_2`): from the reach alone its value near the
    crossing is known only to the square root of the target's rounding, and without its sign.

    Labels: ``shoulder`` left/right is the sign of the arm's reach along the
    forward direction of link 1 (the textbook's left/right arm; "front" is left);
    ``elbow`` up/down (revolute joint 3) is the side of the shoulder–point line
    the elbow lies on, seen along the up-pointing axis 1. See :meth:`labels`.
    """

    name = "intersecting_shoulder"
    generic_count = 4
    #: the frame of a slide normal to axis 2 through it (the Stanford and polar arms), else None
    slide_through_axis_2: SlideThroughAxis2 | None = None

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "IntersectingShoulder | None":
        if len(joints) != 3 or geometry.kinds(joints)[:2] != "RR":
            return None
        i, j, _ = joints
        centre = geometry.intersection(i, j)
        if centre is None:
            return None
        solver = cls(geometry, joints, point)
        solver.centre = centre
        k = joints[2]
        if geometry.model.is_revolute[k] and (geometry.on_axis(k, solver.point) or geometry.on_axis(k, centre)):
            solver.free_joints = (k,)  # subproblem 3 is degenerate for every target
            solver.generic_count = 2
        solver.slide_through_axis_2 = SlideThroughAxis2.of(geometry, joints, solver.point, centre)
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        if self.slide_through_axis_2 is not None:
            return self._solve_slide_through_axis_2(targets, reference)
        c, w = self.centre, self.point
        n_targets = len(targets)
        reach = np.linalg.norm(targets - c, axis=-1)
        if g.model.is_revolute[k]:
            third = subproblem_3(g.direction(k), w - g.point(k), c - g.point(k), reach)
            q3 = third.theta
            if self.free_joints:  # degenerate: the representative is the reference value (or 0), not SP3's 0
                q3 = np.where(third.valid, 0.0 if reference is None else reference[k], q3)
            w3 = g.point(k) + rotate_about(g.direction(k), q3, w - g.point(k))
        else:
            third = prismatic_to_distance(w, g.direction(k), c, reach)
            q3 = third.s
            w3 = w + g.direction(k) * q3[..., None]
        pair = subproblem_2_chain(g.direction(i), g.direction(j), w3 - c, (targets - c)[:, None, :])
        q1, q2 = pair.theta1, pair.theta2  # (N, 2 third roots, 2 pair roots)
        singular = SingularFlags(n_targets)
        # subproblem 2 is degenerate when the target is on axis 1 (joint 1 free), or when the point is on axis 2
        # (joint 2 free: an elbow that lines the point up with it, as the stretched elbow of a 7R arm does)
        reach_scale = np.maximum(reach[:, None], np.linalg.norm(w3 - c, axis=-1))  # (N, 2)
        on_axis_1 = (np.linalg.norm(np.cross(g.direction(i), targets - c), axis=-1)[:, None]
                     <= GEOMETRY_TOLERANCE * reach_scale)
        free_shoulder = pair.degenerate & on_axis_1  # (N, 2)
        free_second = (pair.degenerate | self._near_axis_2_at_fold(third, w3 - c, reach_scale)) & ~on_axis_1
        if free_second.any():  # joint 2 at the reference value (or 0); joint 1 turns the point so placed
            q2_held = np.where(free_second, 0.0 if reference is None else reference[j], q2[..., 0])
            turned = rotate_about(g.direction(j), q2_held, w3 - c)
            q1_held = subproblem_1(g.direction(i), turned, (targets - c)[:, None, :]).theta[..., 0]
            q1 = np.where(free_second[..., None], q1_held[..., None], q1)
            q2 = np.where(free_second[..., None], q2_held[..., None], q2)
        _flag_rows(free_second.any(axis=1), Singularity(
            "shoulder", (j,), "free", "the point is on the second joint's axis; joint 2 is set to the reference "
                                      "value (or 0)"), singular)
        free_both = np.zeros_like(free_shoulder)
        if free_shoulder.any():
            start = 0.0 if reference is None else reference[i]
            back = rotate_about(g.direction(i), -start, (targets - c)[:, None, :])
            second = subproblem_1(g.direction(j), w3 - c, back)
            # the point at the shoulder centre itself (zero-length links): joint 2 is free as well
            free_both = free_shoulder & second.degenerate
            q2_free = np.where(free_both, 0.0 if reference is None else reference[j], second.theta[..., 0])
            _flag_rows(free_both.any(axis=1), Singularity(
                "shoulder", (i, j), "free", "the point is at the shoulder's centre; joints 1 and 2 are set to the "
                                            "reference values (or 0)"), singular)
            q1 = np.where(free_shoulder[..., None], start, q1)
            q2 = np.where(free_shoulder[..., None], q2_free[..., None], q2)
        joints = np.zeros((n_targets, 2, 2, 3))
        joints[..., 0], joints[..., 1] = q1, q2
        joints[..., 2] = q3[:, :, None]
        # a near tangency (merged, not exact) is the touching root: verification refines it
        valid = third.valid[:, :, None] & third.exact[:, :, None] & (
            (pair.valid & (pair.exact | pair.merged[..., None])) | free_second[..., None])
        valid[:, :, 1] &= ~(free_shoulder | free_second)  # one representative when a shoulder joint is free
        _flag_rows(free_shoulder.any(axis=1) & ~free_both.any(axis=1),
                   Singularity("shoulder", (i,), "free", "the point is on the first joint's axis; "
                               "joint 1 is set to the reference value (or 0)"), singular)
        _flag_rows((pair.merged & ~free_shoulder & third.valid & third.exact).any(axis=1),
                   Singularity("shoulder", (i, j), "boundary", "the two shoulder solutions meet: the point is as "
                               "near axis 1 as the shoulder allows"), singular)
        if g.model.is_revolute[k] and third.merged.any():  # (no elbow flag to set otherwise)
            stretched = self._stretched(q3[:, 0], w, c)
            _flag_rows(third.merged & stretched, Singularity("elbow", (k,), "stretched",
                                                             "the arm is fully stretched"), singular)
            _flag_rows(third.merged & ~stretched, Singularity("elbow", (k,), "folded",
                                                              "the arm is fully folded"), singular)
        elif not g.model.is_revolute[k]:
            _flag_rows(third.merged, Singularity("reach", (k,), "boundary",
                                                 "the point is at the nearest reach of the prismatic joint"), singular)
        return PositionerResult(joints.reshape(n_targets, 4, 3), valid.reshape(n_targets, 4), singular)

    def _solve_slide_through_axis_2(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        """The Stanford and polar arms: a slide normal to axis 2 whose line crosses axis 2 (see
        :class:`SlideThroughAxis2` for the frame and the equations).

        ``targets`` (N, 3) in the world frame. The slide's displacement from the crossing, ``t u`` with
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
        g, (i, j, k) = self.geometry, self.joints
        frame = self.slide_through_axis_2
        k1, n_targets = g.direction(i), len(targets)
        y = targets - self.centre  # (N, 3)
        height = y @ k1
        radius = np.linalg.norm(y - height[:, None] * k1, axis=-1)  # from axis 1
        h = frame.height
        along = (height - h * frame.cos_alpha) / frame.sin_alpha  # B (N,)
        # a² = ‖y‖² − h² − B² = radius² − (h sin α − B cos α)²: a difference only where ±a meet
        inner = np.abs(h * frame.sin_alpha - along * frame.cos_alpha)
        across_squared = (radius - inner) * (radius + inner)  # (N,)
        # the target's coordinates carry rounding relative to their size and the arm's
        rounding = ROUNDING_TOLERANCE * (g.length_scale + np.linalg.norm(targets, axis=-1))
        band_along = rounding / frame.sin_alpha
        band_squared = 2 * rounding * (radius + inner + band_along)
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
        free_angle = frame.psi0 + (0.0 if reference is None else reference[j])
        if reference is not None:
            t_ref = reference[k] - frame.foot
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
        turned = h * g.direction(j) + t[..., None] * (np.cos(psi)[..., None] * frame.n1
                                                      + np.sin(psi)[..., None] * frame.n2)
        first = subproblem_1(k1, turned, y[:, None, None, :], free_below=rounding[:, None, None])
        q1 = first.theta[..., 0]
        free_first = first.degenerate | at_centre[:, None, None]  # the target on axis 1 (a polar arm without offset)
        if reference is not None:  # an azimuth seen on a radius r is known to rounding / r
            band_first = rounding[:, None, None] / np.maximum(radius[:, None, None], 1e-300)
            q1 = np.where(free_first | (np.abs(wrap_angle(q1 - reference[i])) <= band_first), reference[i], q1)
        else:
            q1 = np.where(free_first, 0.0, q1)
        joints = np.stack([q1, wrap_angle(psi - frame.psi0), frame.foot + t], axis=-1)
        # exact to the arm's size (subproblem 1 measures against the point's own, tiny near the centre)
        miss = np.linalg.norm(rotate_about(k1, q1, turned) - y[:, None, None, :], axis=-1)
        valid = miss <= GEOMETRY_TOLERANCE * g.length_scale
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
        return PositionerResult(joints.reshape(n_targets, 4, 3), valid.reshape(n_targets, 4), singular)

    def _near_axis_2_at_fold(self, third, point: np.ndarray, scale: np.ndarray) -> np.ndarray:
        """Which points (N, 2) joint 2 cannot place: within ``FOLD_TOLERANCE`` of axis 2 (relative to
        ``scale`` (N, 2)), from a joint-3 root pair that is as close to meeting (its roots ``phi ± half``,
        ``|half| <= FOLD_TOLERANCE``, or merged). There joint 3 is known only to the square root of the
        decoupling's error (a reach through axes that intersect within ``GEOMETRY_TOLERANCE``), the point
        ``point`` (N, 2, 3) to as much, and joint 2's angle to that over the point's radius: an O(1) error. Joint 2
        is held like a free one, and verification refines the representative onto the arm."""
        g, j = self.geometry, self.joints[1]
        if not g.model.is_revolute[self.joints[2]]:
            return np.zeros(point.shape[:2], dtype=bool)
        half = 0.5 * np.abs(wrap_angle(third.theta[:, 0] - third.theta[:, 1]))
        at_fold = third.merged | (np.nan_to_num(half, nan=0.0) <= FOLD_TOLERANCE)  # (N,)
        radius = np.linalg.norm(np.cross(g.direction(j), point), axis=-1)
        return at_fold[:, None] & (radius <= FOLD_TOLERANCE * scale)

    def _stretched(self, q3: np.ndarray, w: np.ndarray, c: np.ndarray) -> np.ndarray:
        g, k = self.geometry, self.joints[2]
        at = g.point(k) + rotate_about(g.direction(k), q3, w - g.point(k))
        opposite = g.point(k) + rotate_about(g.direction(k), q3 + np.pi, w - g.point(k))
        return np.linalg.norm(at - c, axis=-1) >= np.linalg.norm(opposite - c, axis=-1)

    def _offset(self) -> np.ndarray | None:
        """The shoulder offset at q = 0, shape (3,): the point's displacement from the centre along axis 2.

        Joint 2 keeps that component, and so does joint 3 when it turns about an
        axis parallel to axis 2 or slides perpendicular to it (the elbow, PUMA,
        Stanford and polar arms). None when it is zero or not constant.
        """
        g, (_, j, k) = self.geometry, self.joints
        axis = g.direction(j)
        constant = g.parallel(j, k) if g.model.is_revolute[k] \
            else abs(float(g.direction(k) @ axis)) <= GEOMETRY_TOLERANCE
        along = float((self.point - self.centre) @ axis)
        if not constant or abs(along) <= GEOMETRY_TOLERANCE * g.length_scale:
            return None
        return along * axis

    def _forward_direction(self) -> np.ndarray:
        """Link 1's forward direction at q = 0, perpendicular to axis 1: it decides left (front) from right (back).

        * With a shoulder offset (the PUMA, the Stanford arm, textbook §3.3),
          forward is ``offset × up``: the left arm is the one whose offset lies to
          the left of its reach, seen from above. This is a property of the
          arm, the same in every description of it (textbook §3.3: left arm
          θ1 = φ − atan2(d, u0), reach u = +u0 along x1, offset +d along y1).
        * Without an offset the arm is mirror-symmetric and the textbook's
          "front" is a convention of its frames: θ1 = atan2(yc, xc) puts the
          wrist centre along x1 (§3.2, §3.4). Forward is then the x axis of link
          frame 1 at q = 0.
        """
        g, (i, j, _) = self.geometry, self.joints
        axis = g.direction(i)
        offset = self._offset()
        if offset is not None:
            forward = _unit(np.cross(offset, g.upward(axis)))
            if forward is not None:
                return forward
        if g.link_x is not None:
            forward = _unit(g.link_x[i] - (g.link_x[i] @ axis) * axis)
            if forward is not None:
                return forward
        normal = _unit(np.cross(axis, g.direction(j)))
        return normal if normal is not None else self.point - self.centre

    @cached_property
    def label_constants(self) -> tuple[np.ndarray, bool, np.ndarray]:
        """What :meth:`label_codes` needs of the geometry alone, computed once per plan: link 1's forward
        direction at q = 0, whether axes 2 and 3 are parallel, and the up-pointing axis 1."""
        g, (i, j, k) = self.geometry, self.joints
        return self._forward_direction(), bool(g.parallel(j, k)), g.upward(g.direction(i))

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        """Shoulder left/right: the sign of the reach along link 1's forward direction (see
        :meth:`_forward_direction`); none when the point is on axis 1. Elbow up/down (revolute joint 3,
        unless it is free): the side of the shoulder–point line the elbow lies on, along the robot's up
        direction, measured in the arm's plane (normal to axis 2) when axes 2 and 3 are parallel, so that
        the choice of point on axis 3 does not matter. With the point on axis 1 the line is vertical and
        the front configuration's limit is used (textbook §3.2: front, θ3 < 0 is up: the elbow behind).
        """
        g, (i, j, k) = self.geometry, self.joints
        forward_home, in_plane, up = self.label_constants
        forward = rotate_about(g.direction(i), joints[:, i], forward_home)
        point = self._moved(joints, k + 1, self.point)
        reach = point - self.centre
        axis = g.direction(i)
        sideways = reach - np.outer(reach @ axis, axis)
        on_axis = np.linalg.norm(sideways, axis=-1) <= GEOMETRY_TOLERANCE * 10 * g.length_scale
        along = np.einsum("mi,mi->m", reach, forward)
        # on axis 1 (the shoulder singularity) front and back are one family, and at the boundary
        # (the point as near axis 1 as the offset allows) left and right meet: no shoulder label
        codes: LabelCodes = {"shoulder": (("left", "right"), side_codes(along, np.linalg.norm(reach, axis=-1)))}
        if g.model.is_revolute[k] and not self.free_joints:
            elbow = self._moved(joints, k, g.point(k)) - self.centre
            if in_plane:  # work in the arm's plane, normal to axis 2
                m = self.model
                normal = np.einsum("mij,j->mi", chain_rotation(m.directions[:j], m.is_revolute[:j], joints[:, :j]),
                                   g.direction(j))
                elbow = elbow - np.einsum("mi,mi->m", elbow, normal)[:, None] * normal
                reach = reach - np.einsum("mi,mi->m", reach, normal)[:, None] * normal
            line = reach / np.maximum(np.linalg.norm(reach, axis=-1, keepdims=True), 1e-300)
            rejection = elbow - np.einsum("mi,mi->m", elbow, line)[:, None] * line
            side = rejection @ up
            # line along axis 1: "above" is undefined; take the limit from the front (the elbow behind is up)
            side = np.where(on_axis, -(line @ up) * np.einsum("mi,mi->m", elbow, forward), side)
            codes["elbow"] = (("up", "down"), side_codes(side, np.linalg.norm(elbow, axis=-1)))
        return codes


def _common_normal_feet(p1: np.ndarray, d1: np.ndarray, p2: np.ndarray, d2: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """The points of two non-parallel lines (point, unit direction) nearest each other: the common normal's feet."""
    w = p1 - p2
    b, d, e = float(d1 @ d2), float(d1 @ w), float(d2 @ w)
    denominator = 1.0 - b * b
    s, t = (b * e - d) / denominator, (e - b * d) / denominator
    return p1 + s * d1, p2 + t * d2


def _slot_grid(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Slots (N, m1·m2) from the outer product of two slot sets (N, m1) and (N, m1, m2)."""
    return np.broadcast_to(first[:, :, None], second.shape).reshape(len(first), -1)


class OffsetShoulderParallelElbow(Positioner):
    """Joint 1, then revolute joint 2 with a revolute joint 3 parallel to it (or a slide normal to it).

    The ortho-parallel basis of the KUKA KR and Quantec, ABB IRB 140/6700, Fanuc LR Mate and
    Yaskawa arms (Brandstötter et al. 2014, "OPW"), and any arm whose axes 2 ∥ 3 are offset from
    axis 1 at any angle: IK-Geo's ``spherical_two_parallel`` positioner. Joints 2 and 3 keep the
    point's height along their common direction u, so with y the target with joint 1 undone,
    ``u·y = u·w``: subproblem 4 for a revolute joint 1 (two roots: front and back), linear for a
    prismatic one. In the plane normal to u it is the planar two-link arm: the distance from axis
    2 to y fixes joint 3 (subproblem 3, elbow up and down; a quadratic for a slide) and joint 2
    follows by subproblem 1. Four solutions in all (two with a prismatic joint 1).

    Labels (revolute joints 1 and 3): ``shoulder`` left/right is the sign of the point's reach from
    axis 1 along link 1's forward direction, the direction of the shoulder offset (the common
    normal from axis 1 to axis 2): front is left, as for :class:`IntersectingShoulder`. ``elbow``
    up/down is the side of the line from the shoulder (axis 2's foot of that normal) to the point
    on which the elbow (axis 3) lies, along the robot's up direction, in the arm's plane.
    """

    name = "offset_shoulder_parallel_elbow"
    generic_count = 4

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray
              ) -> "OffsetShoulderParallelElbow | None":
        if len(joints) != 3 or not geometry.model.is_revolute[joints[1]]:
            return None
        i, j, k = joints
        u = geometry.direction(j)
        if geometry.model.is_revolute[k]:
            if not geometry.parallel(j, k) or geometry.on_axis(k, np.asarray(point, dtype=float)):
                return None
        elif abs(float(geometry.direction(k) @ u)) > GEOMETRY_TOLERANCE:
            return None
        if geometry.model.is_revolute[i]:
            if geometry.parallel(i, j):
                return None
        elif abs(float(geometry.direction(i) @ u)) <= GEOMETRY_TOLERANCE:
            return None
        solver = cls(geometry, joints, point)
        if geometry.model.is_revolute[i]:
            shoulder_on_1, solver.shoulder = _common_normal_feet(geometry.point(i), geometry.direction(i),
                                                                 geometry.point(j), u)
            offset = solver.shoulder - shoulder_on_1
            solver.forward = _unit(offset - (offset @ geometry.direction(i)) * geometry.direction(i))
        else:
            solver.generic_count, solver.shoulder, solver.forward = 2, geometry.point(j), None
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        u, w, n_targets = g.direction(j), self.point, len(targets)
        if g.model.is_revolute[i]:
            o = g.point(i)
            # u·R(k1, −q1)(x − o) = u·(w − o): subproblem 4 for −q1
            first = subproblem_4(u, g.direction(i), targets - o, np.full(n_targets, float(u @ (w - o))))
            q1 = -first.theta
            if first.degenerate.any():  # the target on axis 1: joint 1 free
                q1 = np.where(first.degenerate[:, None], 0.0 if reference is None else reference[i], q1)
            y = o + rotate_about(g.direction(i), -q1, (targets - o)[:, None, :])  # (N, 2, 3)
        else:
            first = prismatic_to_plane(u, targets, -g.direction(i), np.full(n_targets, float(u @ w)))
            q1 = first.s
            y = targets[:, None, :] - q1[..., None] * g.direction(i)
        in_plane, elbow_to_point, elbow_to_shoulder = self._plane_constants
        reach = np.linalg.norm((y - g.point(j)) @ in_plane, axis=-1)  # (N, m1)
        if g.model.is_revolute[k]:
            third = subproblem_3(g.direction(k), elbow_to_point, elbow_to_shoulder, reach)
            q3 = third.theta  # (N, m1, 2)
            w3 = g.point(k) + rotate_about(g.direction(k), q3, w - g.point(k))
        else:
            third = prismatic_to_distance(in_plane @ (w - g.point(j)), g.direction(k), np.zeros(3), reach)
            q3 = third.s
            w3 = w + q3[..., None] * g.direction(k)
        second = subproblem_1(u, w3 - g.point(j), y[:, :, None, :] - g.point(j))
        q2 = second.theta[..., 0]
        if second.degenerate.any():  # the point on axis 2 (the elbow folded onto it)
            q2 = np.where(second.degenerate, 0.0 if reference is None else reference[j], q2)
        m = q3.shape[1] * 2
        joints = np.empty((n_targets, m, 3))
        joints[..., 0] = _slot_grid(q1, q3)
        joints[..., 1] = q2.reshape(n_targets, m)
        joints[..., 2] = q3.reshape(n_targets, m)
        first_ok = first.valid & first.exact
        if g.model.is_revolute[i]:
            first_ok[:, 1] &= ~first.degenerate
        valid = (first_ok[:, :, None] & third.valid & third.exact & second.exact[..., 0]).reshape(n_targets, m)
        singular = SingularFlags(n_targets)
        if g.model.is_revolute[i]:
            _flag_rows(first.degenerate, Singularity("shoulder", (i,), "free", "the point is on the first "
                                                     "joint's axis; joint 1 is set to the reference value (or 0)"),
                       singular)
            _flag_rows(first.merged, Singularity("shoulder", (i,), "boundary", "the point is as near axis 1 as "
                                                 "the shoulder offset allows: front and back meet"), singular)
        merged = (third.merged & first_ok).any(axis=1)
        if g.model.is_revolute[k] and merged.any():  # (no elbow flag to set otherwise)
            folded = self._folded(q3[:, :, 0])
            _flag_rows((third.merged & first_ok & ~folded).any(axis=1),
                       Singularity("elbow", (k,), "stretched", "the arm is fully stretched"), singular)
            _flag_rows((third.merged & first_ok & folded).any(axis=1),
                       Singularity("elbow", (k,), "folded", "the arm is fully folded"), singular)
        elif not g.model.is_revolute[k]:
            _flag_rows(merged, Singularity("reach", (k,), "boundary",
                                           "the point is at the nearest reach of the prismatic joint"), singular)
        _flag_rows((second.degenerate & first_ok[:, :, None]).any(axis=(1, 2)),
                   Singularity("elbow", (j,), "free", "the point is on axis 2; joint 2 is set to the reference "
                               "value (or 0)"), singular)
        return PositionerResult(joints, valid, singular)

    @cached_property
    def _plane_constants(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The projector onto the arm's plane (normal to axis 2), and in it the point and axis 2 seen from axis 3."""
        g, (_, j, k) = self.geometry, self.joints
        u = g.direction(j)
        in_plane = np.eye(3) - np.outer(u, u)
        return in_plane, in_plane @ (self.point - g.point(k)), in_plane @ (g.point(j) - g.point(k))

    def _folded(self, q3: np.ndarray) -> np.ndarray:
        """Whether joint 3 at q3 brings the point nearer axis 2 than its opposite turn (the folded elbow)."""
        g, (_, j, k) = self.geometry, self.joints
        u = g.direction(j)
        in_plane = np.eye(3) - np.outer(u, u)
        at = g.point(k) + rotate_about(g.direction(k), q3, self.point - g.point(k))
        opposite = g.point(k) + rotate_about(g.direction(k), q3 + np.pi, self.point - g.point(k))
        return (np.linalg.norm((at - g.point(j)) @ in_plane, axis=-1)
                < np.linalg.norm((opposite - g.point(j)) @ in_plane, axis=-1))

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        g, (i, j, k) = self.geometry, self.joints
        if not (g.model.is_revolute[i] and g.model.is_revolute[k]) or self.forward is None:
            return {}
        axis = g.direction(i)
        point = self._moved(joints, k + 1, self.point)
        reach = point - g.point(i)
        reach = reach - np.outer(reach @ axis, axis)
        forward = rotate_about(axis, joints[:, i], self.forward)
        codes: LabelCodes = {"shoulder": (("left", "right"), side_codes(np.einsum("mi,mi->m", reach, forward),
                                                                       np.linalg.norm(point - g.point(i), axis=-1)))}
        shoulder = self._moved(joints, i + 1, self.shoulder)
        normal = rotate_about(axis, joints[:, i], g.direction(j))
        elbow = self._moved(joints, k, g.point(k)) - shoulder
        line = point - shoulder
        elbow = elbow - np.einsum("mi,mi->m", elbow, normal)[:, None] * normal
        line = line - np.einsum("mi,mi->m", line, normal)[:, None] * normal
        line = line / np.maximum(np.linalg.norm(line, axis=-1, keepdims=True), 1e-300)
        rejection = elbow - np.einsum("mi,mi->m", elbow, line)[:, None] * line
        codes["elbow"] = (("up", "down"), side_codes(rejection @ g.upward(axis), np.linalg.norm(elbow, axis=-1)))
        return codes


class OffsetShoulderIntersectingElbow(Positioner):
    """Joint 1 (revolute or prismatic), then revolute joints 2 and 3 whose axes meet at a point c.

    IK-Geo's ``spherical_two_intersecting`` positioner. Joints 2 and 3 turn about axes through c,
    so the point keeps its distance from c: ``‖x − G₁ c‖ = ‖w − c‖`` fixes joint 1 (subproblem 3
    for a revolute joint, a quadratic for a slide: two roots), and then
    ``R(ω₂, q₂) R(ω₃, q₃)(w − c) = y − c``, with y the target with joint 1 undone, is subproblem
    2 (two roots): four solutions. No textbook names its branches, so it gives no labels.
    """

    name = "offset_shoulder_intersecting_elbow"
    generic_count = 4

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray
              ) -> "OffsetShoulderIntersectingElbow | None":
        if len(joints) != 3 or geometry.kinds(joints)[1:] != "RR":
            return None
        i, j, k = joints
        centre = geometry.intersection(j, k)
        point = np.asarray(point, dtype=float)
        if centre is None or np.linalg.norm(point - centre) <= GEOMETRY_TOLERANCE * geometry.length_scale:
            return None
        if geometry.model.is_revolute[i] and geometry.on_axis(i, centre):
            return None  # all three axes through one point: it cannot place a point
        solver = cls(geometry, joints, point)
        solver.centre = centre
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        c, w, n_targets = self.centre, self.point, len(targets)
        radius = np.full(n_targets, float(np.linalg.norm(w - c)))
        if g.model.is_revolute[i]:
            o = g.point(i)
            first = subproblem_3(g.direction(i), c - o, targets - o, radius)
            q1 = first.theta
            if first.degenerate.any():  # the target on axis 1: joint 1 free
                q1 = np.where(first.degenerate[:, None], 0.0 if reference is None else reference[i], q1)
            y = o + rotate_about(g.direction(i), -q1, (targets - o)[:, None, :])
        else:
            first = prismatic_to_distance(np.broadcast_to(c, targets.shape), g.direction(i), targets, radius)
            q1 = first.s
            y = targets[:, None, :] - q1[..., None] * g.direction(i)
        pair = subproblem_2_chain(g.direction(j), g.direction(k), w - c, y - c)
        q2, q3 = pair.theta1, pair.theta2  # (N, 2, 2)
        free = pair.degenerate  # (N, 2): y on axis 2
        if free.any():
            start = 0.0 if reference is None else reference[j]
            back = rotate_about(g.direction(j), -start, y - c)
            q3_free = subproblem_1(g.direction(k), w - c, back).theta[..., 0]
            q2 = np.where(free[..., None], start, q2)
            q3 = np.where(free[..., None], q3_free[..., None], q3)
        first_ok = first.valid & first.exact
        if g.model.is_revolute[i]:
            first_ok[:, 1] &= ~first.degenerate
        valid = first_ok[:, :, None] & pair.valid & pair.exact
        valid[..., 1] &= ~free
        joints = np.stack([np.broadcast_to(q1[:, :, None], q2.shape), q2, q3], axis=-1).reshape(n_targets, 4, 3)
        singular = SingularFlags(n_targets)
        joint_1 = "the first joint's axis" if g.model.is_revolute[i] else "the slide"
        _flag_rows(first.merged, Singularity("shoulder", (i,), "boundary", f"the two solutions of {joint_1} meet: "
                                             "the point is at the edge of the reach"), singular)
        if g.model.is_revolute[i]:
            _flag_rows(first.degenerate, Singularity("shoulder", (i,), "free", "the point is on the first joint's "
                                                     "axis; joint 1 is set to the reference value (or 0)"), singular)
        _flag_rows((free & first_ok).any(axis=1), Singularity("elbow", (j,), "free", "the point is on axis 2; "
                                                              "joint 2 is set to the reference value (or 0)"),
                   singular)
        _flag_rows((pair.merged & first_ok).any(axis=1), Singularity("elbow", (j, k), "boundary", "the two "
                                                                     "solutions of joints 2 and 3 meet"), singular)
        return PositionerResult(joints, valid.reshape(n_targets, 4), singular)


class SkewAxes(Positioner):
    """Three revolute joints whose second and third axes are skew: Pieper's quartic, by subproblem 5.

    The general 3R positioner (IK-Geo's ``spherical`` family). With o₂, o₃ the feet of the common
    normal of axes 2 and 3 and o₁ a point on axis 1, the target x = G₁G₂G₃ w reads
    ``(o₁ − o₂) + R(−ω₁, q₁)(x − o₁) = R(ω₂, q₂)((o₃ − o₂) + R(ω₃, q₃)(w − o₃))``: subproblem 5,
    up to four solutions. With o₂, o₃ on the common normal the equations always separate the
    angles (the length and height rows of subproblem 5 are independent for the third axis). No
    textbook names its branches, so it gives no labels.
    """

    name = "skew_axes"
    generic_count = 4

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "SkewAxes | None":
        if len(joints) != 3 or geometry.kinds(joints) != "RRR":
            return None
        i, j, k = joints
        point = np.asarray(point, dtype=float)
        if geometry.parallel(j, k) or geometry.intersection(j, k) is not None or geometry.on_axis(k, point):
            return None
        solver = cls(geometry, joints, point)
        solver.feet = _common_normal_feet(geometry.point(j), geometry.direction(j), geometry.point(k),
                                          geometry.direction(k))
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        (o2, o3), o1 = self.feet, g.point(i)
        sol = subproblem_5(-g.direction(i), g.direction(j), g.direction(k), o1 - o2, targets - o1, o3 - o2,
                           self.point - o3)
        q1 = sol.theta1
        if sol.degenerate.any() and reference is not None:  # the target on axis 1: joint 1 free
            q1 = np.where(sol.degenerate[:, None], reference[i], q1)
        joints = np.stack([q1, sol.theta2, sol.theta3], axis=-1)
        singular = SingularFlags(len(targets))
        _flag_rows(sol.degenerate, Singularity("shoulder", (i,), "free", "the point is on the first joint's "
                                               "axis; joint 1 is set to the reference value (or 0)"), singular)
        _flag_rows(sol.merged, Singularity("positioner", self.joints, "boundary", "two solutions of the "
                                           "positioner meet: the point is on the edge of the workspace"), singular)
        return PositionerResult(joints, sol.valid, singular)


class ParallelShoulder(Positioner):
    """Revolute joints 1 and 2 with parallel axes, then a prismatic joint 3 along them: the SCARA arm.

    The height along the common axis u fixes the slide: ``u·(w + s v₃) = u·x``
    (linear). In the plane normal to u it is the RRR (Assur) group: the
    distance from axis 1 to the point fixes q₂ by subproblem 3 (two assembly
    modes), and q₁ follows by subproblem 1.

    Labels: ``assembly_mode`` 1 when the elbow lies counter-clockwise of the
    line from axis 1 to the point, seen from the up-pointing axis (the paper's
    φ = θ + β), 2 otherwise.
    """

    name = "parallel_shoulder"
    generic_count = 2

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "ParallelShoulder | None":
        if len(joints) != 3 or geometry.kinds(joints) != "RRP":
            return None
        i, j, k = joints
        if not (geometry.parallel(i, j) and geometry.parallel(i, k)):
            return None
        return cls(geometry, joints, point)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        u = g.direction(i)
        n_targets = len(targets)
        slide = prismatic_to_plane(u, self.point, g.direction(k), targets @ u)  # (N, 1)
        w3 = self.point + g.direction(k) * slide.s[..., None]  # (N, 1, 3)
        radial = targets - g.point(i)
        radial = radial - np.outer(radial @ u, u)
        reach = np.linalg.norm(radial, axis=-1)
        in_plane = np.eye(3) - np.outer(u, u)
        elbow = subproblem_3(g.direction(j), (w3[:, 0] - g.point(j)) @ in_plane, in_plane @ (g.point(i) - g.point(j)),
                             reach)
        q2 = elbow.theta  # (N, 2)
        w2 = g.point(j) + rotate_about(g.direction(j), q2, (w3 - g.point(j)))  # (N, 2, 3)
        first = subproblem_1(u, w2 - g.point(i), (targets - g.point(i))[:, None, :])
        q1 = first.theta[..., 0]
        free = first.degenerate
        if free.any():
            q1 = np.where(free, 0.0 if reference is None else reference[i], q1)
        joints = np.stack([q1, q2, np.broadcast_to(slide.s, q2.shape)], axis=-1)
        valid = elbow.valid & elbow.exact & first.exact[..., 0] & slide.exact
        # The point on the first axis leaves joint 1 free (subproblem 1 is degenerate); it is reachable there
        # only with equal link lengths, the group's coincident case (textbook.md §4.2 item 6).
        coincident = elbow.degenerate | (free & valid).any(axis=1)
        valid[:, 1] &= ~free[:, 1]
        singular = SingularFlags(n_targets)
        _flag_rows(coincident, Singularity("assur_group", (i, j), "coincident",
                                           "the point is on the first axis with equal link lengths: "
                                           "joint 1 is free (increased mobility)"), singular)
        _flag_rows(elbow.merged & ~coincident, Singularity("assur_group", (j,), "aligned",
                                                           "the links are aligned (stretched or folded): "
                                                           "the two assembly modes meet"), singular)
        return PositionerResult(joints, valid, singular)

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        g, (i, j, k) = self.geometry, self.joints
        up = g.upward(g.direction(i))
        elbow = self._moved(joints, i + 1, g.point(j)) - g.point(i)
        point = self._moved(joints, k + 1, self.point) - g.point(i)
        side = np.einsum("mi,i->m", np.cross(point, elbow), up)
        size = np.linalg.norm(point, axis=-1) * np.linalg.norm(elbow, axis=-1)
        return {"assembly_mode": ((1, 2), side_codes(side, size))}


class OneRevolute(Positioner):
    """One revolute joint placing a point on the circle it sweeps: ``R(ω, q)(w − p) = x − p``, subproblem 1.

    One solution where x is on that circle (the point's height along ω and its distance from the axis
    kept), none elsewhere. The positioner of a two-joint arm whose second joint is a roll placing a full
    pose: the roll keeps the points of its axis, so the target fixes where one of them goes. Such an arm is,
    for instance, a planar three-joint arm with two coaxial joints once one of them is held
    (:mod:`._coaxial`). With the point on the axis every q keeps it there: the joint is free (the reference
    value, or 0) and flagged, and a full pose's orientation then fixes it (``DecoupledPlan``).
    """

    name = "one_revolute"
    generic_count = 1

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "OneRevolute | None":
        if len(joints) != 1 or geometry.kinds(joints) != "R":
            return None
        return cls(geometry, joints, point)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        """Joint values (N, 1, 1) carrying the point to targets (N, 3), valid (N, 1) where on the circle."""
        g, (i,) = self.geometry, self.joints
        turn = subproblem_1(g.direction(i), self.point - g.point(i), targets - g.point(i))
        free = turn.degenerate  # (N,): the point (or the target) on the axis
        q = np.where(free[:, None], 0.0 if reference is None else reference[i], turn.theta)
        singular = SingularFlags(len(targets))
        _flag_rows(free, Singularity("shoulder", (i,), "free", f"the point is on axis {i + 1}; joint {i + 1} is "
                                     "set to the reference value (or 0)"), singular)
        return PositionerResult(q[..., None], turn.exact, singular)


class PlanarTwoLink(Positioner):
    """Two revolute joints with parallel axes placing a point in their plane (Spong Example 3.1).

    The distance from axis 1 fixes q₂ (subproblem 3, elbow up/down), then q₁ by
    subproblem 1. The point's height along the axes cannot change: a target
    off that plane is unreachable.

    With the point on axis 2 (a link of length 0, as in a planar arm with two coaxial joints once one is
    held, :mod:`._coaxial`) q₂ never moves it: subproblem 3 is degenerate for every target, q₂ is a free
    joint (the reference value, or 0) and one solution remains.
    """

    name = "planar_two_link"
    generic_count = 2

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "PlanarTwoLink | None":
        if len(joints) != 2 or geometry.kinds(joints) != "RR" or not geometry.parallel(*joints):
            return None
        solver = cls(geometry, joints, point)
        if geometry.on_axis(joints[1], solver.point):
            solver.free_joints = (joints[1],)  # subproblem 3 is degenerate for every target
            solver.generic_count = 1
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j) = self.geometry, self.joints
        u = g.direction(i)
        radial = targets - g.point(i)
        reach = np.linalg.norm(radial - np.outer(radial @ u, u), axis=-1)
        in_plane = np.abs((targets - self.point) @ u) <= GEOMETRY_TOLERANCE * g.length_scale
        in_plane_projector = np.eye(3) - np.outer(u, u)
        elbow = subproblem_3(g.direction(j), in_plane_projector @ (self.point - g.point(j)),
                             in_plane_projector @ (g.point(i) - g.point(j)), reach)
        q2 = elbow.theta  # (N, 2)
        if self.free_joints:  # degenerate: the representative is the reference value (or 0), not SP3's 0
            q2 = np.where(elbow.valid, 0.0 if reference is None else reference[j], q2)
        w2 = g.point(j) + rotate_about(g.direction(j), q2, self.point - g.point(j))
        first = subproblem_1(u, w2 - g.point(i), (targets - g.point(i))[:, None, :])
        q1 = first.theta[..., 0]
        free = first.degenerate
        if free.any():
            q1 = np.where(free, 0.0 if reference is None else reference[i], q1)
        joints = np.stack([q1, q2], axis=-1)
        valid = elbow.valid & elbow.exact & first.exact[..., 0] & in_plane[:, None]
        valid[:, 1] &= ~free[:, 1]
        if self.free_joints:
            valid[:, 1] = False  # one representative of the free elbow
        singular = SingularFlags(len(targets))
        _flag_rows(elbow.merged, Singularity("elbow", (j,), "stretched_or_folded",
                                             "the arm is fully stretched or folded"), singular)
        _flag_rows(free.any(axis=1), Singularity("shoulder", (i,), "free",
                                                 "the point is on the first axis; joint 1 is free"), singular)
        return PositionerResult(joints, valid, singular)

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        g, (i, j) = self.geometry, self.joints
        up = g.upward(g.direction(i))
        elbow = self._moved(joints, i + 1, g.point(j)) - g.point(i)
        point = self._moved(joints, j + 1, self.point) - g.point(i)
        side = np.einsum("mi,i->m", np.cross(point, elbow), up)
        return {"elbow": (("up", "down"), side_codes(side, np.linalg.norm(point, axis=-1) * np.linalg.norm(elbow, axis=-1)))}


class IntersectingPair(Positioner):
    """Two revolute joints whose axes meet at a point c (not parallel), placing a point on a sphere about c.

    ``R(ω₁, q₁) R(ω₂, q₂)(w − c) = x − c`` is subproblem 2: two solutions. The pair places the point
    only on the sphere of radius ``‖w − c‖``: another target is unreachable. The positioner of an arm
    with one joint fewer than six, such as a six-joint arm with two coaxial joints once one of them is
    held (:mod:`._coaxial`). Joint 1 is free when the target is on axis 1, joint 2 when the point is on
    axis 2, both when the point is c. No textbook names its branches, so it gives no labels.
    """

    name = "intersecting_pair"
    generic_count = 2

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "IntersectingPair | None":
        if len(joints) != 2 or geometry.kinds(joints) != "RR":
            return None
        centre = geometry.intersection(*joints)
        if centre is None:
            return None
        solver = cls(geometry, joints, point)
        solver.centre = centre
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j) = self.geometry, self.joints
        c, n_targets = self.centre, len(targets)
        pair = subproblem_2_chain(g.direction(i), g.direction(j), self.point - c, targets - c)
        q1, q2 = pair.theta1, pair.theta2  # (N, 2)
        start = {i: 0.0 if reference is None else float(reference[i]), j: 0.0 if reference is None
                 else float(reference[j])}
        # the chain form's theta1 is free with the target on axis 1, theta2 with the point on axis 2
        on_axis_1 = np.linalg.norm(np.cross(g.direction(i), targets - c), axis=-1) <= GEOMETRY_TOLERANCE * g.length_scale
        on_axis_2 = pair.degenerate & ~on_axis_1
        both = on_axis_1 & (np.linalg.norm(self.point - c) <= GEOMETRY_TOLERANCE * g.length_scale)
        if pair.degenerate.any():
            q1 = np.where(on_axis_1[:, None], start[i], q1)
            second = subproblem_1(g.direction(j), self.point - c, rotate_about(g.direction(i), -start[i], targets - c))
            q2 = np.where(on_axis_1[:, None], np.where(both, start[j], second.theta[..., 0])[:, None], q2)
            q2 = np.where(on_axis_2[:, None], start[j], q2)
            if on_axis_2.any():
                first = subproblem_1(g.direction(i), rotate_about(g.direction(j), start[j], self.point - c),
                                     targets - c)
                q1 = np.where(on_axis_2[:, None], first.theta, q1)
        joints = np.stack([q1, q2], axis=-1)
        valid = pair.valid & pair.exact
        singular = SingularFlags(n_targets)
        _flag_rows(both, Singularity("shoulder", (i, j), "free", "the point is at the axes' crossing; joints "
                                     f"{i + 1} and {j + 1} are set to the reference values (or 0)"), singular)
        _flag_rows(on_axis_1 & ~both, Singularity("shoulder", (i,), "free", f"the point is on axis {i + 1}; joint "
                                                  f"{i + 1} is set to the reference value (or 0)"), singular)
        _flag_rows(on_axis_2, Singularity("shoulder", (j,), "free", f"the point is on axis {j + 1}; joint {j + 1} is "
                                          "set to the reference value (or 0)"), singular)
        _flag_rows(pair.merged, Singularity("shoulder", (i, j), "boundary", "the two solutions meet"), singular)
        return PositionerResult(joints, valid, singular)


class OneRevoluteTwoPrismatic(Positioner):
    """One revolute and two prismatic joints in any order (cylindrical RPP, PRP).

    With the slides s before the revolute joint collected in V_pre and those after it in
    V_post, ``x − p − V_pre s = R(ω, θ)(w − p + V_post s)``. The rotation keeps the
    component along ω (a linear equation in s) and the distance from the axis (a
    quadratic): together up to 2 roots. θ follows by subproblem 1.
    """

    name = "one_revolute_two_prismatic"
    generic_count = 2

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "OneRevoluteTwoPrismatic | None":
        kinds = geometry.kinds(joints)
        if len(joints) != 3 or kinds.count("R") != 1:
            return None
        solver = cls(geometry, joints, point)
        solver.revolute = joints[kinds.index("R")]
        solver.slides = tuple(joint for joint in joints if joint != solver.revolute)
        omega = geometry.direction(solver.revolute)
        axial = np.array([omega @ geometry.direction(s) for s in solver.slides])
        if np.abs(axial).max() <= GEOMETRY_TOLERANCE:
            return None  # no slide along the axis: the height equation does not fix them
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, r = self.geometry, self.revolute
        omega, p = g.direction(r), g.point(r)
        V = np.stack([g.direction(s) for s in self.slides], axis=1)  # (3, 2)
        before = np.array([s < r for s in self.slides])
        V_pre, V_post = V * before, V * ~before
        perp = np.eye(3) - np.outer(omega, omega)
        # linear: a·s = b   with a = ω·(V_pre + V_post), b = ω·(x − w)
        a = omega @ (V_pre + V_post)
        b = (targets - self.point) @ omega
        s0 = np.outer(b, a) / (a @ a)  # (N, 2)
        nullspace = np.array([-a[1], a[0]]) / np.linalg.norm(a)
        alpha = (targets - p) @ perp  # (N, 3)
        beta = (self.point - p) @ perp
        P, Q = perp @ V_pre, perp @ V_post  # (3, 2)
        lhs = alpha - s0 @ P.T
        rhs = beta + s0 @ Q.T
        Pn, Qn = P @ nullspace, Q @ nullspace
        A = Pn @ Pn - Qn @ Qn
        B = -2 * (lhs @ Pn) - 2 * (rhs @ Qn)
        C = np.einsum("ni,ni->n", lhs, lhs) - np.einsum("ni,ni->n", rhs, rhs)
        t, t_valid, merged = _quadratic_roots(A, B, C, g.length_scale)
        slides = s0[:, None, :] + t[..., None] * nullspace  # (N, 2, 2)
        body = self.point - p + slides @ V_post.T
        world = targets[:, None, :] - p - slides @ V_pre.T
        # an azimuth seen on a radius is known to the target's rounding / radius: free only within rounding
        band = ROUNDING_TOLERANCE * (g.length_scale + np.linalg.norm(targets, axis=-1))[:, None]
        turn = subproblem_1(omega, body, world, free_below=band)
        theta = turn.theta[..., 0]
        free = turn.degenerate
        if reference is not None:
            radius = np.linalg.norm(world @ perp, axis=-1)
            free_or_in_band = free | (np.abs(wrap_angle(theta - reference[r])) * radius <= band)
            theta = np.where(free_or_in_band, reference[r], theta)
        elif free.any():
            theta = np.where(free, 0.0, theta)
        joints = np.zeros(slides.shape[:2] + (3,))
        order = list(self.joints)
        joints[..., order.index(r)] = theta
        for column, s in enumerate(self.slides):
            joints[..., order.index(s)] = slides[..., column]
        valid = t_valid & turn.exact[..., 0]
        singular = SingularFlags(len(targets))
        _flag_rows(free.any(axis=1), Singularity("shoulder", (r,), "free",
                                                 "the point is on the revolute axis; that joint is free"), singular)
        _flag_rows(merged, Singularity("reach", self.slides, "boundary",
                                       "the two slide solutions meet"), singular)
        return PositionerResult(joints, valid, singular)


class Cartesian(Positioner):
    """Three prismatic joints with independent directions: one linear solve."""

    name = "cartesian"
    generic_count = 1

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "Cartesian | None":
        if len(joints) != 3 or geometry.kinds(joints) != "PPP":
            return None
        V = np.stack([geometry.direction(j) for j in joints], axis=1)
        if abs(np.linalg.det(V)) < GEOMETRY_TOLERANCE:
            return None
        solver = cls(geometry, joints, point)
        solver.inverse = np.linalg.inv(V)
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        joints = (targets - self.point) @ self.inverse.T
        return PositionerResult(joints[:, None, :], np.ones((len(targets), 1), dtype=bool),
                                SingularFlags(len(targets)))


class SkewAxesWithSlide(Positioner):
    """Two revolute joints and one slide in any order (RRP, RPR, PRR), the axes skew: a quartic.

    What is left of the 3-joint positioners with one slide once the intersecting shoulder, the
    parallel shoulder (SCARA) and the offset-shoulder classes have taken theirs: a gantry's linear
    axis carrying a skew two-axis head (PRR), a turret with a telescoping boom and a skew elbow
    (RPR), two skew revolute axes with an oblique slide (RRP). One revolute joint ``a`` is
    eliminated as in subproblem 5, by the height along its axis and the length it keeps; the other,
    ``b``, moves the point on a circle; the slide on a line. With ``o`` points on the axes, ``v`` the
    slide and ``w`` the point (subproblem 5 with a slide, :func:`subproblem_5_prismatic`):

    * PRR: ``x − o_a − s v = R(k_a, q_a)((o_b − o_a) + R(k_b, q_b)(w − o_b))``;
    * RRP: ``(w − o_b) + s v = R(k_b, −q_b)((o_a − o_b) + R(−k_a, q_a)(x − o_a))``;
    * RPR: ``x − o_a = R(k_a, q_a)((o_b − o_a) + R(k_b, q_b)(w − o_b) + s v)``.

    Eliminating s (linear in the height equation) leaves a trigonometric quartic in the circle's
    angle: 4 solutions (2 when that axis is parallel to the eliminated one). A slide normal to the
    eliminated axis splits it into a harmonic equation and a quadratic in s (still 4). When the
    slide is normal to it and the two axes are parallel the arm is planar and does not place a
    point: no match. No textbook names its branches, so it gives no labels.
    """

    name = "skew_axes_with_slide"
    generic_count = 4

    @classmethod
    def match(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> "SkewAxesWithSlide | None":
        kinds = geometry.kinds(joints) if len(joints) == 3 else ""
        if kinds not in ("RRP", "RPR", "PRR"):
            return None
        point = np.asarray(point, dtype=float)
        slide = joints[kinds.index("P")]
        revolute = [j for j in joints if j != slide]
        if kinds == "RRP":
            eliminated, circle = revolute[1], revolute[0]
            if geometry.intersection(eliminated, circle) is not None:
                return None  # the intersecting shoulder
        else:
            eliminated, circle = revolute
            if geometry.on_axis(circle, point):
                return None  # the circle is a point: joint b does not move it
        along = abs(float(geometry.direction(eliminated) @ geometry.direction(slide)))
        normal = along <= GEOMETRY_TOLERANCE
        if normal and geometry.parallel(eliminated, circle):
            return None  # planar: the height along the parallel axes never changes
        turn = float(np.linalg.norm(np.cross(geometry.direction(eliminated), geometry.direction(circle))))
        if GEOMETRY_TOLERANCE < along <= RECOGNITION_TOLERANCE \
                or 10 * GEOMETRY_TOLERANCE < turn <= RECOGNITION_TOLERANCE:
            return None  # nearly special (a rounded SCARA): the idealised family answers, refined on this arm
        solver = cls(geometry, joints, point)
        solver.kinds, solver.slide, solver.revolute = kinds, slide, tuple(revolute)
        if geometry.parallel(eliminated, circle) and not normal:
            solver.generic_count = 2
        return solver

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, kinds = self.geometry, self.kinds
        (a, b), p = self.revolute, self.slide  # the first and second revolute joints
        ka, kb, oa, ob, v = g.direction(a), g.direction(b), g.point(a), g.point(b), g.direction(p)
        if kinds == "PRR":
            sol = subproblem_5_prismatic(ka, kb, ob - oa, self.point - ob, targets - oa, -v, slide_turns=False)
            qa, qb = sol.phi, sol.theta
        elif kinds == "RRP":
            sol = subproblem_5_prismatic(kb, -ka, oa - ob, targets - oa, self.point - ob, v, slide_turns=False)
            qa, qb = sol.theta, -sol.phi
        else:
            sol = subproblem_5_prismatic(ka, kb, ob - oa, self.point - ob, targets - oa, v, slide_turns=True)
            qa, qb = sol.phi, sol.theta
        # a free turn (its vector on its axis) takes the reference value: the others do not depend on it
        free_joint = b if kinds == "RRP" else a
        start = {j: (0.0 if reference is None else float(reference[j])) for j in (a, b)}
        if sol.phi_free.any():
            if kinds == "RRP":
                qb = np.where(sol.phi_free, start[b], qb)
            else:
                qa = np.where(sol.phi_free, start[a], qa)
        if sol.degenerate.any():  # RRP only: the target on axis a
            qa = np.where(sol.degenerate[:, None], start[a], qa)
        values = {a: qa, b: qb, p: sol.s}
        joints = np.stack([values[j] for j in self.joints], axis=-1)
        singular = SingularFlags(len(targets))
        if kinds == "RRP":
            _flag_rows(sol.degenerate, Singularity("shoulder", (a,), "free", "the point is on the first joint's "
                                                   "axis; joint 1 is set to the reference value (or 0)"), singular)
        _flag_rows(sol.phi_free.any(axis=1), Singularity("shoulder" if free_joint == self.joints[0] else "elbow",
                                                         (free_joint,), "free",
                                                         f"the point is on axis {free_joint + 1}; that joint is set "
                                                         "to the reference value (or 0)"), singular)
        _flag_rows(sol.merged, Singularity("positioner", self.joints, "boundary", "two solutions of the "
                                           "positioner meet: the point is on the edge of the workspace"), singular)
        return PositionerResult(joints, sol.valid & sol.exact, singular)


def _quadratic_roots(A: np.ndarray | float, B: np.ndarray, C: np.ndarray, scale: float):
    """Real roots of A t² + B t + C = 0 per row: (N, 2) roots, validity, and merged flags."""
    A = np.broadcast_to(np.asarray(A, dtype=float), B.shape)
    roots = np.full(B.shape + (2,), np.nan)
    valid = np.zeros(B.shape + (2,), dtype=bool)
    merged = np.zeros(B.shape, dtype=bool)
    linear = np.abs(A) <= 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        roots[linear, 0] = -C[linear] / B[linear]
        valid[linear, 0] = np.abs(B[linear]) > 1e-12
        quad = ~linear
        discriminant = B[quad] ** 2 - 4 * A[quad] * C[quad]
        # the discriminant's rounding: a double root only within it. (SINGULARITY_TOLERANCE here merged roots
        # ±1e-10 of the scale apart and kept the + one: the cylindrical arm's radial slide at −1e-10 came back
        # at +1e-10 with joint 1 turned by π.)
        tolerance = ROUNDING_TOLERANCE * (B[quad] ** 2 + np.abs(4 * A[quad] * C[quad]) + scale ** 2 * 1e-12)
        touching = np.abs(discriminant) <= tolerance
        root = np.sqrt(np.maximum(discriminant, 0.0)) * ~touching  # a double root: the midpoint
        roots[quad, 0] = (-B[quad] + root) / (2 * A[quad])
        roots[quad, 1] = (-B[quad] - root) / (2 * A[quad])
        valid[quad, 0] = discriminant >= -tolerance
        valid[quad, 1] = (discriminant >= -tolerance) & ~touching
        merged[quad] = touching
    return roots, valid, merged


POSITIONERS = (IntersectingShoulder, ParallelShoulder, OneRevoluteTwoPrismatic, Cartesian, PlanarTwoLink,
               IntersectingPair, OneRevolute,
               OffsetShoulderParallelElbow, OffsetShoulderIntersectingElbow, SkewAxes, SkewAxesWithSlide)


def find_positioner(geometry: Geometry, joints: tuple[int, ...], point: np.ndarray) -> Positioner | None:
    """The first positioning family that matches these joints, or None."""
    for family in POSITIONERS:
        solver = family.match(geometry, joints, point)
        if solver is not None:
            return solver
    return None
