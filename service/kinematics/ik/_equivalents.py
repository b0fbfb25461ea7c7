"""2π-equivalents: how many each solution has within the limits, how they rank, and what keeping the first few
costs. The selection (:mod:`._select`) enumerates them; the cost model (:mod:`._cost`) counts them before any work.

A revolute joint with both bounds finite takes every value θ + 2kπ within them, each a solution of its own. A
joint's usable values are the whole turns k of an interval, ranked by cost outwards from the cheapest
(:func:`combination_turns`). A combination among the first L of a solution (L = the most that can be returned of
it) has ranks (r_1 … r_n) with ∏(r_j + 1) ≤ L, since every combination with smaller or equal ranks costs no more
and comes first: only those rank tuples are enumerated (:func:`down_set_size` counts them). Counts are products of
interval lengths, capped at :data:`.._budget.COUNT_CAP`.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._budget import COUNT_CAP
from .._limits import Limits
from .._robot import Robot

_TWO_PI = 2.0 * np.pi

#: Most rank tuples one solution may enumerate (:func:`~._select.select`). Past it the number kept per target is
#: lowered to :func:`enumerable_limit` (said in the target's notes), so the work per solution stays bounded
#: whatever the limits, ``max_equivalents`` and the joint count; the boundary refuses such requests before solving
#: when the client asked for that many. A target's solutions are ranked in one chunk: 16 solutions of 2^15 tuples
#: are about 200 MB of working arrays and a few tenths of a second (2^20 were 1.5 GB and 9 s for 8 UR5 solutions).
MAX_COMBINATIONS_PER_SOLUTION = 1 << 15

#: Rows (one target's solutions) and rank entries per row (∏ caps × n, bounding the cache's memory) up to which
#: :func:`_rank_tuples` looks rows up one by one rather than enumerating them all at once; up to these rows and
#: entries in all, :func:`combination_turns` ranks every row, the single ones too, rather than the rows with
#: several turns alone.
_FEW_ROWS, _FEW_RANKS = 32, 1 << 13


def equivalents_per_solution(robot: Robot, limits: Limits) -> int:
    """Most 2π-equivalents one generic solution can have within the limits: Π_j ceil(span_j / 2π) over revolute
    joints with both bounds finite (1 for every other joint), capped at 2**53 − 1.

    A joint whose span is not a whole number of turns holds at most ceil(span / 2π) values of a 2π-lattice; one
    more only when a value lands exactly on both bounds. Examples: a ±160° joint 1, a ±360° joint 2 (a UR5 has at
    most 2⁶ = 64 per solution).
    """
    return limits.widened(robot).equivalents_per_solution  # worked out once per limits, with them


@functools.lru_cache(maxsize=1024)  # a few arms' counts and limits: the same three integers per request
def worst_answer_per_target(solutions: int, equivalents: int, kept: int) -> tuple[int, int]:
    """The most rows (kept plus rejected) one target's answer can hold, and how many of them are then rejected.

    A solution either fits, and gives up to ``equivalents`` rows of which at most ``kept`` in all are kept, or
    does not, and gives one rejected row (or one flagged row when filter_limits is false). With r rejected the
    answer holds min(kept, (solutions − r) × equivalents) + r rows: growing in r while the fitting ones still
    fill ``kept``, shrinking after, so the most is at the r where they just fill it (or at r = 0).

    >>> worst_answer_per_target(8, 2, 1024)   # a PUMA with its limits: every solution fits, twice
    (16, 0)
    >>> worst_answer_per_target(8, 10**30, 1000)   # one fitting solution fills the cap; the other 7 are rejected
    (1007, 7)
    """
    def rows(rejected: int) -> int:
        return min(kept, (solutions - rejected) * equivalents) + rejected

    filling = solutions - -(-kept // equivalents)  # the most rejected while the others still fill `kept`
    candidates = {0, solutions, max(0, filling), min(solutions, max(0, filling + 1))}
    rejected = max(sorted(candidates), key=rows)
    return rows(rejected), rejected


def combinations_to_rank(n: int, limit: int, equivalents: int) -> int:
    """The most rank tuples one solution of an n-joint arm with ``equivalents`` 2π-equivalents enumerates to keep
    ``limit`` (see :func:`_nearest`): min(equivalents, |{r : ∏(r_j + 1) ≤ min(limit, equivalents)}|)."""
    return min(equivalents, down_set_size(n, min(limit, equivalents)))


@functools.lru_cache(maxsize=256)
def enumerable_limit(n: int) -> int:
    """The largest number kept per target whose rank tuples for n joints fit MAX_COMBINATIONS_PER_SOLUTION."""
    low, high = 1, MAX_COMBINATIONS_PER_SOLUTION  # down_set_size(n, 1) = 1 fits; the high end never does for n ≥ 2
    while low < high:
        middle = (low + high + 1) // 2
        if down_set_size(n, middle) <= MAX_COMBINATIONS_PER_SOLUTION:
            low = middle
        else:
            high = middle - 1
    return low


def combination_turns(q: np.ndarray, first: np.ndarray, last: np.ndarray, ranks_cap: np.ndarray,
                       row_limit: np.ndarray, reference: np.ndarray | None,
                       weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The turns of the combinations of rows (S,) worth costing: those whose rank tuples r (r_j < ``ranks_cap``)
    have ∏(r_j + 1) ≤ ``row_limit`` (:func:`_rank_tuples`). Returns (row (C,) ascending, turns (C, n)), each
    row's combinations in lexicographic order of their rank tuples.

    ``q``, ``first``, ``last`` (S, n) are the rows' values and usable turns, ``ranks_cap`` (S, n) the most
    ranks of each joint worth enumerating. A row with one usable turn per joint (limits under a whole turn,
    the usual case) has one combination, its ``first`` turns (when every row is such, none is ranked).
    """
    single = (first == last).all(axis=1) & (row_limit > 0)
    if single.all():
        return np.arange(len(q)), first
    if len(q) <= _FEW_ROWS:  # few rows: all ranked, the single ones keeping their ``first`` turns
        owner, ranks = _rank_tuples(ranks_cap, row_limit)
        if ranks.size <= _FEW_RANKS:  # and few combinations: tabled at once, the single rows' entries too
            turns = _tabled_turns(ranks_cap, owner, ranks, *_ranked_turns(q, first, last, reference, weights))
            return owner, np.where(single[owner, None], first[owner], turns)
    multi = (~single).nonzero()[0]
    caps = ranks_cap[multi]
    cheapest, direction, ahead, behind = _ranked_turns(q[multi], first[multi], last[multi], reference, weights)
    owner, ranks = _rank_tuples(caps, row_limit[multi])
    multi_turns = _tabled_turns(caps, owner, ranks, cheapest, direction, ahead, behind)
    if len(multi) == len(q):
        return owner, multi_turns
    per_row = np.ones(len(q), dtype=np.int64)  # each row's combinations, placed in row order
    per_row[multi] = np.bincount(owner, minlength=len(multi))
    offset = np.cumsum(per_row) - per_row
    turns = np.empty((int(per_row.sum()), q.shape[1]))
    singles = single.nonzero()[0]
    turns[offset[singles]] = first[singles]
    turns[offset[multi][owner] + position_in_group(owner)] = multi_turns
    return np.repeat(np.arange(len(q)), per_row), turns


