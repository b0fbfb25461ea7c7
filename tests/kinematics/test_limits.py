"""Joint limits in the core: bounds, 2π-equivalents and selection of IK answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from service.kinematics import (
    LIMIT_TOLERANCE,
    InvalidInputError,
    Joint,
    Limits,
    Robot,
    check_limits,
    closest_equivalent,
    nearest_fitting_equivalent,
    turn_ranges,
    violations,
    within,
)
from service.kinematics.ik import IKResult, Ordering, Solution
from tests.selection import select

DEG = math.pi / 180


def arm(*limits: tuple[str, float, float]) -> Robot:
    """A chain of joints with the given (kind, lower, upper); links of 0.5 so the robot has a size."""
    return Robot([Joint(f"q{i + 1}", kind, 0.5, 0.0, 0.0, 0.0, lower, upper)
                  for i, (kind, lower, upper) in enumerate(limits)], name="test arm")


# A ±270° joint, a slide, a continuous joint, a joint bounded below only, a ±100° joint.
MIXED = arm(("revolute", -270 * DEG, 270 * DEG), ("prismatic", 0.1, 1.0), ("revolute", -math.inf, math.inf),
            ("revolute", 0.0, math.inf), ("revolute", -100 * DEG, 100 * DEG))


def test_turn_ranges_per_kind_of_joint():
    q = np.array([100 * DEG, 0.5, 3.0, -10 * DEG, 120 * DEG])
    first, last = turn_ranges(MIXED, Limits.of(MIXED), q)
    np.testing.assert_array_equal(first[:4], [-1, 0, 0, 1])
    np.testing.assert_array_equal(last[:4], [0, 0, 0, 1])
    # −260° and 100° within ±270°; a slide keeps its value; continuous: never expanded; one side only: the
    # nearest that fits, 350°
    np.testing.assert_allclose(q[3] + 2 * np.pi * first[3], 350 * DEG)
    assert last[4] < first[4]  # 120° has no equivalent in ±100°


@pytest.mark.parametrize("robot", [
    arm(*[("revolute", -170 * DEG, 170 * DEG)] * 6),  # every joint bounded within a turn
    arm(("revolute", -170 * DEG, 170 * DEG), ("revolute", -math.inf, math.inf), ("revolute", -120 * DEG, 120 * DEG),
        ("prismatic", 0.1, 1.0), ("revolute", -100 * DEG, 100 * DEG)),  # some bounded, the others not
    MIXED], ids=["bounded", "partly bounded", "mixed"])
def test_the_one_turn_shortcut_gives_the_quotients_turns(robot, monkeypatch):
    """A large batch whose bounded values all sit well inside limits of about one turn takes every such turn as
    0 without the quotients: the same (first, last), bit for bit (+0.0), as the quotients, for batches that take
    the shortcut and batches one value near a bound keeps from it."""
    rng = np.random.default_rng(4)
    limits = Limits.of(robot)
    inside = np.clip(rng.uniform(-1.5, 1.5, (2_000, robot.dof)), np.maximum(robot.lower, -1.5) + 0.01,
                     np.minimum(robot.upper, 1.5) - 0.01)
    near_bound = inside.copy()
    near_bound[7, 0] = robot.upper[0] - 1e-9
    for q in (inside, near_bound):
        _assert_the_shortcut_gives_the_quotients_turns(robot, limits, q, monkeypatch)


@pytest.mark.parametrize("robot", [
    arm(*[("revolute", -math.pi, math.pi)] * 6),  # ±π: the one-turn interval is the whole range, less its margin
    arm(*[("revolute", -170 * DEG, 170 * DEG)] * 5, ("revolute", -266 * DEG, 266 * DEG)),  # a PUMA's joint 6
    MIXED], ids=["pi", "one joint over a turn", "mixed"])
def test_the_one_turn_shortcut_on_one_targets_few_rows(robot, monkeypatch):
    """One target's few rows (as a single-pose answer selects) take the shortcut too: the same (first, last), bit
    for bit, as the quotients, for rows inside the limits, on a bound, a hair inside the one-turn interval's
    margin, and outside."""
    rng = np.random.default_rng(11)
    limits = Limits.of(robot)
    lower, upper = np.maximum(robot.lower, -4.0), np.minimum(robot.upper, 4.0)
    rows = [rng.uniform(lower, upper, (8, robot.dof)), np.tile(robot.lower, (2, 1)), np.tile(robot.upper, (2, 1)),
            rng.uniform(-7.0, 7.0, (8, robot.dof))]
    near_margin = rng.uniform(lower, upper, (4, robot.dof))
    near_margin[:, 0] = robot.upper[0] - np.array([0.5e-6, 1e-6, 2e-6, 1e-3])
    for q in (*rows, near_margin, np.zeros((1, robot.dof)), np.zeros((0, robot.dof))):
        q = np.where(np.isfinite(q), q, 0.5)
        _assert_the_shortcut_gives_the_quotients_turns(robot, limits, q, monkeypatch)


def _assert_the_shortcut_gives_the_quotients_turns(robot, limits, q, monkeypatch):
    """turn_ranges of q with its one-turn shortcut and without it (the quotients alone): the same, bit for bit."""
    from service.kinematics import _limits

    shortcut = turn_ranges(robot, limits, q)
    monkeypatch.setattr(_limits, "_CHECKED_FROM", math.inf)
    quotients = turn_ranges(robot, limits, q)
    monkeypatch.undo()
    for a, b in zip(shortcut, quotients):
        assert a.tobytes() == b.tobytes()


@pytest.mark.parametrize("robot", [
    arm(*[("revolute", -math.pi, math.pi)] * 6),
    arm(*[("revolute", -170 * DEG, 170 * DEG)] * 5, ("revolute", -266 * DEG, 266 * DEG)),
    arm(*[("revolute", -2 * math.pi, 2 * math.pi)] * 6),
    arm(("revolute", 10 * DEG, 20 * DEG), ("revolute", -5 * math.pi, 3 * math.pi), ("revolute", -1e6, 1e6),
        ("revolute", -math.inf, 30 * DEG), ("revolute", -30 * DEG, math.inf), ("prismatic", -0.2, 0.3)),
    MIXED], ids=["pi", "one joint over a turn", "two pi", "assorted", "mixed"])
def test_turn_ranges_on_floats_are_the_arrays_turns(robot):
    """``turns_of_row`` (one target's rows on Python floats) against ``turn_ranges`` and ``closest_turns`` on
    random rows, rows on each bound and a tolerance either side of it, whole turns away from them, and far
    outside: a row that fits gets its turn ranges, one that does not its closest turns, the same bit for bit;
    None for a value that is not finite where its joint takes a quotient."""
    from service.kinematics._limits import closest_turns, turns_of_row

    rng = np.random.default_rng(23)
    limits = Limits.of(robot)
    bounds = limits.widened(robot)
    lower, upper = np.maximum(robot.lower, -8.0), np.minimum(robot.upper, 8.0)
    tolerance = limits.tolerance(robot)
    edges = [robot.lower, robot.upper, robot.lower - tolerance, robot.upper + tolerance,
             robot.lower - 1.0001 * tolerance, robot.upper + 1.0001 * tolerance,
             robot.lower + 2 * np.pi, robot.upper - 2 * np.pi, robot.lower - 2 * np.pi]
    rows = np.concatenate([rng.uniform(lower, upper, (200, robot.dof)), rng.uniform(-20, 20, (200, robot.dof)),
                           *(np.where(np.isfinite(edge), edge, 0.5)[None] for edge in edges),
                           rng.uniform(-1e3, 1e3, (20, robot.dof))])
    first, last = turn_ranges(robot, limits, rows)
    fits = (last >= first).all(axis=1)
    closest = closest_turns(robot, limits, rows, first, last)
    assert fits.any()
    if not np.all(robot.upper - robot.lower >= 2 * np.pi):  # a joint some value cannot reach: rows that misfit
        assert not fits.all()
    for row, row_fits, row_first, row_last, row_closest in zip(rows.tolist(), fits, first, last, closest):
        got = turns_of_row(bounds, row)
        assert got is not None and got[2] == row_fits
        expected = (row_first, row_last) if row_fits else (row_closest, row_closest)
        assert np.array(got[0]).tobytes() == expected[0].tobytes()
        assert np.array(got[1]).tobytes() == expected[1].tobytes()
    quotient_joints = np.flatnonzero(robot.is_revolute & ~bounds.continuous)
    for bad in (math.nan, math.inf, -math.inf):
        row = rows[0].tolist()
        row[quotient_joints[0]] = bad
        assert turns_of_row(bounds, row) is None


def test_turn_ranges_count_huge_limits_without_generating_them():
    wide = arm(("revolute", -1e6, 1e6))
    first, last = turn_ranges(wide, Limits.of(wide), np.array([0.5]))
    # 0.5 + 2kπ ∈ [−1e6, 1e6] for k from ceil((−1e6 − 0.5)/2π) to floor((1e6 − 0.5)/2π)
    assert (first[0], last[0]) == (math.ceil((-1e6 - 0.5) / (2 * math.pi)), math.floor((1e6 - 0.5) / (2 * math.pi)))
    assert last[0] - first[0] + 1 == 318310


def test_a_prismatic_joint_is_never_wrapped():
    """d = 1.0 + 2π is out of [0.1, 1.0]; its value minus 2π would fit, but a slide has no turns."""
    q = np.array([0.0, 0.5 + 2 * np.pi, 0.0, 0.0, 0.0])
    first, last = turn_ranges(MIXED, Limits.of(MIXED), q)
    assert last[1] < first[1]
    assert nearest_fitting_equivalent(MIXED, Limits.of(MIXED), q) is None
    np.testing.assert_array_equal(closest_equivalent(MIXED, Limits.of(MIXED), q)[1], q[1])


def test_closest_equivalent_fixes_what_turns_can_fix_and_nothing_else():
    limits = Limits.of(MIXED)
    q = np.array([300 * DEG, 0.5, 3.0, -10 * DEG, 250 * DEG])
    closest = closest_equivalent(MIXED, limits, q)
    # 300° → −60° (the only equivalent in ±270°); 250° has none in ±100°: −110° is the smallest violation.
    np.testing.assert_allclose(closest, [-60 * DEG, 0.5, 3.0, 350 * DEG, -110 * DEG])
    assert [v.joint for v in violations(MIXED, limits, closest)] == [4]
    assert [v.joint for v in violations(MIXED, limits, q)] == [0, 3, 4]
    # 120° against ±100°: 120° (20° over) beats −240° (140° under).
    assert closest_equivalent(MIXED, limits, np.array([0, 0.5, 0, 0, 120 * DEG]))[4] == pytest.approx(120 * DEG)


def test_nearest_fitting_equivalent_picks_the_nearest_of_several():
    ur5 = arm(*[("revolute", -2 * np.pi, 2 * np.pi)] * 6)
    q = np.array([7.0, -7.0, 0.0, 1.0, 2 * np.pi, -3.0])
    nearest = nearest_fitting_equivalent(ur5, Limits.of(ur5), q)
    # 7 − 2π = 0.717 and 7 − 4π = −5.566 both fit; the nearest to 7 is 0.717.
    np.testing.assert_allclose(nearest, [7.0 - 2 * np.pi, -7.0 + 2 * np.pi, 0.0, 1.0, 2 * np.pi, -3.0])


def test_a_batch_check_is_each_rows_check():
    """check_limits (the limits endpoint's batch, every row at once) gives each row what within, violations and
    nearest_fitting_equivalent give it alone: the mixed arm's kinds of joint, values on and just past the bounds
    (the tolerance), whole turns away, and rows no turn fixes."""
    limits = Limits.of(MIXED)
    rng = np.random.default_rng(3)
    q = rng.uniform(-12, 12, (400, 5))
    q[:, 1] = rng.uniform(0.0, 1.1, 400)  # the slide: inside, and a little out on either side
    q[::7, 0] = 270 * DEG + rng.choice([-1, 1], len(q[::7])) * LIMIT_TOLERANCE * rng.choice([0.5, 2.0], len(q[::7]))
    q[::5] = 0.5 * (limits.lower + np.where(np.isfinite(limits.upper), limits.upper, limits.lower + 1.0))
    q[::5, 2:4] = [1.0, 0.5]
    check = check_limits(MIXED, limits, q)
    assert check.inside.any() and (~check.inside & check.fits).any() and (~check.inside & ~check.fits).any()
    for row in range(len(q)):
        assert bool(check.inside[row]) == bool(within(MIXED, limits, q[row]))
        assert check.violations(row) == violations(MIXED, limits, q[row])
        nearest = None if check.inside[row] else nearest_fitting_equivalent(MIXED, limits, q[row])
        if nearest is None:
            assert not check.fits[row] and np.isnan(check.equivalent[row]).all()
        else:
            assert check.fits[row] and np.array_equal(check.equivalent[row], nearest)


def test_bounds_are_inclusive_with_the_documented_tolerance():
    limits = Limits.of(MIXED)
    size = MIXED.characteristic_length
    inside = np.array([270 * DEG + 0.5 * LIMIT_TOLERANCE, 1.0 + 0.5 * LIMIT_TOLERANCE * size, 0, 0, -100 * DEG])
    outside = np.array([270 * DEG + 2 * LIMIT_TOLERANCE, 1.0 + 2 * LIMIT_TOLERANCE * size, 0, 0, -100 * DEG])
    assert within(MIXED, limits, inside) and not violations(MIXED, limits, inside)
    assert not within(MIXED, limits, outside)
    broken = violations(MIXED, limits, outside)
    assert [(v.joint, v.value, v.lower, v.upper) for v in broken] == [
        (0, outside[0], -270 * DEG, 270 * DEG), (1, outside[1], 0.1, 1.0)]


def test_checked_limits_name_the_joint():
    with pytest.raises(InvalidInputError, match=r"joint 1 \(q2\): lower limit 2 is greater than upper limit 1") as e:
        Limits.checked(MIXED, [-1, 2, -1, -1, -1], [1, 1, 1, 1, 1])
    assert e.value.location == (1,)
    with pytest.raises(InvalidInputError, match=r"joint 3 \(q4\): limits must be numbers, not NaN"):
        Limits.checked(MIXED, [-1, 0, -1, np.nan, -1], [1, 1, 1, 1, 1])
    with pytest.raises(InvalidInputError, match="expected limits for 5 joints"):
        Limits.checked(MIXED, [-1, 0], [1, 1])
    locked = Limits.checked(MIXED, [0.5] * 5, [0.5] * 5)  # lower == upper: a locked joint is allowed
    assert within(MIXED, locked, np.full(5, 0.5))


def test_without_a_reference_fewest_turns_first_and_capped():
    two = arm(("revolute", -2 * np.pi, 2 * np.pi), ("revolute", -2 * np.pi, 2 * np.pi))
    result = IKResult("ok", [Solution(np.array([1.0, -2.0]), {}, 0.0, 0.0)], "analytic", "test", True)
    every = select(two, result, Limits.of(two), max_equivalents=10)
    # turns: q1 = 1 takes k ∈ {−1, 0}, q2 = −2 takes k ∈ {0, 1}; by Σ|k|, ties by the lower value first
    np.testing.assert_allclose([e.solution.joints for e in every.solutions],
                               [[1.0, -2.0], [1.0, -2.0 + 2 * np.pi], [1.0 - 2 * np.pi, -2.0],
                                [1.0 - 2 * np.pi, -2.0 + 2 * np.pi]])
    assert not every.expansion_truncated
    capped = select(two, result, Limits.of(two), max_equivalents=3)
    np.testing.assert_allclose([e.solution.joints for e in capped.solutions],
                               [e.solution.joints for e in every.solutions[:3]])
    assert capped.expansion_truncated and capped.available == 4


# --- selection of IK answers -------------------------------------------------------------------------------

def result_of(*joint_vectors) -> IKResult:
    solutions = [Solution(np.array(q, dtype=float), {"branch": i}, 0.0, 0.0) for i, q in enumerate(joint_vectors)]
    return IKResult("ok", solutions, "analytic", "test", True)


TWO_TURN = arm(("revolute", -2 * np.pi, 2 * np.pi), ("revolute", -2 * np.pi, 2 * np.pi))


def test_select_expands_every_solution_and_rejects_what_no_turn_fixes():
    wrist = arm(("revolute", -2 * np.pi, 2 * np.pi), ("revolute", -100 * DEG, 100 * DEG))
    selection = select(wrist, result_of([1.0, 0.5], [1.0, 120 * DEG], [-1.0, 250 * DEG]), Limits.of(wrist))
    assert selection.status == "ok"
    np.testing.assert_allclose([s.solution.joints for s in selection.solutions],
                               [[1.0, 0.5], [1.0 - 2 * np.pi, 0.5]])
    assert [(r.solution.branch, r.within_limits) for r in selection.rejected] == [({"branch": 1}, False),
                                                                                  ({"branch": 2}, False)]
    # the third is shown turned to −110°, its smallest violation; joint 0 still reads −1 (it fits as it is)
    np.testing.assert_allclose(selection.rejected[1].solution.joints, [-1.0, -110 * DEG])
    assert [v.joint for v in selection.rejected[1].violations] == [1]
    assert selection.available == 2 and not selection.expansion_truncated and selection.trimmed == 0


def test_select_all_rejected_and_unfiltered():
    narrow = arm(("revolute", -0.1, 0.1))
    result = result_of([0.5], [-0.5])
    selection = select(narrow, result, Limits.of(narrow))
    assert selection.status == "no_solution_within_limits" and not selection.solutions
    assert len(selection.rejected) == 2 and "All 2 solutions violate" in selection.notes[0]
    unfiltered = select(narrow, result, Limits.of(narrow), filter_limits=False)
    assert unfiltered.status == "ok" and not unfiltered.rejected
    assert [(s.within_limits, [v.joint for v in s.violations]) for s in unfiltered.solutions] == [
        (False, [0]), (False, [0])]


def test_cap_keeps_the_nearest_with_a_reference():
    result = result_of([1.0, -2.0], [-1.5, 2.5], [3.0, 0.2])
    reference = np.array([-5.0, 4.0])
    full = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=reference)
    assert len(full.solutions) == 12 and not full.expansion_truncated
    distances = [np.abs(s.solution.joints - reference).max() for s in full.solutions]
    assert distances == sorted(distances)
    capped = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=reference, max_equivalents=5)
    assert capped.expansion_truncated and capped.available == 12 and capped.trimmed == 0
    np.testing.assert_array_equal([s.solution.joints for s in capped.solutions],
                                  [s.solution.joints for s in full.solutions[:5]])
    assert "12 solutions fit; the cap of 5 on 2π-equivalents kept the nearest 5" in capped.notes[0]


def test_cap_without_reference_keeps_every_branch_before_any_second_turn():
    result = result_of([1.0, -2.0], [-1.5, 2.5], [3.0, 0.2])
    capped = select(TWO_TURN, result, Limits.of(TWO_TURN), max_equivalents=4)
    np.testing.assert_array_equal([s.solution.joints for s in capped.solutions[:3]], [[1.0, -2.0], [-1.5, 2.5],
                                                                                      [3.0, 0.2]])
    assert capped.solutions[3].solution.branch == {"branch": 0} and capped.expansion_truncated


def test_max_solutions_and_max_joint_move_are_counted_as_trimmed():
    result = result_of([1.0, -2.0], [-1.5, 2.5], [3.0, 0.2])
    reference = np.array([0.0, 0.0])
    full = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=reference)
    nearest = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=reference, ordering=Ordering(max_solutions=2))
    assert [s.solution.branch for s in nearest.solutions] == [s.solution.branch for s in full.solutions[:2]]
    assert nearest.trimmed == 10 and not nearest.expansion_truncated
    move = Ordering(max_joint_move=np.array([2.0, 2.6]))
    bounded = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=reference, ordering=move)
    # within |Δ0| ≤ 2 and |Δ1| ≤ 2.6: (1, −2) and (−1.5, 2.5) only
    np.testing.assert_array_equal([s.solution.joints for s in bounded.solutions], [[1.0, -2.0], [-1.5, 2.5]])
    assert bounded.trimmed == 10 and bounded.available == 2
    nothing = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=reference,
                     ordering=Ordering(max_joint_move=np.zeros(2)))
    assert nothing.status == "ok" and nothing.solutions == [] and nothing.trimmed == 12
    assert "none is within the joint move or among the solutions allowed near the reference" in nothing.notes[0]


def test_continuous_joints_are_measured_across_the_wrap():
    spinning = arm(("revolute", -math.inf, math.inf), ("revolute", -math.inf, math.inf))
    result = result_of([np.pi - 0.1, 0.5], [-np.pi + 0.4, -0.5])
    selection = select(spinning, result, Limits.of(spinning), reference=np.array([-np.pi + 0.05, 0.5]))
    assert len(selection.solutions) == 2  # never expanded
    assert [s.solution.branch for s in selection.solutions] == [{"branch": 0}, {"branch": 1}]
    # the same joint with ±360° limits is a different thing: π − 0.1 − 2π is the nearer equivalent
    nearest = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=np.array([-np.pi + 0.05, 0.5]))
    np.testing.assert_allclose(nearest.solutions[0].solution.joints, [-np.pi - 0.1, 0.5])


@pytest.mark.parametrize("ordering, reference, location, message", [
    (Ordering(max_solutions=1), None, ("max_solutions",), "needs a reference"),
    (Ordering(max_joint_move=np.ones(2)), None, ("max_joint_move",), "needs a reference"),
    (Ordering(weights=np.ones(2)), None, ("weights",), "needs a reference"),
    (Ordering(weights=np.ones(3)), np.zeros(2), ("weights",), "expected 2 values of weights"),
    (Ordering(weights=np.array([1.0, -1.0])), np.zeros(2), ("weights", 1), "≥ 0"),
    (Ordering(weights=np.array([1.0, np.inf])), np.zeros(2), ("weights", 1), "finite"),
    (Ordering(max_joint_move=np.array([np.nan, 1.0])), np.zeros(2), ("max_joint_move", 0), "≥ 0"),
    (Ordering(max_solutions=-1), np.zeros(2), ("max_solutions",), "≥ 0"),
])
def test_select_refuses_bad_orderings(ordering, reference, location, message):
    with pytest.raises(InvalidInputError, match=message) as error:
        select(TWO_TURN, result_of([0.0, 0.0]), Limits.of(TWO_TURN), reference=reference, ordering=ordering)
    assert error.value.location == location


@pytest.mark.parametrize("max_solutions, cap, kept, truncated, trimmed", [
    (3, 5, 3, False, 9),    # max_solutions is the tighter: its cut is counted as trimmed
    (5, 5, 5, False, 7),    # equal: the user asked for k, so nothing was lost to the cap
    (8, 5, 5, True, 0),     # the cap is the tighter: truncated, and nothing counts as trimmed
    (20, 50, 12, False, 0),
])
def test_cap_and_max_solutions_say_which_one_cut(max_solutions, cap, kept, truncated, trimmed):
    result = result_of([1.0, -2.0], [-1.5, 2.5], [3.0, 0.2])
    selection = select(TWO_TURN, result, Limits.of(TWO_TURN), reference=np.zeros(2),
                       ordering=Ordering(max_solutions=max_solutions), max_equivalents=cap)
    assert (len(selection.solutions), selection.expansion_truncated, selection.trimmed) == (kept, truncated, trimmed)
    assert selection.available == 12


def test_limits_applied_to_two_robots_widen_for_each():
    """Limits keep the bounds they have applied to each robot (an answer applies them half a dozen times): the
    same limits on two arms of different sizes widen a slide by each arm's own tolerance, each time asked, and
    equal limits made anew find the robot's kept bounds."""
    small = arm(("prismatic", 0.1, 1.0), ("revolute", -1.0, 1.0))
    large = Robot([Joint("q1", "prismatic", 50.0, 0.0, 0.0, 0.0, 0.1, 1.0),
                   Joint("q2", "revolute", 50.0, 0.0, 0.0, 0.0, -1.0, 1.0)], name="large arm")
    limits = Limits(np.array([0.1, -1.0]), np.array([1.0, 1.0]))
    for _ in range(2):
        for robot in (small, large):
            widened = limits.widened(robot)
            np.testing.assert_array_equal(widened.lower, limits.lower - limits.tolerance(robot))
            assert widened.equivalents_per_solution == 1
    assert limits.widened(small).lower[0] != limits.widened(large).lower[0]
    assert Limits(limits.lower.copy(), limits.upper.copy()).widened(large) is limits.widened(large)


def test_limits_applied_to_many_robots_keep_a_few():
    """The bounds a Limits keeps per robot stay few however many robots it is applied to (a Limits kept long,
    say), and each robot still gets its own."""
    from service.kinematics import _limits

    limits = Limits(np.array([-1.0]), np.array([1.0]))
    for index in range(3 * _limits._WIDENED_KEPT):
        robot = Robot([Joint("q1", "prismatic", 0.5 + index, 0.0, 0.0, 0.0, -1.0, 1.0)], name=f"slide {index}")
        assert limits.widened(robot).lower[0] == -1.0 - limits.tolerance(robot)[0]
        assert len(limits._applied) <= _limits._WIDENED_KEPT


def test_limits_as_wide_as_floats_go_count_their_equivalents_capped():
    """Bounds at the ends of the float range (their span overflows to infinity) widen, count the cap of
    equivalents and give a value its turns, as the arrays do."""
    from service.kinematics import COUNT_CAP
    from service.kinematics._limits import turns_of_row

    wide = arm(("revolute", -1.7e308, 1.7e308), ("revolute", -1e300, 1e300), ("revolute", -1.0, 1.0))
    limits = Limits.of(wide)
    bounds = limits.widened(wide)
    assert bounds.equivalents_per_solution == COUNT_CAP
    q = np.array([[0.5, -0.5, 0.25]])
    first, last = turn_ranges(wide, limits, q)
    got = turns_of_row(bounds, q[0].tolist())
    assert got is not None and got[2]
    assert got[0] == first[0].tolist() and got[1] == last[0].tolist()
