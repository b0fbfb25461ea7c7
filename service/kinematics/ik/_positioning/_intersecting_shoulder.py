"""The intersecting shoulder: revolute joints 1 and 2 whose axes meet, then a revolute or prismatic joint 3
(the elbow arms, the PUMA, the Stanford and polar arms), with its left/right and up/down labels."""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..._angles import wrap_angle
from ..._tolerances import FOLD_TOLERANCE, GEOMETRY_TOLERANCE, ROUNDING_TOLERANCE
from ..._forward import JointTrig, cross, radius_about
from .._screws import rotate_about
from .._structure import Geometry, target_error
from .._types import NEAR_SINGULAR, LabelCodes, SingularFlags, Singularity
from ..subproblems import prismatic_to_distance, subproblem_1, subproblem_2_chain, subproblem_3, subproblem_4
from ._base import Needs, Positioner, PositionerResult, _flag_rows, _unit, side_codes
from ._slide_through_axis_2 import SlideThroughAxis2


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
    the shoulder instead (:meth:`SlideThroughAxis2.solve`): from the reach alone its value near the
    crossing is known only to the square root of the target's rounding, and without its sign.

    Labels: ``shoulder`` left/right is the sign of the arm's reach along the
    forward direction of link 1 (the textbook's left/right arm; "front" is left);
    ``elbow`` up/down (revolute joint 3) is the side of the shoulder–point line
    the elbow lies on, seen along the up-pointing axis 1. See :meth:`labels`.
    """

    name = "intersecting_shoulder"
    generic_count = 4
    needs = Needs(kinds=("RR?",), meeting=(0, 1))

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray, *,
                 slide_through_axis_2: SlideThroughAxis2 | None, generic_count: int | None = None,
                 free_joints: tuple[int, ...] = ()) -> None:
        super().__init__(geometry, joints, point, centre, generic_count=generic_count, free_joints=free_joints)
        #: the frame of a slide normal to axis 2 through it (the Stanford and polar arms), else None
        self.slide_through_axis_2 = slide_through_axis_2

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "IntersectingShoulder":
        k = joints[2]
        slide = SlideThroughAxis2.of(geometry, joints, point, centre)
        if geometry.model.is_revolute[k] and (geometry.on_axis(k, point) or geometry.on_axis(k, centre)):
            # subproblem 3 is degenerate for every target
            return cls(geometry, joints, point, centre, slide_through_axis_2=slide, generic_count=2, free_joints=(k,))
        return cls(geometry, joints, point, centre, slide_through_axis_2=slide)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, (i, j, k) = self.geometry, self.joints
        if self.slide_through_axis_2 is not None:
            return self.slide_through_axis_2.solve(g, self.joints, self.centre, targets, reference)
        c, w = self.centre, self.point
        n_targets = len(targets)
        reach = np.linalg.norm(targets - c, axis=-1)
        if g.model.is_revolute[k]:
            third = subproblem_3(g.direction(k), w - g.point(k), c - g.point(k), reach)
            q3 = third.theta
            if self.free_joints:  # degenerate: the representative is the reference value (or 0), not SP3's 0
                held = np.full(n_targets, 0.0 if reference is None else float(reference[k]))
                if g.on_axis(k, c):
                    held = self._turn_that_reaches(held, targets)
                q3 = np.where(third.valid, held[:, None], q3)
            w3 = g.point(k) + rotate_about(g.direction(k), q3, w - g.point(k))
        else:
            third = prismatic_to_distance(w, g.direction(k), c, reach)
            q3 = third.s
            w3 = w + g.direction(k) * q3[..., None]
        # two shoulder roots as close as the arm's own deviation from this family can bring them are one: the
        # deviation splits a boundary's double root by its square root, and each half then misses its target
        error = target_error(g, np.linalg.norm(targets, axis=-1), rounding=0.0)[:, None]
        pair = subproblem_2_chain(g.direction(i), g.direction(j), w3 - c, (targets - c)[:, None, :], error=error)
        q1, q2 = pair.theta1, pair.theta2  # (N, 2 third roots, 2 pair roots)
        singular = SingularFlags(n_targets)
        # subproblem 2 is degenerate when the target is on axis 1 (joint 1 free), or when the point is on axis 2
        # (joint 2 free: an elbow that lines the point up with it, as the stretched elbow of a 7R arm does)
        reach_scale = np.maximum(reach[:, None], np.linalg.norm(w3 - c, axis=-1))  # (N, 2)
        # the target and the placed point both at the centre, within the target's rounding (an arm whose axes all
        # meet there): subproblem 2 would judge their dust against itself; joints 1 and 2 are both free
        at_centre = reach_scale <= ROUNDING_TOLERANCE * g.length_scale
        on_axis_1 = at_centre | (radius_about(g.direction(i), targets - c)[:, None]
                                 <= GEOMETRY_TOLERANCE * reach_scale)
        free_shoulder = (pair.degenerate | at_centre) & on_axis_1  # (N, 2)
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
            free_both = free_shoulder & (second.degenerate | at_centre)
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
        valid = ((third.valid & third.exact) | at_centre)[:, :, None] & (
            (pair.valid & (pair.exact | pair.merged[..., None])) | free_second[..., None] | at_centre[..., None])
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
        # subproblem 2 reads q1 off the target's radius about axis 1 and q2 off the placed point's about axis 2
        near = NEAR_SINGULAR * g.length_scale
        near_axes = ((radius_about(g.direction(i), targets - c) <= near)[:, None]
                     | (radius_about(g.direction(j), w3 - c) <= near))  # (N, 2 third roots)
        return PositionerResult(joints.reshape(n_targets, 4, 3), valid.reshape(n_targets, 4), singular,
                                np.repeat(near_axes, 2, axis=1))

    def _turn_that_reaches(self, held: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Joint 3's value (N,) when its axis passes through the centre c, for targets x (N, 3).

        Joints 1 to 3 then all turn the point p about c: a one-parameter family of solutions, of which joint 3
        picks the member. Joints 1 and 2 reach x from p₃ = R(ω₃, q₃)(w − c) (subproblem 2) iff z = ω₂·p₃ lies
        in ``h c₁₂ ± s₁₂ √(r² − h²)``, with h = ω₁·(x − c), r = ‖x − c‖, c₁₂ and s₁₂ the cosine and sine of the
        angle between axes 1 and 2 (the projections of a sphere's points onto two axes fill an ellipse). Where
        ``held`` (N,) leaves z outside that band, joint 3 takes the value nearest it that puts z mid-band
        (subproblem 4), so that no reachable target is answered unreachable for the value held.
        """
        g, (i, j, k) = self.geometry, self.joints
        w1, w2, w3 = g.direction(i), g.direction(j), g.direction(k)
        p, x = self.point - self.centre, targets - self.centre
        h, r = x @ w1, np.linalg.norm(x, axis=-1)
        half_band = float(radius_about(w1, w2)) * np.sqrt(np.maximum(r * r - h * h, 0.0))
        low, high = h * float(w1 @ w2) - half_band, h * float(w1 @ w2) + half_band
        along = float(w3 @ p)  # z(q₃) = z₀ + ρ cos(q₃ − φ): its range is z₀ ± ρ
        z0, rho = along * float(w2 @ w3), float(radius_about(w2, w3)) * float(radius_about(w3, p))
        tolerance = GEOMETRY_TOLERANCE * g.length_scale
        z_held = rotate_about(w3, held, p) @ w2
        move = ((z_held < low - tolerance) | (z_held > high + tolerance)) \
            & (np.maximum(low, z0 - rho) <= np.minimum(high, z0 + rho))  # else out of reach for every value
        if not move.any():
            return held
        middle = 0.5 * (np.maximum(low, z0 - rho) + np.minimum(high, z0 + rho))[move]
        turns = subproblem_4(w2, w3, p, middle).theta  # (M, 2)
        distance = np.abs(wrap_angle(turns - held[move, None]))
        nearest = np.argmin(np.where(np.isnan(distance), np.inf, distance), axis=1)
        held = held.copy()
        held[move] = turns[np.arange(len(turns)), nearest]
        return held

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
        radius = radius_about(g.direction(j), point)
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
            forward = _unit(cross(offset, g.upward(axis)))
            if forward is not None:
                return forward
        if g.link_x is not None:
            forward = _unit(g.link_x[i] - (g.link_x[i] @ axis) * axis)
            if forward is not None:
                return forward
        normal = _unit(cross(axis, g.direction(j)))
        return normal if normal is not None else self.point - self.centre

    @cached_property
    def label_constants(self) -> tuple[np.ndarray, bool, np.ndarray]:
        """What :meth:`label_codes` needs of the geometry alone, computed once per plan: link 1's forward
        direction at q = 0, whether axes 2 and 3 are parallel, and the up-pointing axis 1."""
        g, (i, j, k) = self.geometry, self.joints
        return self._forward_direction(), bool(g.parallel(j, k)), g.upward(g.direction(i))

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        """Shoulder left/right: the sign of the reach along link 1's forward direction (see
        :meth:`_forward_direction`); none when the point is on axis 1. Elbow up/down (revolute joint 3,
        unless it is free): the side of the shoulder–point line the elbow lies on, along the robot's up
        direction, measured in the arm's plane (normal to axis 2) when axes 2 and 3 are parallel, so that
        the choice of point on axis 3 does not matter. With the point on axis 1 the line is vertical and
        the front configuration's limit is used (textbook §3.2: front, θ3 < 0 is up: the elbow behind).
        """
        g, (i, j, k) = self.geometry, self.joints
        forward_home, in_plane, up = self.label_constants
        trig = JointTrig(joints) if trig is None else trig  # each joint's cos and sin, shared by the turns below
        forward = rotate_about(g.direction(i), joints[:, i], forward_home, trig[i])
        point = self._moved(joints, k + 1, self.point, trig)
        reach = point - self.centre
        axis = g.direction(i)
        sideways = reach - np.outer(reach @ axis, axis)
        on_axis = np.linalg.norm(sideways, axis=-1) <= GEOMETRY_TOLERANCE * 10 * g.length_scale
        along = np.einsum("mi,mi->m", reach, forward)
        # on axis 1 (the shoulder singularity) front and back are one family, and at the boundary
        # (the point as near axis 1 as the offset allows) left and right meet: no shoulder label
        codes: LabelCodes = {"shoulder": (("left", "right"), side_codes(along, np.linalg.norm(reach, axis=-1)))}
        if g.model.is_revolute[k] and not self.free_joints:
            elbow = self._moved(joints, k, g.point(k), trig) - self.centre
            if in_plane:  # work in the arm's plane, normal to axis 2 (turned by joint 1, the one before it)
                normal = rotate_about(axis, joints[:, i], g.direction(j), trig[i])
                elbow = elbow - np.einsum("mi,mi->m", elbow, normal)[:, None] * normal
                reach = reach - np.einsum("mi,mi->m", reach, normal)[:, None] * normal
            line = reach / np.maximum(np.linalg.norm(reach, axis=-1, keepdims=True), 1e-300)
            rejection = elbow - np.einsum("mi,mi->m", elbow, line)[:, None] * line
            side = rejection @ up
            # line along axis 1: "above" is undefined; take the limit from the front (the elbow behind is up)
            side = np.where(on_axis, -(line @ up) * np.einsum("mi,mi->m", elbow, forward), side)
            codes["elbow"] = (("up", "down"), side_codes(side, np.linalg.norm(elbow, axis=-1)))
        return codes
