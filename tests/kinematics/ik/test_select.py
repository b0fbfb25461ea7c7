"""Selection against a brute-force oracle: every 2π-equivalent enumerated explicitly, filtered, sorted, cut.

The oracle follows the rules of :mod:`service.kinematics.ik._select`'s docstring with its own loops.
"""

from __future__ import annotations

import itertools
import time
import tracemalloc

import numpy as np
import pytest

from service.kinematics import COUNT_CAP, LIMIT_TOLERANCE, Joint, Limits, Robot, forward_kinematics
from service.kinematics.ik import IKResult, Ordering, Solution, solve_ik_arrays
from tests.selection import select, select_arrays, select_table, table_of_arrays
from service.robots.catalogue import load_catalogue
from service.config import Settings

INF = np.inf
TWO_PI = 2 * np.pi
KINDS = [(-np.pi, np.pi), (-TWO_PI, TWO_PI), (-3 * np.pi, 3 * np.pi), (-INF, INF), (0.0, INF), (-INF, 1.0),
         (-1.5, 2.0), (-20.0, 3.0)]


def random_case(rng):
    n = int(rng.integers(1, 5))
    joints = []
    for i in range(n):
        if rng.random() < 0.15:
            lower, upper = sorted(rng.uniform(-1, 2, 2))
            joints.append(Joint(f"q{i}", "prismatic", 0.5, 0.0, 0.0, 0.0, lower, upper))
        else:
            lower, upper = KINDS[rng.integers(len(KINDS))]
            joints.append(Joint(f"q{i}", "revolute", 0.5, 0.0, 0.0, 0.0, lower, upper))
    robot = Robot(joints, name="random arm")
    solutions = [Solution(rng.uniform(-np.pi, np.pi, n), {"slot": str(s)}, 0.0, 0.0)
                 for s in range(int(rng.integers(1, 5)))]
    options = {"filter_limits": bool(rng.random() < 0.6), "max_equivalents": int(rng.integers(1, 30))}
    if rng.random() < 0.7:
        options["reference"] = rng.uniform(-4, 4, n)
        options["ordering"] = Ordering(
            str(rng.choice(["linf", "l2"])), rng.uniform(0, 2, n) if rng.random() < 0.4 else None,
            int(rng.integers(0, 20)) if rng.random() < 0.4 else None,
            np.where(rng.random(n) < 0.5, rng.uniform(0, 6, n), INF) if rng.random() < 0.4 else None)
    return robot, IKResult("ok", solutions, "analytic", "test", True), options


def within_limits(robot, reference):
    """The reference with each two-sided revolute joint outside its limits moved to its equivalent within them
    nearest its value, where there is one (the selection's rule for a reference the arm cannot be at)."""
    if reference is None:
        return None
    tolerance = LIMIT_TOLERANCE
    moved = np.array(reference, dtype=float)
    for j in range(robot.dof):
        lower, upper = robot.lower[j], robot.upper[j]
        if not (robot.is_revolute[j] and np.isfinite(lower) and np.isfinite(upper)):
            continue
        if lower - tolerance <= moved[j] <= upper + tolerance:
            continue
        fitting = [moved[j] + TWO_PI * k for k in range(-12, 13)
                   if lower - tolerance <= moved[j] + TWO_PI * k <= upper + tolerance]
        if fitting:
            moved[j] = min(fitting, key=lambda value: abs(value - reference[j]))
    return moved