def _tabled_turns(caps: np.ndarray, owner: np.ndarray, ranks: np.ndarray, cheapest: np.ndarray,
                  direction: np.ndarray, ahead: np.ndarray, behind: np.ndarray) -> np.ndarray:
    """The turns (C, n) of the combinations ``ranks`` (C, n) of rows ``owner`` (C,), from the rows' ranked turns
    (S, n each, :func:`_ranked_turns`) and ``caps`` (S, n): as ``cheapest[owner] + _rank_offsets(ranks, …)``, but
    each (row, joint, rank) turn is worked out once (no more of them than combinations), then looked up."""
    table_start = (np.cumsum(caps.ravel()) - caps.ravel()).reshape(caps.shape)
    entry = np.repeat(np.arange(caps.size), caps.ravel())
    rank = np.arange(len(entry)) - table_start.ravel()[entry]
    table = [a.ravel()[entry] for a in (cheapest, direction, ahead, behind)]
    table = table[0] + _rank_offsets(rank, *table[1:])
    at = table_start.take(owner, axis=0)  # take: a plain gather, faster than indexing with arrays
    at += ranks
    return table.take(at)


def _ranked_turns(q: np.ndarray, first: np.ndarray, last: np.ndarray, reference: np.ndarray | None,
                  weights: np.ndarray) -> tuple[np.ndarray, ...]:
    """How each joint's usable turns rank by cost |q + 2kπ − r|·w for the reference r (shape (n,)); without
    one, by |k| itself (exact, so equal turning ties exactly). Ties: the lower value first.

    Returns, shape (S, n) each: the cheapest turn, the direction (±1) of the second cheapest, and how many
    turns lie beyond the cheapest in that direction and in the other. The cost grows outwards from the
    cheapest, so the ranks alternate between the two sides until one runs out (:func:`_rank_offsets`).
    """
    if reference is None:  # the cost |k|·w: 0 is cheapest, then −1 before +1 (equal costs: the lower value)
        cheapest, direction = np.zeros(first.shape), np.full(first.shape, -1.0)
    else:
        def cost(k):
            return np.abs(q + _TWO_PI * k - reference) * weights

        below = np.floor((reference - q) / _TWO_PI)
        above = below + 1.0
        at_above = cost(above)
        lower_costs_more = at_above < cost(below)
        cheapest = np.where(lower_costs_more, above, below)
        direction = np.where(lower_costs_more | (cost(below - 1.0) <= at_above), -1.0, 1.0)
    indifferent = weights == 0  # every value costs 0: ascending values
    if indifferent.any():
        cheapest, direction = np.where(indifferent, first, cheapest), np.where(indifferent, 1.0, direction)
    direction = np.where(cheapest < first, 1.0, np.where(cheapest > last, -1.0, direction))
    cheapest = np.minimum(np.maximum(cheapest, first), last)
    ahead = np.where(direction > 0, last - cheapest, cheapest - first)
    return cheapest, direction, ahead, (last - first) - ahead


