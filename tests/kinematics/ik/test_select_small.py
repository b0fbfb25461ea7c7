"""One target's answer (the few-rows forms of the selection) is the general array path's, field by field.

For one target the selection looks rank tuples up row by row, tables each joint's ranked turns once and skips
the bookkeeping of many targets (:mod:`service.kinematics.ik._equivalents`), on Python floats where its
combinations are few (``_select._one_target``: in turn without a reference, nearest first with one); where
each solution has at most one equivalent within the limits and nothing orders the rows, it keeps them in table
order without ranking any (``_select._each_once``). The general path is forced by answering the same target
inside a batch of other targets, with those forms switched off and an exclusion mask that excludes nothing:
the two answers must agree bit for bit, over random catalogue arms, limits (±2π and wider, narrow, one-sided,
exactly at a solution's joints), references (some exactly between two equivalents) and options.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.config import Settings
from service.kinematics import UNLIMITED, Limits, forward_kinematics
from service.kinematics.ik import AnswerOptions, IKTargets, Ordering, SolutionTable, answer_ik, select, solve_ik_arrays
from service.kinematics.ik import _equivalents, _select
from tests.selection import table_of_arrays
from service.robots.catalogue import load_catalogue

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
ROBOTS = ["puma560_standard", "ur5", "kuka_kr6_r900_2", "kuka_kr210_r2700", "abb_irb120", "ur10e"]
TWO_PI = 2 * np.pi


def _random_case(rng):
    """(robot, target (4, 4), options) with limits and a reference drawn around the target's own solutions."""
    robot = CATALOGUE.get(ROBOTS[rng.integers(len(ROBOTS))]).robot
    n = robot.dof
    target = forward_kinematics(robot, rng.uniform(-np.pi, np.pi, n))
    arrays = solve_ik_arrays(robot, target[None])
    solutions = arrays.joints[0][arrays.valid[0]]
    solution = solutions[rng.integers(len(solutions))]
    lower, upper = robot.lower.copy(), robot.upper.copy()
    kind = rng.integers(5)
    if kind == 1:  # ±π … ±5 turns
        width = rng.choice([np.pi, TWO_PI, 2.5 * np.pi, 3 * np.pi, 10 * np.pi], n)
        lower, upper = -width, width
    elif kind == 2:  # narrow
        centre, width = rng.uniform(-1, 1, n), rng.uniform(0.2, 2.0, n)
        lower, upper = centre - width, centre + width
    elif kind == 3:  # exactly at a solution's joints (or a whole turn away)
        turns = rng.integers(-1, 2, n)
        lower = np.where(rng.random(n) < 0.6, solution + TWO_PI * turns, lower)
        upper = np.where(rng.random(n) < 0.6, solution + TWO_PI * turns + rng.choice([0.0, TWO_PI, 3.0], n), upper)
        lower, upper = np.minimum(lower, upper), np.maximum(lower, upper)
    elif kind == 4:  # some one-sided or open
        width = rng.choice([TWO_PI, 4 * np.pi, np.inf], n)
        lower, upper = np.where(rng.random(n) < 0.2, -np.inf, -width), width
    reference, ordering = None, Ordering()
    draw = rng.random()
    if draw > 0.3:
        if draw < 0.55:  # between two equivalents of a solution's joint: a tie in exact arithmetic
            reference = solution + np.where(rng.random(n) < 0.6, np.pi * rng.choice([-1, 1], n),
                                            rng.uniform(-0.5, 0.5, n))
        else:
            reference = rng.uniform(-4, 4, n)
        ordering = Ordering(str(rng.choice(["linf", "l2"])),
                            rng.choice([0.0, 0.5, 1.0, 2.0], n) if rng.random() < 0.4 else None,
                            int(rng.integers(0, 12)) if rng.random() < 0.4 else None,
                            np.where(rng.random(n) < 0.5, rng.uniform(0, 6, n), np.inf) if rng.random() < 0.4
                            else None)
    options = AnswerOptions(reference=reference, limits=Limits(lower, upper), filter_limits=bool(rng.random() < 0.6),
                            ordering=ordering, max_equivalents=int(rng.choice([1, 2, 3, 5, 17, 1024])))
    return robot, target, options