def oracle(robot, result, options):
    """(kept rows [(joints, within, cost)], rejected joints, available, with_all_moves) by explicit enumeration."""
    lower, upper = robot.lower, robot.upper
    tolerance = np.where(robot.is_revolute, LIMIT_TOLERANCE, LIMIT_TOLERANCE * robot.characteristic_length)
    reference, ordering = options.get("reference"), options.get("ordering", Ordering())
    weights = np.ones(robot.dof) if ordering.weights is None else ordering.weights
    move = np.full(robot.dof, INF) if ordering.max_joint_move is None else ordering.max_joint_move
    continuous = robot.is_revolute & np.isinf(lower) & np.isinf(upper)

    def inside(j, value):
        return lower[j] - tolerance[j] <= value <= upper[j] + tolerance[j]

    reference = within_limits(robot, reference)

    def turns_of(j, value):  # every usable k, explicitly
        if not robot.is_revolute[j]:
            return [0] if inside(j, value) else []
        fitting = [k for k in range(-12, 13) if inside(j, value + TWO_PI * k)]
        if np.isfinite(lower[j]) and np.isfinite(upper[j]):
            return fitting
        return [min(fitting, key=abs)]  # one side or none: the one nearest the value

    def distance(j, value):
        d = abs(value - reference[j])
        return (min(d % TWO_PI, TWO_PI - d % TWO_PI) if continuous[j] else d) * weights[j]

    def closest_turn(j, value):
        fitting = turns_of(j, value)
        if fitting:
            return min(fitting, key=lambda k: (abs(k), k))
        if not robot.is_revolute[j]:
            return 0
        return min(range(-12, 13), key=lambda k: max(lower[j] - value - TWO_PI * k, value + TWO_PI * k - upper[j]))

    streams, rejected, with_all_moves = [], [], 0
    for index, solution in enumerate(result.solutions):
        q = solution.joints
        per_joint = [turns_of(j, q[j]) for j in range(robot.dof)]
        fits = all(per_joint)
        if not fits:
            closest = q + TWO_PI * np.array([closest_turn(j, q[j]) for j in range(robot.dof)])
            if options["filter_limits"]:
                rejected.append(closest)
                continue
            per_joint = [[closest_turn(j, q[j])] for j in range(robot.dof)]
        combos = [np.array(k, dtype=float) for k in itertools.product(*per_joint)]
        with_all_moves += len(combos)
        rows = []
        for k in combos:
            values = q + TWO_PI * k
            if reference is not None:
                if any(abs(values[j] - reference[j]) > move[j] + tolerance[j] if not continuous[j] else
                       distance(j, values[j]) / (weights[j] or 1) > move[j] + tolerance[j]
                       for j in range(robot.dof)):
                    continue
                d = [distance(j, values[j]) for j in range(robot.dof)]
                cost = max(d) if ordering.norm == "linf" else float(np.sqrt(np.sum(np.square(d))))
            else:
                cost = float(np.sum(np.abs(k)))
            ranks = tuple(sorted(per_joint[j], key=lambda t: (abs(t), t)).index(k[j]) for j in range(robot.dof))
            rows.append((values, fits, cost, ranks))
        streams.append(rows)
    available = sum(len(rows) for rows in streams)
    limit = options["max_equivalents"] if ordering.max_solutions is None else min(options["max_equivalents"],
                                                                                 ordering.max_solutions)
    if reference is not None:
        every = sorted(((row, s) for s, rows in enumerate(streams) for row in rows), key=lambda e: e[0][2])
        kept = [row for row, _ in every[:limit]]
        rejected.sort(key=lambda r: (max if ordering.norm == "linf" else np.linalg.norm)(
            [distance(j, r[j]) for j in range(robot.dof)]))
    else:
        # each stream by (Σ|k|, ranks lexicographically), a joint's values ranked by (|k|, k)
        ranked = [sorted(rows, key=lambda r: (r[2], r[3])) for rows in streams]
        kept = [rows[i] for i in range(max(map(len, ranked), default=0)) for rows in ranked if i < len(rows)][:limit]
    return kept, rejected, available, with_all_moves, [row for rows in streams for row in rows]


def cost(robot, values, options):
    """The documented distance of one joint vector from the reference (per-joint travel, weights, norm)."""
    reference, ordering = within_limits(robot, options["reference"]), options.get("ordering", Ordering())
    continuous = robot.is_revolute & np.isinf(robot.lower) & np.isinf(robot.upper)
    d = np.abs(values - reference)
    d = np.where(continuous, np.minimum(d % TWO_PI, TWO_PI - d % TWO_PI), d)
    d = d * (1.0 if ordering.weights is None else ordering.weights)
    return float(d.max() if ordering.norm == "linf" else np.sqrt(np.sum(d ** 2)))