def _rank_offsets(ranks: np.ndarray, direction: np.ndarray, ahead: np.ndarray, behind: np.ndarray) -> np.ndarray:
    """The turn, relative to the cheapest, of a joint's value of rank r (arrays of one shape, see :func:`_ranked_turns`).

    Ranks 1, 2, 3, 4, … go +1, −1, +2, −2, … in ``direction`` while both sides have turns left, then on along the
    side that has.
    """
    r = ranks.astype(float)
    alternating = np.where(np.mod(r, 2.0) == 1.0, direction * (r + 1.0) / 2.0, -direction * r / 2.0)
    one_side = np.where(ahead <= behind, -direction * (r - ahead), direction * (r - behind))
    return np.where(r <= 2.0 * np.minimum(ahead, behind), alternating, one_side)


def _rank_tuples(ranks_cap: np.ndarray, row_limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every rank tuple r of each row with r_j < ranks_cap[row, j] and ∏(r_j + 1) ≤ row_limit[row].

    Returns (row (C,), ranks (C, n)), rows ascending and each row's tuples in lexicographic order. Rows all
    alike, or a few rows (one target's), of few tuples each are looked up (:func:`_row_rank_tuples`): once for
    all, or row by row.
    """
    if len(ranks_cap) > 1 and (ranks_cap == ranks_cap[0]).all() and (row_limit == row_limit[0]).all():
        caps = ranks_cap[0].tolist()  # every row alike (a batch of one arm's solutions): one row's tuples, repeated
        if math.prod(caps) * len(caps) <= _FEW_RANKS:
            ranks = _row_rank_tuples(tuple(caps), int(row_limit[0]))
            return np.repeat(np.arange(len(ranks_cap)), len(ranks)), np.tile(ranks, (len(ranks_cap), 1))
    if len(ranks_cap) <= _FEW_ROWS:
        caps, limits = ranks_cap.tolist(), row_limit.tolist()
        if all(math.prod(row) * len(row) <= _FEW_RANKS for row in caps):
            per_row = [_row_rank_tuples(tuple(row), limit) for row, limit in zip(caps, limits)]
            owner = np.repeat(np.arange(len(per_row)), [len(ranks) for ranks in per_row])
            return owner, np.concatenate(per_row) if per_row else np.zeros(ranks_cap.shape, dtype=np.int64)
    return _enumerated_rank_tuples(ranks_cap, row_limit)


@functools.lru_cache(maxsize=256)
def _row_rank_tuples(ranks_cap: tuple[int, ...], row_limit: int) -> np.ndarray:
    """:func:`_rank_tuples` of one row, (C, n), read-only: the same caps and limit recur from target to target."""
    ranks = _enumerated_rank_tuples(np.array([ranks_cap], dtype=np.int64), np.array([row_limit]))[1]
    ranks.flags.writeable = False
    return ranks


def _enumerated_rank_tuples(ranks_cap: np.ndarray, row_limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_rank_tuples` for any number of rows at once."""
    rows, n = ranks_cap.shape
    owner = np.flatnonzero(np.all(ranks_cap > 0, axis=1) & (row_limit > 0))
    product = np.ones(len(owner), dtype=np.int64)
    levels = []  # per joint: each partial tuple's parent and its rank there
    for j in range(n):
        children = np.minimum(ranks_cap[owner, j], row_limit[owner] // product)
        parent = np.repeat(np.arange(len(owner)), children)
        rank = np.arange(len(parent)) - (np.cumsum(children) - children)[parent]
        owner, product = owner[parent], product[parent] * (rank + 1)
        levels.append((parent, rank))
    ranks = np.zeros((len(owner), n), dtype=np.int64)
    index = np.arange(len(owner))
    for j in range(n - 1, -1, -1):  # back along the parents
        parent, rank = levels[j]
        ranks[:, j] = rank[index]
        index = parent[index]
    return owner, ranks


@functools.lru_cache(maxsize=4096)
def down_set_size(n: int, limit: int) -> int:
    """How many rank tuples of n joints have ∏(r_j + 1) ≤ limit.

    >>> down_set_size(2, 4)   # (0,0) (0,1) (0,2) (0,3) (1,0) (1,1) (2,0) (3,0)
    8
    """
    if limit < 1:
        return 0
    if n == 0:
        return 1
    total, factor = 0, 1
    while factor <= limit:
        quotient = limit // factor
        same = limit // quotient  # every factor up to this one leaves the same quotient
        total += (same - factor + 1) * down_set_size(n - 1, quotient)
        factor = same + 1
    return total


def position_in_group(keys: np.ndarray) -> np.ndarray:
    """0, 1, 2, … within each run of equal values of sorted ``keys``."""
    if len(keys) == 0 or keys[0] == keys[-1]:  # one run
        return np.arange(len(keys))
    index = np.arange(len(keys))
    run_start = np.where(np.concatenate(([True], keys[1:] != keys[:-1])), index, 0)
    return index - np.maximum.accumulate(run_start)


def capped_products(counts: np.ndarray) -> np.ndarray:
    """∏_j counts[:, j] per row (counts ≥ 0, shape (S, n)), capped at :data:`COUNT_CAP` without overflow, (S,).

    The float product is exact below 2**53: without a zero factor every partial product is a whole number no
    larger than the whole; at or above 2**53 (or past the float range) the cap applies, and a zero factor gives 0.
    """
    factors = np.minimum(counts, COUNT_CAP).astype(float)
    if factors.max(initial=1.0) ** factors.shape[1] < 2.0 ** 53:  # the usual few turns: exact, no cap reached
        return np.prod(factors, axis=1).astype(np.int64)
    with np.errstate(over="ignore", invalid="ignore"):
        product = np.prod(factors, axis=1)
    capped = np.where(product >= 2.0 ** 53, float(COUNT_CAP), product)
    return np.where((factors == 0).any(axis=1), 0.0, capped).astype(np.int64)


def capped_sums(target: np.ndarray, values: np.ndarray, n_targets: int) -> np.ndarray:
    """Σ values per target (values ≤ COUNT_CAP), capped at :data:`COUNT_CAP`, shape (N,).

    The float sum is exact while it stays below 2**53 (non-negative integers); at or above it the cap applies.
    """
    total = np.bincount(target, weights=values.astype(float), minlength=n_targets)
    return np.where(total >= 2.0 ** 53, COUNT_CAP, total).astype(np.int64)


def rounds_needed(target: np.ndarray, lengths: np.ndarray, n_targets: int, limit: int) -> np.ndarray:
    """Per target, the rounds of a round robin over its rows' streams (``lengths`` (S,)) that yield ``limit``
    items (all, if fewer), ≥ 1, shape (N,).

    Rounds R yield Y(R) = Σ min(length, R) items. With the streams sorted by length s_0 ≤ s_1 ≤ …, for R in
    (s_{k−1}, s_k] Y(R) = Σ_{i<k} s_i + R·(P − k) (P streams): the smallest R reaching ``limit`` is the smallest
    over those segments of the first R of each that does. R ≤ ``limit``, so longer streams count as ``limit``.
    """
    position = position_in_group(target)
    streams = np.zeros((n_targets, int(position.max()) + 1 if len(position) else 1), dtype=np.int64)
    streams[target, position] = lengths

    rounds = np.maximum(1, streams.max(axis=1))  # a target whose streams yield fewer than ``limit``: all of them
    capped = np.minimum(streams, limit)
    enough = capped.sum(axis=1) >= limit
    if not enough.any():
        return rounds
    s = np.sort(capped[enough], axis=1)
    shorter = np.cumsum(s, axis=1) - s  # Σ of the streams before each
    segment_start = np.concatenate((np.zeros((len(s), 1), dtype=np.int64), s[:, :-1]), axis=1) + 1
    first_reaching = np.maximum(segment_start, -((shorter - limit) // (s.shape[1] - np.arange(s.shape[1]))))
    rounds[enough] = np.where(first_reaching <= s, first_reaching, limit).min(axis=1)
    return rounds
