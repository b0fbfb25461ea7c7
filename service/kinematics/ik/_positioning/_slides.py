"""Positioners with slides, beyond the shoulders: the SCARA arm (:class:`ParallelShoulder`), the cylindrical
arms (:class:`OneRevoluteTwoPrismatic`), the Cartesian gantry (:class:`Cartesian`) and two skew revolute axes
with a slide (:class:`SkewAxesWithSlide`)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..._angles import wrap_angle
from ..._tolerances import GEOMETRY_TOLERANCE, RECOGNITION_TOLERANCE
from ..._forward import JointTrig, cross, radius_about
from .._screws import rotate_about
from .._structure import Geometry, target_error
from .._types import LabelCodes, SingularFlags, Singularity
from ..subproblems import prismatic_to_plane, quadratic_roots, subproblem_1, subproblem_3, subproblem_5_prismatic
from ._base import Needs, Positioner, PositionerResult, _flag_rows, side_codes


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
    needs = Needs(kinds=("RRP",), parallel=((0, 1), (0, 2)))

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
        first = subproblem_1(u, w2 - g.point(i), (targets - g.point(i))[:, None, :], scale=g.length_scale)
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

    def label_codes(self, joints: np.ndarray, trig: JointTrig | None = None) -> LabelCodes:
        g, (i, j, k) = self.geometry, self.joints
        up = g.upward(g.direction(i))
        elbow = self._moved(joints, i + 1, g.point(j), trig) - g.point(i)
        point = self._moved(joints, k + 1, self.point, trig) - g.point(i)
        side = np.einsum("mi,i->m", cross(point, elbow), up)
        size = np.linalg.norm(point, axis=-1) * np.linalg.norm(elbow, axis=-1)
        return {"assembly_mode": ((1, 2), side_codes(side, size))}


class SlideEquations(NamedTuple):
    """The fixed parts of :class:`OneRevoluteTwoPrismatic`'s equations: the revolute axis (direction ``omega``
    through ``p``), the slides' directions as columns (3, 2) split into those before the revolute joint
    (``V_pre``) and after it (``V_post``, zero columns elsewhere), the projector ``perp`` normal to the axis, the
    height equation's ``a`` = ω·(V_pre + V_post) (2,) and its null direction ``nullspace`` (2,), the projected
    columns ``P``, ``Q`` (3, 2) and their images ``Pn``, ``Qn`` (3,) of the null direction. Built once per
    positioner; its scalar path (``_decoupled``) reads them too."""

    omega: np.ndarray
    p: np.ndarray
    V_pre: np.ndarray
    V_post: np.ndarray
    perp: np.ndarray
    a: np.ndarray
    nullspace: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    Pn: np.ndarray
    Qn: np.ndarray

    @classmethod
    def of(cls, geometry: Geometry, revolute: int, slides: tuple[int, int], point: np.ndarray) -> "SlideEquations":
        omega, p = geometry.direction(revolute), geometry.point(revolute)
        V = np.stack([geometry.direction(s) for s in slides], axis=1)  # (3, 2)
        before = np.array([s < revolute for s in slides])
        V_pre, V_post = V * before, V * ~before
        perp = np.eye(3) - np.outer(omega, omega)
        a = omega @ (V_pre + V_post)
        nullspace = np.array([-a[1], a[0]]) / np.linalg.norm(a)
        P, Q = perp @ V_pre, perp @ V_post
        return cls(omega, p, V_pre, V_post, perp, a, nullspace, P, Q, P @ nullspace, Q @ nullspace)


class OneRevoluteTwoPrismatic(Positioner):
    """One revolute and two prismatic joints in any order (cylindrical RPP, PRP).

    With the slides s before the revolute joint collected in V_pre and those after it in
    V_post, ``x − p − V_pre s = R(ω, θ)(w − p + V_post s)``. The rotation keeps the
    component along ω (a linear equation in s) and the distance from the axis (a
    quadratic): together up to 2 roots. θ follows by subproblem 1.
    """

    name = "one_revolute_two_prismatic"
    generic_count = 2
    needs = Needs(kinds=("RPP", "PRP", "PPR"))

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, *, revolute: int,
                 slides: tuple[int, int]) -> None:
        super().__init__(geometry, joints, point)
        #: the revolute joint and the two slides (indices into the arm)
        self.revolute, self.slides = revolute, slides
        #: the equations' fixed parts (:class:`SlideEquations`)
        self.equations = SlideEquations.of(geometry, revolute, slides, self.point)

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "OneRevoluteTwoPrismatic | None":
        kinds = geometry.kinds(joints)
        revolute = joints[kinds.index("R")]
        slides = tuple(joint for joint in joints if joint != revolute)
        omega = geometry.direction(revolute)
        axial = np.array([omega @ geometry.direction(s) for s in slides])
        # (within RECOGNITION_TOLERANCE: the equations below would divide by the rounding of the geometry; the
        # idealised arm's families answer such an arm)
        if np.abs(axial).max() <= RECOGNITION_TOLERANCE:
            return None  # no slide along the axis: the height equation does not fix them
        if geometry.nearly_parallel(*slides):
            return None  # parallel slides move the point along one line: only their sum is fixed
        return cls(geometry, joints, point, revolute=revolute, slides=slides)

    def solve(self, targets: np.ndarray, reference: np.ndarray | None) -> PositionerResult:
        g, r = self.geometry, self.revolute
        omega, p, V_pre, V_post, perp, a, nullspace, P, Q, Pn, Qn = self.equations
        # linear: a·s = b   with a = ω·(V_pre + V_post), b = ω·(x − w)
        b = (targets - self.point) @ omega
        s0 = np.outer(b, a) / (a @ a)  # (N, 2)
        alpha = (targets - p) @ perp  # (N, 3)
        beta = (self.point - p) @ perp
        lhs = alpha - s0 @ P.T
        rhs = beta + s0 @ Q.T
        A = Pn @ Pn - Qn @ Qn
        B = -2 * (lhs @ Pn) - 2 * (rhs @ Qn)
        C = np.einsum("ni,ni->n", lhs, lhs) - np.einsum("ni,ni->n", rhs, rhs)
        t, t_valid, merged = quadratic_roots(A, B, C, g.length_scale)
        slides = s0[:, None, :] + t[..., None] * nullspace  # (N, 2, 2)
        body = self.point - p + slides @ V_post.T
        world = targets[:, None, :] - p - slides @ V_pre.T
        # an azimuth seen on a radius is known to the target's error / radius: free only within that error
        band = target_error(g, np.linalg.norm(targets, axis=-1))[:, None]
        turn = subproblem_1(omega, body, world, free_below=band, scale=g.length_scale)
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
    needs = Needs(kinds=("PPP",))

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, *,
                 inverse: np.ndarray) -> None:
        super().__init__(geometry, joints, point)
        #: the inverse (3, 3) of the slides' directions as columns
        self.inverse = inverse

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "Cartesian | None":
        V = np.stack([geometry.direction(j) for j in joints], axis=1)
        if abs(np.linalg.det(V)) < GEOMETRY_TOLERANCE:
            return None
        return cls(geometry, joints, point, inverse=np.linalg.inv(V))

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
    needs = Needs(kinds=("RRP", "RPR", "PRR"))

    def __init__(self, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, *, kinds: str, slide: int,
                 revolute: tuple[int, int], generic_count: int | None = None) -> None:
        super().__init__(geometry, joints, point, generic_count=generic_count)
        #: the joints' kinds ("RRP", "RPR" or "PRR"), the slide and the two revolute joints in chain order
        self.kinds, self.slide, self.revolute = kinds, slide, revolute

    @classmethod
    def _fit(cls, geometry: Geometry, joints: tuple[int, ...], point: np.ndarray, centre: np.ndarray | None
             ) -> "SkewAxesWithSlide | None":
        kinds = geometry.kinds(joints)
        slide = joints[kinds.index("P")]
        revolute = [j for j in joints if j != slide]
        if kinds == "RRP":
            eliminated, circle = revolute[1], revolute[0]
            if geometry.intersection(eliminated, circle) is not None:
                return None  # the intersecting shoulder
        else:
            eliminated, circle = revolute
            if geometry.nearly_on_axis(circle, point):
                return None  # the circle is a point (joint b does not move it), or nearly (a rounded R-R-P-R)
        along = abs(float(geometry.direction(eliminated) @ geometry.direction(slide)))
        normal = along <= GEOMETRY_TOLERANCE
        if normal and geometry.parallel(eliminated, circle):
            return None  # planar: the height along the parallel axes never changes
        turn = float(radius_about(geometry.direction(eliminated), geometry.direction(circle)))
        if GEOMETRY_TOLERANCE < along <= RECOGNITION_TOLERANCE \
                or 10 * GEOMETRY_TOLERANCE < turn <= RECOGNITION_TOLERANCE:
            return None  # nearly special (a rounded SCARA): the idealised family answers, refined on this arm
        return cls(geometry, joints, point, kinds=kinds, slide=slide, revolute=tuple(revolute),
                   generic_count=2 if geometry.parallel(eliminated, circle) and not normal else None)

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