@pytest.mark.parametrize("seed", range(6))
def test_select_matches_the_brute_force_oracle(seed):
    rng = np.random.default_rng(seed)
    for trial in range(60):
        robot, result, options = random_case(rng)
        selection = select(robot, result, Limits.of(robot), **options)
        kept, rejected, available, with_all_moves, everything = oracle(robot, result, options)
        context = (seed, trial, options)
        assert selection.available == available, context
        assert len(selection.solutions) == len(kept), context
        ordering = options.get("ordering", Ordering())
        capped = ordering.max_solutions is not None and ordering.max_solutions <= options["max_equivalents"]
        assert selection.expansion_truncated == (available > len(kept) and not capped), context
        assert selection.trimmed == with_all_moves - available + (available - len(kept) if capped else 0), context
        got = np.array([e.solution.joints for e in selection.solutions]).reshape(-1, robot.dof)
        if "reference" in options:  # the same costs in order (ties may swap rows), each row one the oracle has
            np.testing.assert_allclose([cost(robot, row, options) for row in got], [r[2] for r in kept], atol=1e-9,
                                       err_msg=str(context))
            assert all(any(np.allclose(row, r[0], atol=1e-12) for r in everything) for row in got), context
        else:
            np.testing.assert_allclose(got, np.array([r[0] for r in kept]).reshape(-1, robot.dof), atol=1e-12,
                                       err_msg=str(context))
        assert [e.within_limits for e in selection.solutions] == [bool(r[1]) for r in kept], context
        np.testing.assert_allclose(np.array([e.solution.joints for e in selection.rejected]).reshape(-1, robot.dof),
                                   np.array(rejected).reshape(-1, robot.dof), atol=1e-9, err_msg=str(context))
        for entry in selection.solutions + selection.rejected:
            outside = (entry.solution.joints < robot.lower - 1e-9) | (entry.solution.joints > robot.upper + 1e-9)
            assert [v.joint for v in entry.violations] == np.flatnonzero(outside).tolist(), context


@pytest.mark.parametrize("seed", range(6, 9))
def test_select_matches_the_oracle_when_a_target_spans_many_chunks(seed, monkeypatch):
    """Chunks of whole solutions, three combinations at most: every target with several solutions, or one with
    several equivalents, is ranked over several chunks and its kept ones ordered again as one."""
    from service.kinematics.ik import _select
    monkeypatch.setattr(_select, "_CHUNK_ROWS", 3)
    test_select_matches_the_brute_force_oracle(seed)


def test_a_batch_answers_the_same_in_small_chunks(monkeypatch):
    """The UR5 (±360°: up to 64 equivalents a solution) over 40 targets, with and without a reference: the same
    rows in the same order whether a chunk holds every target or a few of one target's solutions."""
    from service.kinematics.ik import _select
    robot = CATALOGUE.get("ur5").robot
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (40, 6))
    arrays = solve_ik_arrays(robot, forward_kinematics(robot, q))
    for options in ({"max_equivalents": 50}, {"reference": q[0], "max_equivalents": 20},
                    {"reference": q[1], "ordering": Ordering("l2", weights=np.linspace(0.5, 2, 6))}):
        whole = select_arrays(robot, arrays, Limits.of(robot), **options)
        monkeypatch.setattr(_select, "_CHUNK_ROWS", 40)
        small = select_arrays(robot, arrays, Limits.of(robot), **options)
        monkeypatch.undo()
        np.testing.assert_array_equal(small.solutions.target, whole.solutions.target)
        np.testing.assert_array_equal(small.solutions.joints, whole.solutions.joints)


def test_chunk_edges_move_to_target_starts_and_the_answer_stays(monkeypatch):
    """Chunks of 4,096 combinations over UR5 targets of up to 512 (8 solutions × 64 equivalents): each edge moves to
    its target's first row, so no target spans chunks, and the rows, their order, joints (bit for bit), flags and
    labels are those of one chunk, with and without a reference and with a cap that trims."""
    from service.kinematics.ik import _select
    robot = CATALOGUE.get("ur5").robot
    q = np.random.default_rng(4).uniform(-np.pi, np.pi, (60, 6))
    arrays = solve_ik_arrays(robot, forward_kinematics(robot, q))
    edges_made = []
    target_edges = _select._target_edges

    def recorded(target, *rest):
        edges = target_edges(target, *rest)
        edges_made.append((target, edges))
        return edges

    for options in ({}, {"max_equivalents": 100}, {"reference": q[0], "max_equivalents": 300}):
        whole = select_arrays(robot, arrays, Limits.of(robot), **options)
        monkeypatch.setattr(_select, "_CHUNK_ROWS", 4096)
        monkeypatch.setattr(_select, "_target_edges", recorded)
        small = select_arrays(robot, arrays, Limits.of(robot), **options)
        monkeypatch.undo()
        for kind in ("solutions", "rejected"):
            mine, one = getattr(small, kind), getattr(whole, kind)
            np.testing.assert_array_equal(mine.target, one.target)
            assert mine.joints.tobytes() == one.joints.tobytes()
            np.testing.assert_array_equal(mine.within_limits, one.within_limits)
            assert {k: (v, c.tolist()) for k, (v, c) in mine.labels.items()} == {
                k: (v, c.tolist()) for k, (v, c) in one.labels.items()}
    assert edges_made
    for target, edges in edges_made:
        assert len(edges) > 3  # several chunks
        inner = edges[1:-1]
        assert (target[inner] != target[inner - 1]).all()  # each one at a target's first row


