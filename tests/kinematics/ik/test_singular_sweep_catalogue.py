"""One singular-set sweep over the whole catalogue: every closed-form answer keeps the service's promise.

The promise: an IK answer with ``complete: true`` holds EVERY solution, and ``unreachable`` is never said of a
pose the arm reaches. The per-family sweeps (test_near_singular.py for spherical wrists, test_three_parallel_arcs.py
and test_skew_wrist_singular.py for UR-type wrists) each know their family's singular sets; this one knows none.

Robots: every catalogue arm whose pose IK is closed form (``solve_ik`` answers with method ``analytic``). Left out:
the redundant arms (more than 6 joints: Panda, iiwa, Kinova Gen3, xArm7), whose pose IK is numeric and promises
no completeness, and any arm whose pose IK is numeric (the sweep asserts the analytic set is not empty and that
no arm of 6 joints or fewer falls back to the numeric solver).

Poses: FK of random configurations put on candidate singular sets without knowing the family:

* each joint j at each of {0, π/2, π, −π/2} (a slide at {0, ¼, ½, −¼} of the arm's size) plus δ, δ in
  {0, ±1e-12, ±1e-9, ±1e-6, ±1e-3} (of the arm's size for a slide): wrist joints at 0/π are wrist singularities,
  elbows at 0/π stretched or folded for many arms, a slide at 0 the Stanford arm's nearest reach;
* for arms of 6 joints, q2 and q3 at a root of det J (the geometric Jacobian) found by bisection on FK-derived
  axes with the other joints random: a shoulder singularity (the wrist centre on axis 1, or as near it as an
  offset allows) for q2, the true stretched/folded elbow for q3 (PUMA's is not at q3 = 0), plus the same δ;
  for arms of 3 joints the same with the 3×3 position Jacobian of the tool point.

Checks on each answer (``solve_ik(robot, T)``, no reference; it ignores joint limits, so none are applied):

* status ``ok`` and at least one solution (never ``unreachable`` for an FK pose);
* every solution reaches T by this test's FK: position within 1e-9 of the arm's size, rotation within 1e-9;
* where ``complete`` is true and no singularity is reported, the generating configuration q is among the
  solutions up to what the pose determines: with J the Jacobian at q (positions over the arm's size, slides
  times it) and J = U Σ Vᵀ, the difference d (wrapped, slides over the arm's size) has each component Vᵀd
  within max(1e-7, 1e-9 / σ_i) (well-determined coordinates to 1e-7, the split of coupled joints to the FK
  acceptance over their conditioning, as ``_recovered`` in test_near_singular.py);
* where a singularity is reported, the free joints take any value and the others follow it, so T is solved again
  with q as reference (free joints take the reference's values): every solution must reach T, and q must come
  back by the criterion above or with every joint the reports leave out within 1e-7 (within
  ``DUPLICATE_TOLERANCE`` where two roots are reported meeting, relation ``boundary``).

Found and fixed:

* the intersecting-wrist UR type (Unitree Z1) with its wrist centre on axis 1 reported q1 free but set it to 0
  whatever the reference, so with q as reference the generating configuration was missing;
* pose targets on the positioning arms of 3–4 joints exactly on their singular sets (a slide at 0, the point on
  axis 1 at q2 = 0/π, the point at the shoulder's centre, the polar offset arm's fold) were answered
  ``unreachable`` with ``complete: true``: the position left a joint free, the positioner held it at 0 (or the
  reference) and the orientation, which fixes it, was not used. The orientation now sets one free joint (no
  wrist, or a roll after it) or two meeting at the point (no wrist); ex004_1_prp, ex004_2_polar_rrp,
  ex004_4_polar_offset_rrp, spong_ex3_2_cylindrical_rpp and both spong_sec4_3 spherical arms;
* where a pose target leaves a joint free that the closed form cannot set and no solution verifies, the answer
  no longer claims ``complete: true``: the fallback answers (``complete: false``) and the condition is reported
  (``test_a_free_joint_the_closed_form_cannot_set_is_reported_not_promised``): ex004_3_spherical_rrpr with the
  point at the shoulder's centre (two free joints and a roll), Unitree Z1 with its wrist centre on axis 1 and no
  reference (q1 held at 0, where the elbow does not reach);
* the polar arms with the slide 1e-12 (of the arm's size) from the shoulder's centre were answered
  ``unreachable`` with ``complete: true``: the position fixed q1 and q2 only to rounding over that distance
  (1e-4 rad), outside every flag's band, and the orientation that fixes them was not used. A point within half
  the acceptance of the centre is now the centre (both joints free, set by the orientation): ex004_2_polar_rrp
  q = [-1.2004773259865509, 2.0998009493042797, -1e-12]; spong_sec4_3_spherical_arm_table3_4_frames
  q = [-0.35685530300652246, 2.417432178046128, -5e-13];
* so101 (rounded geometry, refined from the idealised family) at q2 = π + 1e-9 was answered ``unreachable`` with
  ``complete: true``: the idealised closed form's q1, from the position of a point 1/30 of the arm's size from
  axis 1, is off by about 100 δ, beyond the near-miss margin, so no candidate was refined. A row with nothing
  verified now refines every candidate, and one answered only that way is not promised: the fallback answers,
  ``complete: false``, saying why (``test_a_rounded_arm_whose_closed_form_misses_is_answered_not_promised``).
"""