def _rows(table, index):
    mine = np.flatnonzero(table.target == index)
    labels = [{name: values[codes[k]] for name, (values, codes) in table.labels.items() if codes[k] >= 0}
              for k in mine.tolist()]
    return (table.joints[mine].tobytes(), table.within_limits[mine].tolist(), table.position[mine].tobytes(),
            table.orientation[mine].tobytes(), labels)  # bit for bit


def _assert_identical(mine, index, general, general_index) -> None:
    """Target ``index`` of selection ``mine`` and ``general_index`` of ``general`` agree in every field."""
    for name in ("status", "truncated", "trimmed", "available"):
        assert getattr(mine, name)[index] == getattr(general, name)[general_index], name
        assert getattr(mine, name).dtype == getattr(general, name).dtype, name  # the encoders list them as they are
    assert mine.notes.get(index, []) == general.notes.get(general_index, [])
    assert (index in mine.notes) == (general_index in general.notes)  # noted, even where a note has no words
    assert mine.notes.rows.dtype == general.notes.rows.dtype
    for kind in ("solutions", "rejected"):
        assert _rows(getattr(mine, kind), index) == _rows(getattr(general, kind), general_index), kind


def _select_both(robot, target, options, rng, monkeypatch):
    """The target's selection alone, and within a batch of six other targets through the general forms."""
    reference = options.reference
    alone = table_of_arrays(solve_ik_arrays(robot, target[None], reference=reference))
    others = table_of_arrays(solve_ik_arrays(robot, forward_kinematics(robot, rng.uniform(-np.pi, np.pi,
                                                                                           (6, robot.dof))),
                                             reference=reference))
    first, last = others.take(others.target < 3), others.take(others.target >= 3)
    batch = SolutionTable.concat([first, alone.with_targets(alone.target + 3), last.with_targets(last.target + 1)],
                                 robot.dof)
    arguments = dict(filter_limits=options.filter_limits, reference=reference, ordering=options.ordering,
                     max_equivalents=options.max_equivalents)
    mine = select(robot, alone, 1, options.limits, **arguments)
    with monkeypatch.context() as forced:  # the general forms only: every row enumerated and tabled at once
        forced.setattr(_equivalents, "_FEW_ROWS", -1)
        forced.setattr(_equivalents, "_FEW_RANKS", -1)
        general = select(robot, batch, 7, options.limits, excluded=np.zeros(len(batch), dtype=bool), **arguments)
    return mine, general


@pytest.fixture
def calls(monkeypatch):
    """Counts of the selection's few-rows and general forms, as the cases call them."""
    counted = {"few rows": 0, "general": 0, "few in turn": 0, "one target": 0, "one target, nearest first": 0,
               "one target, within a joint move": 0, "nearest on floats": 0}

    def counting(function, key):
        def wrapper(*args, **kwargs):
            counted[key] += 1
            return function(*args, **kwargs)
        return wrapper

    monkeypatch.setattr(_equivalents, "_row_rank_tuples", counting(_equivalents._row_rank_tuples, "few rows"))
    monkeypatch.setattr(_equivalents, "_tabled_turns", counting(_equivalents._tabled_turns, "general"))
    monkeypatch.setattr(_select, "_in_turn", counting(_select._in_turn, "few in turn"))
    monkeypatch.setattr(_select, "_nearest_on_floats", counting(_select._nearest_on_floats, "nearest on floats"))

    selects_one_target = _select._one_target

    def one_target(*args, **kwargs):  # counted where it selects (it declines many combinations)
        chosen = selects_one_target(*args, **kwargs)
        counted["one target"] += chosen is not None
        counted["one target, nearest first"] += chosen is not None and args[5] is not None
        counted["one target, within a joint move"] += chosen is not None and args[6].max_joint_move is not None
        return chosen
    monkeypatch.setattr(_select, "_one_target", one_target)
    return counted