def test_rows_all_alike_take_one_rows_rank_tuples_repeated():
    """Rows of equal caps and limits get one row's tuples, repeated: the same as enumerating every row."""
    from service.kinematics.ik import _equivalents
    rng = np.random.default_rng(2)
    for _ in range(30):
        rows, n = int(rng.integers(2, 80)), int(rng.integers(1, 7))
        caps = np.repeat(rng.integers(0, 4, (1, n)), rows, axis=0)
        limit = np.full(rows, int(rng.integers(0, 40)))
        owner, ranks = _equivalents._rank_tuples(caps, limit)
        expected_owner, expected_ranks = _equivalents._enumerated_rank_tuples(caps, limit)
        np.testing.assert_array_equal(owner, expected_owner)
        np.testing.assert_array_equal(ranks, expected_ranks)
        assert ranks.shape == (len(owner), n)


CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "spong_ex3_5_stanford"])
def test_one_target_select_is_the_row_of_select_arrays(robot_id):
    robot = CATALOGUE.get(robot_id).robot
    rng = np.random.default_rng(1)
    q = rng.uniform(-np.pi, np.pi, (20, robot.dof))
    q[:, ~robot.is_revolute] = 0.5
    targets = forward_kinematics(robot, q)
    reference = np.zeros(robot.dof)
    for options in ({}, {"reference": reference, "ordering": Ordering("l2")},
                    {"filter_limits": False, "reference": reference, "max_equivalents": 5}):
        arrays = solve_ik_arrays(robot, targets)
        chosen = select_arrays(robot, arrays, Limits.of(robot), **options)
        for row in range(len(targets)):
            solutions = [Solution(arrays.joints[row, s], {}, float(arrays.position[row, s]),
                                  float(arrays.orientation[row, s])) for s in range(arrays.count[row])]
            one = select(robot, IKResult("ok" if solutions else "unreachable", solutions, "analytic", "x", True),
                         Limits.of(robot), **options)
            assert (one.status, one.expansion_truncated, one.trimmed, one.available, one.notes) == (
                chosen.status[row], chosen.truncated[row], chosen.trimmed[row], chosen.available[row],
                chosen.notes.get(row, []))
            for table, entries in ((chosen.solutions, one.solutions), (chosen.rejected, one.rejected)):
                mine = np.flatnonzero(table.target == row)
                np.testing.assert_array_equal(table.joints[mine],
                                              np.array([e.solution.joints for e in entries]).reshape(-1, robot.dof))
                assert table.within_limits[mine].tolist() == [e.within_limits for e in entries]