from __future__ import annotations

import numpy as np
import pytest

from service.config import BUILTIN_ROBOTS_DIR
from service.kinematics import forward_kinematics, geometric_jacobian, joint_screws
from service.kinematics._tolerances import DUPLICATE_TOLERANCE
from service.kinematics.ik import joint_difference, solve_ik
from service.robots.catalogue import load_catalogue

BASES = (0.0, np.pi / 2, np.pi, -np.pi / 2)
SLIDE_BASES = (0.0, 0.25, 0.5, -0.25)
DELTAS = (0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3)
FK_ACCEPTANCE = 1e-9
SEED = 20240611
#: configurations per (joint, singular value, δ)
ROUNDS = 3

_CATALOGUE = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)
ALL_IDS = sorted(entry.description.id for entry in _CATALOGUE.entries())


def _is_closed_form(robot) -> bool:
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, robot.dof)
    q[~robot.is_revolute] = 0.4 * robot.characteristic_length
    return solve_ik(robot, forward_kinematics(robot, q)).method == "analytic"


CLOSED_FORM = [rid for rid in ALL_IDS if _CATALOGUE.get(rid).robot.dof <= 6
               and _is_closed_form(_CATALOGUE.get(rid).robot)]


def test_the_sweep_covers_every_arm_of_six_joints_or_fewer():
    """Only the redundant arms are left out: an arm of ≤ 6 joints falling back to numeric IK is a regression."""
    small = [rid for rid in ALL_IDS if _CATALOGUE.get(rid).robot.dof <= 6]
    assert len(CLOSED_FORM) >= 30 and CLOSED_FORM == small, sorted(set(small) - set(CLOSED_FORM))


def _scaled_jacobian(robot, q: np.ndarray) -> np.ndarray:
    size = robot.characteristic_length
    J = geometric_jacobian(robot, q)
    J = np.concatenate([J[:3] / size, J[3:]])
    return J * np.where(robot.is_revolute, 1.0, size)


def _singular_function(robot, q: np.ndarray) -> np.ndarray:
    """det of the scaled Jacobian (6 joints) or of the tool point's position Jacobian (3 joints), batched."""
    if robot.dof == 6:
        return np.linalg.det(_scaled_jacobian(robot, q))
    directions, points, world_T_tool = joint_screws(robot, q)
    lever = world_T_tool[..., None, :3, 3] - points
    columns = np.where(robot.is_revolute[:, None], np.cross(directions, lever), directions)
    return np.linalg.det(columns)