def test_one_target_selects_as_the_general_path(monkeypatch, calls):
    rng = np.random.default_rng(20240611)
    ranked = kept_many = rejected_in_order = 0
    for case in range(250):
        robot, target, options = _random_case(rng)
        before = calls["few rows"]
        mine, general = _select_both(robot, target, options, rng, monkeypatch)
        ranked += calls["few rows"] > before
        _assert_identical(mine, 0, general, 3)
        kept_many += int(np.sum(mine.solutions.target == 0)) > 1
        rejected_in_order += options.reference is not None and len(mine.rejected) > 1  # (nearest first)
        # and the answer built on it (one part, one target) keeps it as it is
        answer = answer_ik(robot, IKTargets.poses(target[None]), options)
        assert _rows(answer.solutions, 0) == _rows(mine.solutions, 0), case
        assert _rows(answer.rejected, 0) == _rows(mine.rejected, 0), case
        assert (answer.status[0], answer.available[0], answer.trimmed[0]) == (
            mine.status[0], mine.available[0], mine.trimmed[0])
    # the cases exercise the few-rows forms, one target selected on floats (its few combinations put in turn on
    # integers) and the general form, and rank many equivalents
    assert ranked > 50 and calls["general"] > 50 and calls["one target"] > 30 and calls["few in turn"] > 20 \
        and calls["one target, nearest first"] > 30 and calls["one target, within a joint move"] > 20 \
        and calls["nearest on floats"] > 30 \
        and kept_many > 100 and rejected_in_order > 20, (ranked, calls, kept_many, rejected_in_order)


def test_a_target_without_rows_is_selected_as_the_general_path_selects_it(monkeypatch):
    """A target the solver found no row for (unreachable) goes through the one-target path too: its status, its
    counts and its notes (none) as the general path gives them inside a batch, whatever the limits' filter."""
    rng = np.random.default_rng(20261206)
    for case in range(20):
        robot, target, options = _random_case(rng)
        empty = SolutionTable.empty(robot.dof)
        others = table_of_arrays(solve_ik_arrays(robot, forward_kinematics(robot, rng.uniform(-np.pi, np.pi,
                                                                                               (2, robot.dof)))))
        later = others.take(others.target >= 1)  # the empty target between the two others: number 1
        batch = SolutionTable.concat([others.take(others.target < 1), later.with_targets(later.target + 1)],
                                     robot.dof)
        arguments = dict(filter_limits=options.filter_limits, max_equivalents=options.max_equivalents)
        mine = select(robot, empty, 1, options.limits, **arguments)
        with monkeypatch.context() as forced:
            forced.setattr(_equivalents, "_FEW_ROWS", -1)
            forced.setattr(_equivalents, "_FEW_RANKS", -1)
            general = select(robot, batch, 3, options.limits, excluded=np.zeros(len(batch), dtype=bool),
                             **arguments)
        assert mine.status[0] == general.status[1] == "unreachable", case
        _assert_identical(mine, 0, general, 1)


def test_one_outcome_is_the_outcome_of_one_target():
    """``_select._one_outcome`` (one target's counts on Python integers) against ``_select._outcome`` (the
    arrays' rules) on random counts, zeros and caps included: the same status, columns, dtypes and notes."""
    rng = np.random.default_rng(20261207)
    for case in range(400):
        n_rows, n_kept, n_rejected = (int(rng.choice([0, 1, 2, 5])) for _ in range(3))
        kept = SolutionTable(np.zeros(n_kept, dtype=np.int64), np.zeros((n_kept, 6)), rng.random(n_kept) < 0.7,
                             np.zeros(n_kept), np.zeros(n_kept), {})
        rejected = SolutionTable(np.zeros(n_rejected, dtype=np.int64), np.zeros((n_rejected, 6)),
                                 np.zeros(n_rejected, dtype=bool), np.zeros(n_rejected), np.zeros(n_rejected), {})
        candidates = int(rng.choice([0, 1, n_kept, n_kept + 2]))
        available = n_kept + int(rng.choice([0, 0, 1, 7, 2 ** 60]))
        with_all_moves = available + int(rng.choice([0, 0, 3]))
        capped, has_reference, cap = bool(rng.random() < 0.3), bool(rng.random() < 0.5), int(rng.choice([1, 3, 64]))
        mine = _select._one_outcome(n_rows, kept, rejected, candidates, available, with_all_moves, capped, cap,
                                    has_reference, 6)
        general = _select._outcome(*(np.array([count], dtype=np.int64) for count in (n_rows,)), kept,
                                   np.array([n_kept], dtype=np.int64), rejected,
                                   *(np.array([count], dtype=np.int64) for count in (candidates, available,
                                                                                      with_all_moves, 0)),
                                   capped, cap, has_reference, None, 6)
        _assert_identical(mine, 0, general, 0)