@pytest.mark.parametrize("robot_id", ["puma560_standard", "kuka_kr6_r900_2", "ur5"])
def test_rows_kept_once_each_are_the_general_paths(robot_id, monkeypatch):
    """Limits under a whole turn (each solution has one equivalent within them, or none) and no reference: the
    selection keeps the rows in table order without ranking any (``_each_once``). A batch's answer, with
    solutions rejected, flagged, capped and targets out of reach, is the general path's (forced by an exclusion
    mask that excludes nothing) in every field, bit for bit."""
    from service.kinematics.ik import _select
    robot = CATALOGUE.get(robot_id).robot
    rng = np.random.default_rng(11)
    q = rng.uniform(-np.pi, np.pi, (30, robot.dof))
    targets = forward_kinematics(robot, q)
    targets[::7, :3, 3] += 10.0  # out of reach
    table = table_of_arrays(solve_ik_arrays(robot, targets))
    taken = []
    each_once = _select._each_once
    monkeypatch.setattr(_select, "_each_once", lambda *args: taken.append(True) or each_once(*args))
    met = {"rejected": 0, "flagged": 0, "truncated": 0, "unreachable": 0}
    for trial in range(12):
        lower = rng.uniform(-np.pi, 0.5, robot.dof)
        upper = lower + rng.uniform(0.5, TWO_PI - 0.01, robot.dof)
        open_joint = rng.random(robot.dof) < 0.2
        limits = Limits(np.where(open_joint, -INF, lower), np.where(open_joint, INF, upper))
        options = {"filter_limits": bool(trial % 2), "max_equivalents": [1, 3, 1024][trial % 3]}
        lean = select_table(robot, table, len(targets), limits, **options)
        general = select_table(robot, table, len(targets), limits, excluded=np.zeros(len(table), dtype=bool),
                               **options)
        context = (trial, options)
        for name in ("status", "truncated", "trimmed", "available"):
            np.testing.assert_array_equal(getattr(lean, name), getattr(general, name), err_msg=str(context))
        assert dict(lean.notes) == dict(general.notes), context
        for kind in ("solutions", "rejected"):
            mine, theirs = getattr(lean, kind), getattr(general, kind)
            for column in ("target", "joints", "within_limits", "position", "orientation"):
                assert getattr(mine, column).tobytes() == getattr(theirs, column).tobytes(), (context, kind, column)
            assert {k: (v, c.tolist()) for k, (v, c) in mine.labels.items()} == {
                k: (v, c.tolist()) for k, (v, c) in theirs.labels.items()}, (context, kind)
        met["rejected"] += len(lean.rejected)
        met["flagged"] += int(np.sum(~lean.solutions.within_limits))
        met["truncated"] += int(lean.truncated.sum())
        met["unreachable"] += int(np.sum(lean.status == "unreachable"))
    assert len(taken) == 12  # every lean call took the rows-once path
    assert min(met.values()) > 0, met  # and the cases meet each kind of row and target


def test_huge_limits_are_answered_bounded_with_exact_counts():
    wide = Robot([Joint(f"q{i}", "revolute", 0.5, 0.0, 0.0, 0.0, -1e6, 1e6) for i in range(3)], name="wide")
    result = IKResult("ok", [Solution(np.array([0.5, -1.0, 2.0]), {}, 0.0, 0.0),
                             Solution(np.array([-0.5, 1.0, -2.0]), {}, 0.0, 0.0)], "analytic", "test", True)
    per_joint = [int(np.floor((1e6 - v) / TWO_PI) - np.ceil((-1e6 - v) / TWO_PI) + 1) for v in (0.5, -1.0, 2.0)]
    tracemalloc.start()
    started = time.perf_counter()
    selection = select(wide, result, Limits.of(wide), reference=np.zeros(3), max_equivalents=64)
    elapsed = time.perf_counter() - started
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert elapsed < 5.0 and peak < 200e6
    assert selection.available == min(2 * int(np.prod(per_joint, dtype=object)), COUNT_CAP)
    assert len(selection.solutions) == 64 and selection.expansion_truncated
    costs = [np.max(np.abs(e.solution.joints)) for e in selection.solutions]
    assert costs == sorted(costs) and costs[0] == pytest.approx(2.0)  # the solutions themselves come first
    six = Robot([Joint(f"q{i}", "revolute", 0.5, 0.0, 0.0, 0.0, -1e6, 1e6) for i in range(6)], name="wide six")
    capped = select(six, IKResult("ok", [Solution(np.full(6, 0.5), {}, 0.0, 0.0)], "analytic", "x", True),
                    Limits.of(six), max_equivalents=8)
    assert capped.available == COUNT_CAP and len(capped.solutions) == 8 and "the count's cap" in capped.notes[0]


def test_the_core_notes_name_no_option_of_the_wire():
    """The core words its notes in its own terms; the boundary words them for the wire (tests/api)."""
    from service.kinematics.ik import NOTE_WORDING

    for text in NOTE_WORDING.values():
        for wire_name in ("max_equivalents", "filter_limits", "max_joint_move", "max_solutions", "free_joints"):
            assert wire_name not in text