def _roots(robot, q: np.ndarray, joint: int, count: int = 2) -> list[float]:
    """Values of q[joint] (the others fixed) where the singular function changes sign, to full precision."""
    size = 1.0 if robot.is_revolute[joint] else robot.characteristic_length
    grid = np.linspace(-np.pi, np.pi, 97) if robot.is_revolute[joint] else np.linspace(-1.0, 1.0, 97) * size
    rows = np.repeat(q[None], len(grid), axis=0)
    rows[:, joint] = grid
    values = _singular_function(robot, rows)
    changes = np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)
    roots = []
    for i in changes[:count]:
        lo, hi, f_lo = grid[i], grid[i + 1], values[i]
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            trial = q.copy()
            trial[joint] = mid
            f_mid = _singular_function(robot, trial)
            if np.sign(f_mid) == np.sign(f_lo):
                lo, f_lo = mid, f_mid
            else:
                hi = mid
        roots.append(0.5 * (lo + hi))
    return roots


def _generating(robot, rng) -> list[tuple[str, np.ndarray]]:
    """(label, q) for every joint and singular value plus δ, each on fresh random other joints."""
    size = robot.characteristic_length
    slides = ~robot.is_revolute

    def fresh():
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        q[slides] = rng.uniform(0.2, 1.0, slides.sum()) * size
        return q

    out = []
    for joint in range(robot.dof):
        scale = 1.0 if robot.is_revolute[joint] else size
        for base in (BASES if robot.is_revolute[joint] else SLIDE_BASES):
            for delta in DELTAS:
                q = fresh()
                q[joint] = (base + delta) * scale
                out.append((f"q{joint + 1}={base:+.4f}{delta:+.0e}", q))
    if robot.dof in (3, 6):
        for joint in (1, 2):
            for attempt in range(6):
                q = fresh()
                roots = _roots(robot, q, joint, count=1)
                if roots:
                    break
            scale = 1.0 if robot.is_revolute[joint] else size
            for root in roots:
                for delta in DELTAS:
                    moved = q.copy()
                    moved[joint] = root + delta * scale
                    out.append((f"q{joint + 1}=det-root{delta:+.0e}", moved))
    return out


def _fk_miss(robot, solutions: np.ndarray, target: np.ndarray, size: float) -> np.ndarray:
    """How far each solution (M, n) misses the target (4, 4) by this test's FK, (M,): the position over ``size``, or
    the rotation matrix's largest entry, whichever is larger."""
    reached = forward_kinematics(robot, solutions)
    return np.maximum(np.abs(reached[:, :3, 3] - target[:3, 3]).max(axis=1) / size,
                      np.abs(reached[:, :3, :3] - target[:3, :3]).max(axis=(1, 2)))


def _problem(robot, q: np.ndarray, result) -> str | None:
    """What breaks the promise in ``result`` for FK(q), or None."""
    size = robot.characteristic_length
    target = forward_kinematics(robot, q)
    solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
    if result.status != "ok" or len(solutions) == 0:
        return f"no solution ({result.status}, complete={result.complete})"
    miss = _fk_miss(robot, solutions, target, size)
    if miss.max() > FK_ACCEPTANCE:
        return f"FK miss {miss.max():.1e} ({int((miss > FK_ACCEPTANCE).sum())} of {len(solutions)})"
    d = joint_difference(robot, solutions, q) / np.where(robot.is_revolute, 1.0, size)
    _, sigma, vt = np.linalg.svd(_scaled_jacobian(robot, q))
    sigma = np.r_[sigma, np.zeros(robot.dof - len(sigma))]
    tolerance = np.maximum(1e-7, FK_ACCEPTANCE / np.maximum(sigma, 1e-300))
    if (np.abs(d @ vt.T) <= tolerance).all(axis=1).any():
        return None
    if result.singularities:
        # the reported joints are free or coupled, the rest follow the values they take: with q as reference
        # the free ones take q's values, so q itself must come back (up to what the pose determines)
        again = solve_ik(robot, target, reference=q)
        back = np.array([s.joints for s in again.solutions]).reshape(-1, robot.dof)
        if len(back):
            miss = _fk_miss(robot, back, target, size)
            if miss.max() > FK_ACCEPTANCE:
                return f"FK miss {miss.max():.1e} with q as reference"
            d = joint_difference(robot, back, q) / np.where(robot.is_revolute, 1.0, size)
            if (np.abs(d @ vt.T) <= tolerance).all(axis=1).any():
                return None
        coupled = sorted({j for s in again.singularities for j in s.joints})
        held = DUPLICATE_TOLERANCE if any(s.relation == "boundary" for s in again.singularities) else 1e-7
        others = np.delete(np.abs(d), coupled, axis=1).max(axis=1, initial=0.0) if len(back) else [np.inf]
        if np.min(others) <= held:
            return None
        kinds = ",".join(f"{s.kind}{s.joints}{s.relation}" for s in again.singularities)
        return f"generating configuration missing with q as reference, reported {kinds} (off {np.min(others):.1e})"
    if not result.complete:
        return None  # no promise made; counted below
    closest = np.abs(d).max(axis=1).min()
    return f"generating configuration missing, complete, nothing reported ({len(solutions)} solutions, off {closest:.1e})"