def test_few_combinations_without_a_reference_come_in_the_general_paths_order(monkeypatch, calls):
    """Without a reference, one target's few combinations (``_select._FEW_COMBINATIONS``) are put in order on
    Python integers: the same rows, values and counts as the general path, over the random cases without their
    reference and orderings."""
    rng = np.random.default_rng(20261205)
    for case in range(200):
        robot, target, options = _random_case(rng)
        options = AnswerOptions(limits=options.limits, filter_limits=options.filter_limits,
                                max_equivalents=options.max_equivalents)
        mine, general = _select_both(robot, target, options, rng, monkeypatch)
        _assert_identical(mine, 0, general, 3)
    assert calls["few in turn"] > 40, calls


def test_in_turn_is_the_general_ranking_of_random_turn_ranges():
    """``_select._in_turn`` against ``_select._nearest`` on random rows: usable turns anywhere from −3 to +6
    (0 inside, or every turn on one side), up to 1,024 combinations and 256 a row, as the one-target selection
    takes them (a ±2π arm's 8 × 64 among them), any limit: the same rows and values, bit for bit."""
    rng = np.random.default_rng(7)
    robot = CATALOGUE.get("puma560_standard").robot
    limits = Limits.of(robot)
    ways = {"lists": 0, "stacked": 0, "lexsort": 0}  # how _in_turn takes the rounds, by the rows' sizes
    for case in range(300):
        rows = int(rng.integers(1, 9))
        first = rng.integers(-3, 3, (rows, 6)).astype(float)
        if case % 3 == 0:  # a ±2π arm's: two turns a joint, 0 and one side
            first = -rng.integers(0, 2, (rows, 6)).astype(float)
            last = first + 1
        else:
            last = first + rng.choice([0, 0, 0, 1, 1, 2, 3], (rows, 6))
        counts = last - first + 1.0
        sizes = np.prod(counts, axis=1)
        if sizes.sum() > _select._ONE_TARGET_COMBINATIONS or sizes.max() > _select._ROW_COMBINATIONS:
            continue
        ways["lists" if sizes.sum() <= _select._FEW_IN_TURN else "stacked" if sizes.min() == sizes.max()
             else "lexsort"] += not (first == last).all()
        q = rng.uniform(-np.pi, np.pi, (rows, 6))
        limit = int(rng.choice([rng.integers(1, 80), rng.integers(80, 2000)]))
        target = np.zeros(rows, dtype=np.int64)
        row_limit = _equivalents.rounds_needed(target, sizes.astype(np.int64), 1, limit)[target]
        expected = _select._nearest(robot, limits, target, q, first, last, counts, row_limit, limit, None, Ordering(),
                                    UNLIMITED)
        rows_kept, turns = _select._in_turn(first.tolist(), last.tolist(), limit, 6)
        assert rows_kept.tolist() == expected[0].tolist(), case
        values = turns * TWO_PI + q[rows_kept]  # as _select._one_target lists them
        assert values.tobytes() == expected[1].tobytes(), case
    assert min(ways.values()) > 30, ways


def test_joint_exactly_at_its_limits_and_reference_between_equivalents(monkeypatch):
    """A ±360° arm whose limits pass through a solution's joints, the reference half a turn from each: the
    single target's selection is the general path's, ties and limit values included."""
    robot = CATALOGUE.get("ur5").robot
    target = forward_kinematics(robot, np.array([0.3, -1.1, 1.4, -0.6, 1.2, 2.0]))
    solution = solve_ik_arrays(robot, target[None]).joints[0, 0]
    limits = Limits(solution - TWO_PI, solution + TWO_PI)  # each joint's values: exactly both limits, and itself
    rng = np.random.default_rng(1)
    for reference in (solution + np.pi, solution - np.pi, None):
        for filter_limits in (True, False):
            options = AnswerOptions(reference=reference, limits=limits, filter_limits=filter_limits,
                                    max_equivalents=7)
            mine, general = _select_both(robot, target, options, rng, monkeypatch)
            _assert_identical(mine, 0, general, 3)
            assert mine.available[0] >= 7 and mine.truncated[0]