def test_a_reference_outside_the_limits_is_met_at_its_equivalent_within_them():
    """Issue 22, item 7: with a reference outside a joint's ±π limits, the solution equal to it up to a whole
    turn is at no distance and comes first; another solution half a turn away comes after it, though it is
    nearer the reference's raw value."""
    arm = Robot([Joint("q1", "revolute", 0.5, 0.0, 0.0, 0.0, -np.pi, np.pi),
                 Joint("q2", "revolute", 0.5, 0.0, 0.0, 0.0, -np.pi, np.pi)])
    reference = np.array([np.pi + 0.2, 0.1])
    same_up_to_a_turn = Solution(np.array([0.2 - np.pi, 0.1]), {}, 0.0, 0.0)
    half_a_turn_away = Solution(np.array([0.2, 0.1]), {}, 0.0, 0.0)
    for order in ([half_a_turn_away, same_up_to_a_turn], [same_up_to_a_turn, half_a_turn_away]):
        selection = select(arm, IKResult("ok", order, "analytic", "test", True), Limits.of(arm), reference=reference)
        listed = [entry.solution.joints for entry in selection.solutions]
        np.testing.assert_allclose(listed[0], same_up_to_a_turn.joints, atol=1e-15)
        np.testing.assert_allclose(listed[1], half_a_turn_away.joints, atol=1e-15)
    # a reference with no equivalent within the limits keeps its value
    narrow = Robot([Joint("q1", "revolute", 0.5, 0.0, 0.0, 0.0, -1.0, 1.0)])
    solutions = [Solution(np.array([0.9]), {}, 0.0, 0.0), Solution(np.array([-0.9]), {}, 0.0, 0.0)]
    selection = select(narrow, IKResult("ok", solutions, "analytic", "test", True), Limits.of(narrow),
                       reference=np.array([2.5]))
    assert [entry.solution.joints[0] for entry in selection.solutions] == [0.9, -0.9]


def _effective_reference_on_arrays(robot, limits, reference):
    """The arrays' rule :func:`effective_reference` applied before it went to floats (the same arithmetic, every
    joint at once): the independent form the float one must equal bit for bit."""
    bounds = limits.widened(robot)
    lower, upper, multi_valued = bounds.lower, bounds.upper, bounds.multi_valued
    outside = multi_valued & ((reference < lower) | (reference > upper))
    tolerance = limits.tolerance(robot)
    with np.errstate(invalid="ignore"):
        turns = np.where(reference > limits.upper, -np.ceil((reference - limits.upper - tolerance) / (2 * np.pi)),
                         np.ceil((lower - reference) / (2 * np.pi)))
        moved = reference + 2 * np.pi * np.where(outside, turns, 0.0)
    fits = (moved >= lower) & (moved <= upper)
    return np.where(outside & fits, moved, reference)


def test_the_effective_reference_is_the_arrays_rule_on_random_references():
    """``effective_reference`` on floats against the arrays' rule: references inside and outside limits of every
    kind (within a turn, several turns, one-sided, open, a slide, narrower than the tolerance), values exactly at a
    bound, a whole turn past it, far away, and not finite (kept as they are)."""
    from service.kinematics.ik._select import effective_reference

    rng = np.random.default_rng(20261208)
    moved = 0
    for case in range(300):
        n = int(rng.integers(1, 8))
        kinds = rng.choice(["revolute", "prismatic"], n, p=[0.85, 0.15])
        robot = Robot([Joint(f"q{j + 1}", str(kind), 0.3, 0.1, 0.2, 0.0) for j, kind in enumerate(kinds)])
        centre, width = rng.uniform(-4, 4, n), rng.choice([1e-10, 0.3, 2.0, np.pi, 2 * np.pi, 9.0], n)
        lower, upper = centre - width, centre + width
        lower = np.where(rng.random(n) < 0.15, -np.inf, lower)
        upper = np.where(rng.random(n) < 0.15, np.inf, upper)
        limits = Limits(lower, upper)
        reference = rng.uniform(-20, 20, n)
        at = rng.random(n)
        reference = np.where(at < 0.1, lower, np.where(at < 0.2, upper + 2 * np.pi, reference))
        reference = np.where(rng.random(n) < 0.03, rng.choice([np.inf, -np.inf, np.nan, 1e300]), reference)
        got = effective_reference(robot, limits, reference)
        expected = _effective_reference_on_arrays(robot, limits, reference)
        assert got.dtype == expected.dtype and got.shape == expected.shape
        assert got.tobytes() == expected.tobytes(), case  # bit for bit, NaN and the zeros' signs included
        moved += int(np.sum(got != reference))
    assert moved > 100, moved