@pytest.mark.parametrize("robot_id", CLOSED_FORM)
def test_catalogue_arm_on_its_singular_sets_keeps_every_solution(robot_id):
    robot = _CATALOGUE.get(robot_id).robot
    rng = np.random.default_rng([SEED, ALL_IDS.index(robot_id)])
    failures, incomplete = [], 0
    cases = [case for _ in range(ROUNDS) for case in _generating(robot, rng)]
    assert len(cases) >= 200, len(cases)
    for label, q in cases:
        result = solve_ik(robot, forward_kinematics(robot, q))
        incomplete += not result.complete  # (a numeric fallback among them)
        problem = _problem(robot, q, result)
        if problem:
            failures.append((label, q.tolist(), problem))
    assert not failures, f"{len(failures)} of {len(cases)}: " + "\n".join(map(str, failures[:40]))
    # an analytic answer that gives up its promise is allowed only where it says why: near a singular set, rarely
    assert incomplete <= len(cases) // 10, (incomplete, len(cases))


#: (robot id, q): pose targets whose free joint the closed form cannot set (see the module docstring)
UNSET_FREE = [
    ("ex004_3_spherical_rrpr", [1.8081504193373166, 1.3882641748024298, 0.0, -1.0647370003086811]),
    ("unitree_z1", [0.3286158210121557, -1.5630857378251153, -2.702076647467699, -1.1563599559027478,
                    2.579055835984403, 0.4534670036914106]),
]


@pytest.mark.parametrize(("robot_id", "q"), UNSET_FREE)
def test_a_free_joint_the_closed_form_cannot_set_is_reported_not_promised(robot_id, q):
    """Never ``unreachable`` with ``complete: true``: the answer finds q's pose and says why it is not complete."""
    robot = _CATALOGUE.get(robot_id).robot
    q = np.array(q)
    result = solve_ik(robot, forward_kinematics(robot, q))
    assert not (result.status == "unreachable" and result.complete)
    assert result.status == "ok" and _problem(robot, q, result) is None, _problem(robot, q, result)
    if not result.complete:
        assert any(s.relation == "free" for s in result.singularities), result.singularities


#: (robot id, q): rounded arms whose idealised closed form misses every solution by more than the near-miss margin
MISSED_BY_THE_IDEALISED_FORM = [
    ("so101", [1.3326501794110595, 3.141592654589793, -1.5136825495925217, -1.130837883586524,
               1.8771418030623932]),
]


@pytest.mark.parametrize(("robot_id", "q"), MISSED_BY_THE_IDEALISED_FORM)
def test_a_rounded_arm_whose_closed_form_misses_is_answered_not_promised(robot_id, q):
    """Never ``unreachable`` with ``complete: true``: q's pose is answered with q, and the answer says why it is
    not complete (the idealised family's margins did not hold), with or without q as reference."""
    robot = _CATALOGUE.get(robot_id).robot
    q = np.array(q)
    for reference in (None, q):
        result = solve_ik(robot, forward_kinematics(robot, q), reference=reference)
        assert result.status == "ok" and _problem(robot, q, result) is None, _problem(robot, q, result)
        assert not result.complete and "cannot promise every solution" in result.detail, result.detail