def test_nearest_of_one_is_the_general_ranking_of_random_rows():
    """``_select._nearest_of_one`` (its float ranking of a few combinations, and its arrays past them) against
    ``_select._nearest`` on random rows of arms of 2 to 9 joints, prismatic and continuous joints among them:
    usable turns from −3 to +4, references anywhere (some exactly half a turn from a row's value, where two
    equivalents tie), weights with zeros, both norms, with and without a joint-move bound, any limit: the same
    rows and values, bit for bit."""
    from tests.arms import random_dh_robot

    rng = np.random.default_rng(20261206)
    ways = {"on floats": 0, "on arrays": 0}
    for case in range(400):
        n = int(rng.choice([2, 3, 6, 7, 8, 9]))
        kinds = "".join(rng.choice(["R", "R", "R", "P"], n))
        robot = random_dh_robot(rng, "standard", kinds)
        revolute = robot.is_revolute
        lower = np.where(rng.random(n) < 0.2, -np.inf, -rng.choice([np.pi, 3 * np.pi, 5 * np.pi], n))
        upper = np.where(np.isinf(lower), np.inf, -lower)
        limits = Limits(np.where(revolute, lower, -1.0), np.where(revolute, upper, 1.0))
        multi = limits.multi_valued(robot)
        rows = int(rng.integers(1, 9))
        q = rng.uniform(-np.pi, np.pi, (rows, n))
        first = np.where(multi, rng.integers(-3, 2, (rows, n)), 0).astype(float)
        last = np.where(multi, first + rng.choice([0, 0, 1, 2], (rows, n)), first)
        reference = rng.uniform(-6, 6, n)
        if case % 3 == 0:  # half a turn from the first row's value: its two nearest equivalents tie
            reference = np.where(revolute, q[0] + np.pi * rng.choice([-1, 1], n), reference)
        ordering = Ordering(str(rng.choice(["linf", "l2"])),
                            rng.choice([0.0, 0.5, 1.0, 2.0], n) if rng.random() < 0.4 else None, None,
                            np.where(rng.random(n) < 0.5, rng.uniform(0, 4, n), np.inf) if rng.random() < 0.3
                            else None)
        limit = int(rng.choice([1, 2, 3, 7, 1024]))
        counts = last - first + 1.0
        c_first, c_last = first, last
        if ordering.max_joint_move is not None:
            c_first, c_last = _select._within_move(robot, limits, q, first, last, reference, ordering.max_joint_move)
            counts = np.maximum(c_last - c_first + 1.0, 0.0)
        combinations = counts.prod(axis=1)
        target = np.zeros(rows, dtype=np.int64)
        expected = _select._nearest(robot, limits, target, q, c_first, c_last, counts,
                                    np.full(rows, limit, dtype=np.int64), limit, reference, ordering, UNLIMITED)
        floats = 1 < combinations.sum() <= _select._FEW_NEAREST and (combinations[combinations > 0] > 1).any()
        ways["on floats" if floats and (ordering.norm == "linf" or n < 8) else "on arrays"] += 1
        rows_kept, turns, available = _select._nearest_of_one(robot, limits, q, first.tolist(), last.tolist(), limit,
                                                              reference, ordering)
        assert rows_kept.tolist() == expected[0].tolist(), case
        assert (turns * TWO_PI + q[rows_kept]).tobytes() == expected[1].tobytes(), case
        assert available == int(combinations.sum()), case
    assert min(ways.values()) > 60, ways


def test_the_l2_travel_of_fewer_than_8_joints_is_summed_in_joint_order():
    """The float ranking (``_select._nearest_on_floats``) sums an l2 travel's squares in joint order, which is what
    numpy's reduction does for fewer than 8 terms (8 or more it sums pairwise, and those arms stay on arrays):
    travel() on arrays equals the sequential sum bit for bit, for 1 to 7 joints, values over many magnitudes."""
    rng = np.random.default_rng(8)
    robot = CATALOGUE.get("puma560_standard").robot
    for n in range(1, 8):
        distance = rng.uniform(0, 7, (500, n)) * rng.choice([1.0, 1e-8, 1e8], (500, n))
        in_order = np.sqrt([_squares_in_order(row) for row in distance])
        assert in_order.tobytes() == np.sqrt(np.sum(distance ** 2, axis=-1)).tobytes(), n
    q = rng.uniform(-np.pi, np.pi, (50, 6))  # and travel() itself, whose costs the float ranking mirrors
    reference = rng.uniform(-6, 6, 6)
    in_order = np.sqrt([_squares_in_order(np.abs(row - reference)) for row in q])
    assert in_order.tobytes() == _select.travel(robot, Limits.of(robot), q, reference, Ordering("l2")).tobytes()


def _squares_in_order(values: np.ndarray) -> float:
    """Σ v_j² of a row (n,), summed in joint order on Python floats."""
    total = 0.0
    for value in values.tolist():
        total = total + value * value
    return total
