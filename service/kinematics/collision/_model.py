"""The collision model of a robot: which shape pairs to check, compiled once, and their signed distances for a
batch of configurations.

A model is built from the robot's link shapes (:class:`~._shapes.LinkShape`, each in its link's frame), the
obstacles (:class:`~._shapes.Obstacle`, world frame) and the rules of the request (self-collision, ignored link
pairs). It is a value: it holds no per-call state, so one model may serve concurrent requests.

Evaluation takes link frames as :func:`~service.kinematics.link_frames` returns them, ``world_T_frame`` of
shape (S, n + 1, 4, 4) (0 the base, i the frame that moves with joint i, n the flange), and gives the signed
distance of every pair in every configuration, shape (S, P), with the sign convention of :mod:`._distances`
(positive apart, negative in overlap). The frames are taken as rigid transforms, as link_frames gives them.

How the work is laid out: every shape is reduced to a few reference rows (a capsule's two end points, a sphere's
centre, a box's centre and its three axes), each a homogeneous point or direction fixed to a link or to the
world. One matrix product per link maps that link's rows to the world for a block of configurations; the pairs
then fall into groups by the kernel that measures them: box–box, round–point, box–point, round–round and
box–round (a point is a sphere or a capsule of length 0, a round shape any other capsule), each with the pairs of
a base shape and an obstacle first (they do not move while the base frame stays put). Each group gathers its rows and runs one vectorised kernel
over the block. Configurations go through in blocks of a few thousand pair evaluations, so that the temporaries
stay in cache.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Callable, Iterator, NamedTuple, Sequence

import numpy as np

from .._errors import InvalidInputError
from ._bounds import FAMILY_BOUNDS, block_bounds, bound_constants
from ._distances import Separation, _box_box, _box_point, _box_segment, _quiet, _segment_point, _segment_segment, _swept
from ._shapes import Box, Capsule, LinkShape, Obstacle, Shape, Sphere

#: Pair evaluations per block (configurations × pairs of the widest group): large enough that numpy's cost per
#: call is small against the arithmetic, small enough that a block's temporaries stay in cache. Measuring every
#: pair: 4096 to 16384 alike, 1024 and 65536 slower. With the single-precision bounds, which leave an eighth to a
#: third of the pairs to measure in smaller arrays, up to sixteen times as many, in at most 4096 configurations
#: (80,000 PUMA configurations and 34 pairs: 98304 to 196608 elements alike, 32768 a tenth slower, 16384 a quarter;
#: with 12 pairs, blocks of 3,500 to 8,192 configurations alike, 18,724 half as slow again).
_BLOCK_ELEMENTS = 8192
_BOUNDED_BLOCK_ELEMENTS = 131072
_BOUNDED_BLOCK_CONFIGURATIONS = 4096

#: Fewer pair evaluations than this are all measured: the bounds' numpy calls would cost more than they save.
_BOUNDED_FROM = 4096

#: The order in which pairs name the kinds of their shapes, and in which the kernels take them.
_KIND_ORDER = (Box, Capsule, Sphere)
_KIND_NAMES = {Box: "box", Capsule: "capsule", Sphere: "sphere"}


@dataclass(frozen=True)
class ShapePair:
    """One pair of shapes the model checks.

    ``a`` and ``b`` name the bodies for answers: a link as ``"link 3"`` (or its name, when the model was given
    link names), an obstacle by its name. ``a`` is always a link; ``b`` is a link of higher index, or an
    obstacle (``link_b`` is then None). ``shape_a`` indexes the model's link shapes; ``shape_b`` the link
    shapes too, or the obstacles when ``link_b`` is None. ``kind`` names the two shapes' kinds in the order box,
    capsule, sphere (``"box-capsule"``), whichever of them is ``a``.
    """

    a: str
    b: str
    link_a: int
    link_b: int | None
    shape_a: int
    shape_b: int
    kind: str


class _Group(NamedTuple):
    """The pairs one kernel measures: columns [start, stop) of the distances. Per pair, the reference rows the
    kernel reads (those of its first shape, then its second: a box before a round shape, of two round shapes
    the longer), the sizes, and whether the kernel's first shape is the pair's ``b``."""

    start: int
    stop: int
    kernel: Callable
    rows: np.ndarray  # (P_k, m) row indices
    half_size_a: np.ndarray | None  # (3, P_k, 1): a box's half sizes (None for a round shape)
    half_size_b: np.ndarray | None
    radius_a: np.ndarray | None  # (P_k, 1): a round shape's radius (None for a box)
    radius_b: np.ndarray | None
    swapped: np.ndarray  # (P_k,) bool
    bounds: Callable | None  # the kernel's cheap bounds (None: none, every pair is measured)
    bound_constants: tuple  # the bounds' sizes, single precision (see the bound functions), (..., P_k, 1) each
    fixed: int  # the first pairs, a base shape's with the obstacles: the same wherever the base frame is the same

    def sizes(self) -> tuple:
        """The kernel's four sizes."""
        return self.half_size_a, self.half_size_b, self.radius_a, self.radius_b

    def part(self, begin: int, end: int) -> "_Group":
        """The group's pairs [begin, end) as a group of their own (columns start + begin … start + end)."""
        def pairs_of(size):
            return None if size is None else size[..., begin:end, :]

        return self._replace(start=self.start + begin, stop=self.start + end, rows=self.rows[begin:end],
                             half_size_a=pairs_of(self.half_size_a), half_size_b=pairs_of(self.half_size_b),
                             radius_a=pairs_of(self.radius_a), radius_b=pairs_of(self.radius_b),
                             swapped=self.swapped[begin:end],
                             bound_constants=tuple(pairs_of(constant) for constant in self.bound_constants),
                             fixed=min(self.fixed, end) - min(self.fixed, begin))

    def bounds_of(self, placed32: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The lower and upper bounds (P_k, B) of the group's distances from the block's reference rows (3, K, B)
        in single precision (a group with ``bounds``)."""
        return self.bounds(np.take(placed32, self.rows.T, axis=1), *self.bound_constants)


class CollisionCheck(NamedTuple):
    """The outcome of :meth:`CollisionModel.check` for S configurations, in columns.

    ``clearance`` (S,): the smallest signed distance over the model's pairs (+inf when it has none).
    ``pair_distances`` (S, P): in the order of :attr:`CollisionModel.pairs`, each pair's signed distance where
    it can be the clearance or closer than the margin; elsewhere a lower bound of it, at least both.
    The close body pairs, those closer than the margin, are listed for configuration i at positions
    ``offsets[i]:offsets[i + 1]`` of ``body_pairs`` (indices into :attr:`CollisionModel.body_pairs`) and
    ``distances`` (their signed distance: the smallest over their shape pairs), nearest first.
    """

    clearance: np.ndarray
    pair_distances: np.ndarray
    offsets: np.ndarray
    body_pairs: np.ndarray
    distances: np.ndarray

    @property
    def colliding(self) -> np.ndarray:
        """(S,) bool: the configuration has a close pair."""
        return self.offsets[1:] > self.offsets[:-1]

    def close_pairs(self, model: "CollisionModel", configuration: int) -> list[tuple[str, str, float]]:
        """Configuration ``configuration``'s close body pairs as (a, b, distance), nearest first (a batch's, as
        columns: :class:`~._clearance.Contacts`)."""
        listed = slice(self.offsets[configuration], self.offsets[configuration + 1])
        return [(*model.body_pairs[pair], distance)
                for pair, distance in zip(self.body_pairs[listed].tolist(), self.distances[listed].tolist())]


class _LinkRows(NamedTuple):
    """The reference rows fixed to one link: rows [first, end) of the world block, and their homogeneous
    coordinates in the link's frame, (4, k): x, y, z and w (1 for a point, 0 for a direction)."""

    link: int
    first: int
    end: int
    local: np.ndarray


@dataclass(frozen=True, eq=False)
class CollisionModel:
    """The shape pairs of a robot and its obstacles, compiled for evaluation; build it with
    :func:`collision_model`.

    Attributes
    ----------
    link_count : int
        n + 1, the number of link frames the model expects.
    pairs : tuple of ShapePair
        The checked pairs, in the order of the columns of :meth:`distances`.
    body_pairs : tuple of (str, str)
        The distinct (a, b) names of the pairs: the bodies answers report. Several shape pairs share one when
        a link carries several shapes, or several obstacles share a name (one obstacle made of several shapes).
    body_pair_of : ndarray of int, shape (P,)
        For each pair, its index in ``body_pairs``.
    """

    link_count: int
    link_shapes: tuple[LinkShape, ...]
    obstacles: tuple[Obstacle, ...]
    pairs: tuple[ShapePair, ...]
    body_pairs: tuple[tuple[str, str], ...]
    body_pair_of: np.ndarray
    _link_rows: tuple[_LinkRows, ...]
    _world_rows_fixed: np.ndarray  # (3, K_obstacles): the obstacles' rows, already in the world
    _groups: tuple[_Group, ...]
    _body_merge: _BodyMerge

    # --- evaluation -------------------------------------------------------------------------------------------

    def distances(self, world_T_frames: np.ndarray) -> np.ndarray:
        """Signed distance of every pair in every configuration.

        Parameters
        ----------
        world_T_frames : array_like, shape (S, n + 1, 4, 4) or (n + 1, 4, 4)
            Link frames as :func:`~service.kinematics.link_frames` returns them.

        Returns
        -------
        ndarray, shape (S, P) or (P,)
            In the order of :attr:`pairs`; in the frames' length unit.

        Raises
        ------
        InvalidInputError
            Frames of the wrong shape (location ``("frames",)``), or not finite where a shape sits (location
            ``("frames", configuration, link)``, without the configuration for a single one).
        """
        columns, single = self._checked_frames(world_T_frames)
        result = self._distances(columns)
        self._check_finite(columns, result, single)
        return result[0] if single else result

    def check(self, world_T_frames: np.ndarray, margin: float = 0.0) -> CollisionCheck:
        """Clearance of every configuration and the body pairs closer than ``margin``.

        ``world_T_frames`` as in :meth:`distances` (a single configuration counts as S = 1). ``margin`` is a
        finite length (location ``("margin",)``); a pair is close when its signed distance is < margin, so with
        margin 0 touching shapes are not reported and overlapping ones are.
        """
        columns, single = self._checked_frames(world_T_frames)
        return self.check_frame_columns(columns, margin, single=single)

    def check_frame_columns(self, frame_columns: np.ndarray, margin: float = 0.0, *,
                            single: bool = False) -> CollisionCheck:
        """:meth:`check` of link frames laid out as :func:`~service.kinematics.link_frame_columns` gives them,
        shape (n + 1, 12, S) or (n + 1, 4, 3, S), without their copy into 4 × 4 matrices (``single``: locate
        errors as for one configuration)."""
        margin_value = _finite_number(margin, ("margin",))
        columns = frame_columns.reshape(self.link_count, 4, 3, -1)
        count = columns.shape[3]
        pair_distances = _pair_major(count, len(self.pairs))
        clearance = np.full(count, np.inf)
        close: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        if count and self.pairs:
            for begin, end in self._evaluated_blocks(columns, pair_distances, margin_value):
                # each block's clearance and close pairs while its distances are in cache
                by_pair = pair_distances[begin:end].T
                by_pair.min(axis=0, out=clearance[begin:end])
                rows, bodies, values = _close_pairs(by_pair, clearance[begin:end], self._body_merge, margin_value)
                close.append((rows + begin, bodies, values))
        self._check_finite(columns, pair_distances, single)
        rows, bodies, values = (np.concatenate(parts) for parts in zip(*close)) if close else \
            (np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp), np.zeros(0))
        offsets = np.zeros(count + 1, dtype=np.intp)
        np.cumsum(np.bincount(rows, minlength=count), out=offsets[1:])
        return CollisionCheck(clearance, pair_distances, offsets, bodies, values)

    def witnesses(self, world_T_frames: np.ndarray, configurations: Sequence[int] | np.ndarray,
                  pairs: Sequence[int] | np.ndarray) -> Separation:
        """Signed distance and witness points (world frame) of chosen entries: pair ``pairs[k]`` in configuration
        ``configurations[k]``, for example the close pairs to draw. ``point_a`` is on the pair's ``a`` and
        ``normal`` runs from a to b.

        Returns a :class:`~._distances.Separation` of batch shape (len(pairs),).
        """
        columns, _ = self._checked_frames(world_T_frames)
        configuration = np.asarray(configurations).reshape(-1)
        column = np.asarray(pairs).reshape(-1)
        for values, name, size in ((configuration, "configurations", columns.shape[3]),
                                   (column, "pairs", len(self.pairs))):
            if values.size and not (np.issubdtype(values.dtype, np.integer) and 0 <= values.min()
                                    and values.max() < size):
                raise InvalidInputError(f"{name} must be indices in [0, {size})", location=(name,))
        if configuration.shape != column.shape:
            raise InvalidInputError("configurations and pairs must have the same length", location=("pairs",))
        count = column.size
        result = Separation(np.empty(count), np.empty((count, 3)), np.empty((count, 3)), np.empty((count, 3)))
        for group in self._groups:
            chosen = np.flatnonzero((column >= group.start) & (column < group.stop))
            if chosen.size == 0:
                continue
            local = column[chosen] - group.start
            world = self._world_rows(columns[..., configuration[chosen]])
            # entry k is pair local[k] in configuration k of this block: gather one (3, m) per entry
            rows = world[:, group.rows[local].T, np.arange(chosen.size)][:, :, None]
            with _quiet():
                core = group.kernel(rows, *(None if size is None else size[..., local, 0][..., None, :]
                                            for size in group.sizes()),
                                    witness=True)
            swapped = group.swapped[local][:, None]
            first, second, normal = (vector[:, 0].T for vector in core[1:])
            result.distance[chosen] = core.distance[0]
            result.point_a[chosen] = np.where(swapped, second, first)
            result.point_b[chosen] = np.where(swapped, first, second)
            result.normal[chosen] = np.where(swapped, -normal, normal)
        return result

    # --- internals --------------------------------------------------------------------------------------------

    def _checked_frames(self, world_T_frames) -> tuple[np.ndarray, bool]:
        """Frames (S, n + 1, 4, 4) or (n + 1, 4, 4) checked, seen as frame columns (n + 1, 4, 3, S) (a view: the
        rotation's columns and the origin, each (3, S)), and whether one configuration was given."""
        try:
            frames = np.asarray(world_T_frames, dtype=float)
        except (TypeError, ValueError) as error:
            raise InvalidInputError(f"frames must be an array of numbers: {error}", location=("frames",)) from None
        single = frames.ndim == 3
        if single:
            frames = frames[None]
        if frames.ndim != 4 or frames.shape[1:] != (self.link_count, 4, 4):
            raise InvalidInputError(
                f"frames must have shape (S, {self.link_count}, 4, 4) or ({self.link_count}, 4, 4), "
                f"got {np.shape(world_T_frames)}", location=("frames",))
        return frames[:, :, :3, :].transpose(1, 3, 2, 0), single

    def _check_finite(self, columns: np.ndarray, result: np.ndarray, single: bool) -> None:
        if np.isfinite(result).all():
            return
        configuration = int(np.flatnonzero(~np.isfinite(result).all(axis=1))[0])
        where = () if single else (configuration,)
        for rows in self._link_rows:
            if not np.isfinite(columns[rows.link, ..., configuration]).all():
                raise InvalidInputError(f"link frame {rows.link} is not finite",
                                        location=("frames", *where, rows.link))
        raise InvalidInputError("link frames too large: the distances overflow", location=("frames", *where))

    def _distances(self, columns: np.ndarray) -> np.ndarray:
        """Every pair's distance (S, P) for frame columns (L, 4, 3, S), each measured."""
        result = _pair_major(columns.shape[3], len(self.pairs))
        if columns.shape[3] and self.pairs:
            for _ in self._evaluated_blocks(columns, result, None):
                pass
        return result

    def _evaluated_blocks(self, columns: np.ndarray, result: np.ndarray,
                          margin: float | None) -> Iterator[tuple[int, int]]:
        """Distances of the pairs into ``result`` (S, P), for the frame columns (L, 4, 3, S), a block of
        configurations [begin, end) at a time (yielded when it is filled).

        The groups without bounds are measured first, in full: two boxes, and the pairs of a base shape and an
        obstacle (once per block when the base frame is the same throughout, as it is for one robot). With a
        ``margin``, the other pairs are then measured only where they can matter: their distances and each bounded
        pair's cheap bounds (a shape's round core inside the ball about its middle, and around it) give every
        configuration an upper bound U of its clearance, and a pair whose lower bound is at least max(U, margin)
        can be neither the clearance nor a close pair (a pair that attains U is measured, unless its bounds meet).
        Such a pair keeps its lower bound in ``result``.
        """
        count = columns.shape[3]
        if count * len(self.pairs) < _BOUNDED_FROM:
            margin = None  # every pair measured: as exact, and fewer calls
        widest = max(group.stop - group.start for group in self._groups)
        block = max(1, min(count, _BLOCK_ELEMENTS // widest if margin is None else
                           min(_BOUNDED_BLOCK_ELEMENTS // widest, _BOUNDED_BLOCK_CONFIGURATIONS)))
        world = self._world_buffer(block)
        if margin is None:  # every pair measured in full: one kernel call per group
            measured, bounded = list(self._groups), []
        else:  # first a base shape's pairs with the obstacles, then the groups without bounds, then the others
            measured = [group.part(0, group.fixed) for group in self._groups if group.fixed] + \
                [group.part(group.fixed, len(group.rows)) for group in self._groups
                 if group.bounds is None and group.fixed < len(group.rows)]
            bounded = [group.part(group.fixed, len(group.rows)) for group in self._groups
                       if group.bounds is not None and group.fixed < len(group.rows)]
        # some group is only a base shape's pairs with obstacles: measured once per block while the base stays put
        whole_fixed_groups = any(group.fixed == len(group.rows) for group in measured)
        for begin in range(0, count, block):
            with _quiet():  # per block: the caller's code between blocks keeps its own floating-point state
                end = min(begin + block, count)
                frames = columns[..., begin:end]
                if frames.strides[-1] != frames.itemsize:  # 4 × 4 frames seen as columns: the block's, in a
                    frames = np.ascontiguousarray(frames)  # row each, so that einsum runs on unit strides
                placed = self._world_rows(frames, world[:, :, : end - begin])
                block_result = result[begin:end]
                base_still = whole_fixed_groups and bool((frames[0] == frames[0][..., :1]).all())
                for group in measured:
                    _measure(block_result[:, group.start:group.stop], group, world, None, None, 0.0,
                             once=base_still and group.fixed == len(group.rows))
                if bounded:
                    clearance = np.full(end - begin, np.inf)  # so far: of the pairs measured
                    for group in measured:
                        np.fmin(clearance, block_result[:, group.start:group.stop].min(axis=1), out=clearance)
                    bounds, cutoff, slack = block_bounds(bounded, placed, margin, clearance)
                    for group, bound in zip(bounded, bounds):
                        _measure(block_result[:, group.start:group.stop], group, world, bound, cutoff, slack)
            yield begin, end

    def _world_buffer(self, block: int) -> np.ndarray:
        """(3, K, block): room for every reference row of a block of configurations, the obstacles' filled in."""
        links = self._link_rows[-1].end
        world = np.empty((3, links + self._world_rows_fixed.shape[1], block))
        world[:, links:, :] = self._world_rows_fixed[:, :, None]
        return world

    def _world_rows(self, columns: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """World coordinates (3, K, B) of every reference row for the frame columns (L, 4, 3, B) of B
        configurations: x_world = world_T_link · x_link, homogeneous (w = 1 for points, 0 for directions)."""
        count = columns.shape[3]
        if out is None:
            out = self._world_buffer(count)
        for link, first, end, local in self._link_rows:
            # x_world = x X + y Y + z Z + w P with the frame's columns X, Y, Z, P
            out[:, first:end, :] = np.einsum("jcb,jk->ckb", columns[link], local)
        return out


def _pair_major(count: int, pair_count: int) -> np.ndarray:
    """Room for the distances (S, P) of S configurations, laid out pair by pair: the kernels fill a pair's
    configurations, which are then contiguous."""
    return np.empty((pair_count, count)).T


# --- kernels: gathered rows (3, m, ...) and sizes -> distances, or cores with witnesses ------------------------


def _round_round(rows, half_size_a, half_size_b, radius_a, radius_b, *, witness):
    """Two capsules: rows p0, p1 (the longer), q0, q1."""
    core = _segment_segment(rows, witness)
    return _swept(core, radius_a, radius_b) if witness else core - (radius_a + radius_b)


def _round_point(rows, half_size_a, half_size_b, radius_a, radius_b, *, witness):
    """A capsule or a sphere, and a sphere (or a capsule of length 0): rows p0, p1 (p0 twice for a sphere), q."""
    core = _segment_point(rows, witness)
    return _swept(core, radius_a, radius_b) if witness else core - (radius_a + radius_b)


def _box_round(rows, half_size_a, half_size_b, radius_a, radius_b, *, witness):
    """A box and a capsule: rows centre, three axes, start, end."""
    core = _box_segment(rows[:, :4], half_size_a, rows[:, 4:6], witness)
    return _swept(core, 0.0, radius_b) if witness else core - radius_b


def _box_point_kernel(rows, half_size_a, half_size_b, radius_a, radius_b, *, witness):
    """A box and a sphere (or a capsule of length 0): rows centre, three axes, the sphere's centre."""
    core = _box_point(rows[:, :4], half_size_a, rows[:, 4], witness)
    return _swept(core, 0.0, radius_b) if witness else core - radius_b


def _box_box_kernel(rows, half_size_a, half_size_b, radius_a, radius_b, *, witness):
    """Two boxes: rows centre and three axes of each."""
    return _box_box(rows[:, :4], half_size_a, rows[:, 4:8], half_size_b, witness)


#: The kernel of each pair of families, in the order of the columns: box–box first (it has no bounds in
#: :data:`._bounds.FAMILY_BOUNDS`, so it is always measured in full).
_KERNELS = {("box", "box"): _box_box_kernel, ("round", "point"): _round_point, ("box", "point"): _box_point_kernel,
            ("round", "round"): _round_round, ("box", "round"): _box_round}


def _measure(out: np.ndarray, group: _Group, world: np.ndarray, bound, cutoff: np.ndarray | None,
             slack: float, *, once: bool = False) -> None:
    """Into ``out`` (B, P_k): the group's distances where the pair's single-precision lower bound is below the
    configuration's ``cutoff`` (B,), that bound less the ``slack`` elsewhere; every one without a ``bound``, and
    ``once`` (the same rows in every configuration) those of the first. ``world`` (3, K, block) holds the block's
    reference rows in its first B columns."""
    count, kernel, rows, sizes = out.shape[0], group.kernel, group.rows.T, group.sizes()
    if bound is not None:
        lower = bound[0]
        pairs, configurations = np.nonzero(lower < cutoff)
    if bound is None or pairs.size > _MEASURE_ALL * lower.size:  # the compaction would cost more than it saves
        # (3, m, P_k, B): each row a contiguous block; once, the first configuration twice (as below)
        placed = np.repeat(world[:, :, :1], 2, axis=2) if once else world[:, :, :count]
        distances = kernel(np.take(placed, rows, axis=1), *sizes, witness=False)
        out[...] = distances[:, :1].T if once else distances.T
        return
    np.subtract(lower.T, slack, out=out)
    if pairs.size == 1:  # einsum sums a lone element in another order: measure it twice, for a batch's bits
        pairs, configurations = np.repeat(pairs, 2), np.repeat(configurations, 2)
    # (3, m, n), gathered with np.take: the kernels then see the layout of a whole block (components first,
    # contiguous), so that each distance has the same bits either way; indexing would lay the entries out first
    entries = np.take(world.reshape(3, -1), rows[:, pairs] * world.shape[2] + configurations, axis=1)
    out[configurations, pairs] = kernel(entries, *(None if size is None else np.take(size[..., 0], pairs, axis=-1)
                                                   for size in sizes),
                                        witness=False)


#: Above this share of pairs in doubt, a block measures them all.
_MEASURE_ALL = 0.6

# --- the close pairs ------------------------------------------------------------------------------------------


class _BodyMerge(NamedTuple):
    """How the shape pairs' distances become the body pairs': each body pair's first shape pair (B,), and the
    later shape pairs of a body pair as (shape pair, body pair); None for ``first`` when every body pair has one
    shape pair, in order."""

    first: np.ndarray | None
    later: tuple[tuple[int, int], ...]

    @classmethod
    def of(cls, body_pair_of: np.ndarray) -> "_BodyMerge":
        first = np.unique(body_pair_of, return_index=True)[1]
        if len(first) == len(body_pair_of):  # body pairs are numbered by their first shape pair: the identity
            return cls(None, ())
        later = np.flatnonzero(first[body_pair_of] != np.arange(len(body_pair_of)))
        return cls(first, tuple(zip(later.tolist(), body_pair_of[later].tolist())))

    def distances(self, by_pair: np.ndarray) -> np.ndarray:
        """(B, S): each body pair's signed distance, the smallest over its shape pairs' rows of ``by_pair``
        (P, S)."""
        if self.first is None:
            return by_pair
        body_distances = np.take(by_pair, self.first, axis=0)
        for row, body in self.later:
            np.minimum(body_distances[body], by_pair[row], out=body_distances[body])
        return body_distances


def _close_pairs(by_pair: np.ndarray, clearance: np.ndarray, merge: _BodyMerge,
                 margin: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The body pairs closer than ``margin`` of S configurations (their pair distances laid out pair by pair
    (P, S), and their clearance (S,)): configuration, body pair and distance of each, by configuration, nearest
    first."""
    close = np.flatnonzero(clearance < margin)  # the configurations that have a close pair
    body_distances = merge.distances(np.take(by_pair, close, axis=1))
    rows, bodies = np.nonzero(body_distances.T < margin)  # by configuration, then by body pair
    values = body_distances[bodies, rows]
    rows = close[rows]
    if rows.size and (rows[1:] == rows[:-1]).any():  # some configuration has several: nearest first
        order = np.lexsort((values, rows))  # stable: equal distances keep the body pairs' order
        rows, bodies, values = rows[order], bodies[order], values[order]
    return rows, bodies, values


# --- compilation ----------------------------------------------------------------------------------------------


def collision_model(link_shapes: Sequence[LinkShape], link_count: int, obstacles: Sequence[Obstacle] = (), *,
                    self_collision: bool = True, ignore: Sequence[Sequence[int]] = (),
                    link_names: Sequence[str] | None = None) -> CollisionModel:
    """Compile the pairs to check for a robot's link shapes and the obstacles.

    Pairs: every link shape with every obstacle (the base's shapes too); and with ``self_collision``, every two
    link shapes except those on the same link, on links joined by a joint (i and i + 1), and on the link pairs
    of ``ignore``.

    Parameters
    ----------
    link_shapes : sequence of LinkShape
        At least one. Each ``link`` is a frame index 0 … n (0 the base, n the flange).
    link_count : int
        n + 1, the number of frames of :func:`~service.kinematics.link_frames` (the robot's dof + 1).
    obstacles : sequence of Obstacle
        In the world frame. Obstacles that share a name are one body (their pairs report under one name); a name
        must not be empty nor the name of a link.
    self_collision : bool
    ignore : sequence of (int, int)
        More link pairs not to check against each other (two different links, either order).
    link_names : sequence of str, optional
        n + 1 distinct names of the links, for answers; otherwise a link is called ``"link i"``.

    Raises
    ------
    InvalidInputError
        Located by argument: ``("link_shapes",)`` when empty, ``("link_shapes", k)`` or
        ``("link_shapes", k, "link")``, ``("obstacles", k)`` or ``("obstacles", k, "name")``, ``("ignore", k)``
        or ``("ignore", k, 0 | 1)``, ``("link_names",)`` or ``("link_names", k)``, ``("link_count",)``.

    Examples
    --------
    Three capsules on links 1, 2 and 3 of a 3-joint arm, and a table: links 1–2 and 2–3 are joined, so only
    1–3 is checked for self-collision, and each link against the table.

    >>> arm = [LinkShape(i, Capsule([0, 0, 0], [0.3, 0, 0], 0.05)) for i in (1, 2, 3)]
    >>> table = Obstacle("table", Box([0, 0, -0.1], [2, 2, 0.2]))
    >>> [(pair.a, pair.b) for pair in collision_model(arm, 4, [table]).pairs]
    [('link 1', 'link 3'), ('link 1', 'table'), ('link 2', 'table'), ('link 3', 'table')]
    """
    count = _checked_link_count(link_count)
    names = _checked_link_names(link_names, count)
    shapes = _checked_link_shapes(link_shapes, count)
    obstacle_list = _checked_obstacles(obstacles, set(names))
    skipped = _checked_ignore(ignore, count)
    skipped.update((link, link + 1) for link in range(count - 1))

    # Reference rows: the link shapes' rows, grouped by link, then the obstacles'. Indices are plain lists here.
    by_link: dict[int, list[list[float]]] = {}
    local_positions = []  # per link shape: its rows' positions among its link's rows
    for item in shapes:
        rows = by_link.setdefault(item.link, [])
        own = _local_rows(item.shape)
        local_positions.append(range(len(rows), len(rows) + len(own)))
        rows.extend(own)
    link_rows, first_row, position = [], {}, 0
    for link in sorted(by_link):
        rows = np.array(by_link[link])  # (k, 4)
        first_row[link] = position
        link_rows.append(_LinkRows(link, position, position + len(rows), rows.T.copy()))
        position += len(rows)
    shape_rows = [[first_row[item.link] + k for k in positions] for item, positions in zip(shapes, local_positions)]
    obstacle_rows, fixed = [], []
    for obstacle in obstacle_list:
        rows = _local_rows(obstacle.shape)
        obstacle_rows.append(list(range(position + len(fixed), position + len(fixed) + len(rows))))
        fixed.extend(row[:3] for row in rows)

    # The pairs: each link shape with each obstacle, then the link shapes with each other; in the kernels' groups.
    candidates = [(index, shapes[index].shape, shape_rows[index], obstacle.name, None, number, obstacle.shape,
                   obstacle_rows[number])
                  for index in range(len(shapes)) for number, obstacle in enumerate(obstacle_list)]
    if self_collision:
        ordered = sorted(range(len(shapes)), key=lambda index: shapes[index].link)
        for position_a, index in enumerate(ordered):
            for other in ordered[position_a + 1:]:
                link_a, link_b = shapes[index].link, shapes[other].link
                if link_a != link_b and (link_a, link_b) not in skipped:
                    candidates.append((index, shapes[index].shape, shape_rows[index], names[link_b], link_b, other,
                                       shapes[other].shape, shape_rows[other]))
    half = {id(shape): _half_length(shape) for shape in (*(item.shape for item in shapes),
                                                         *(obstacle.shape for obstacle in obstacle_list))}
    members: dict[tuple[str, str], list] = {family: [] for family in _KERNELS}
    for index, shape_a, rows_a, b, link_b, index_b, shape_b, rows_b in candidates:
        named = sorted((shape_a, shape_b), key=lambda shape: _KIND_ORDER.index(type(shape)))
        pair = ShapePair(names[shapes[index].link], b, shapes[index].link, link_b, index, index_b,
                         f"{_KIND_NAMES[type(named[0])]}-{_KIND_NAMES[type(named[1])]}")
        swapped = _kernel_order(shape_a, half[id(shape_a)]) > _kernel_order(shape_b, half[id(shape_b)])
        first, second = (shape_b, shape_a) if swapped else (shape_a, shape_b)
        first_rows, second_rows = (rows_b, rows_a) if swapped else (rows_a, rows_b)
        family = ("box" if isinstance(first, Box) else "round",
                  "box" if isinstance(second, Box) else "point" if half[id(second)] == 0.0 else "round")
        rows = _kernel_rows(first, first_rows, False) + _kernel_rows(second, second_rows, family[1] == "point")
        members[family].append((pair, rows, first, second, swapped, half[id(first)], half[id(second)]))

    pairs: list[ShapePair] = []
    groups: list[_Group] = []
    for family, kernel in _KERNELS.items():
        if not members[family]:
            continue
        still = [member[0].link_a == 0 and member[0].link_b is None for member in members[family]]
        group = [member for member, _ in sorted(zip(members[family], still), key=lambda item: not item[1])]
        start = len(pairs)
        pairs.extend(member[0] for member in group)
        firsts, seconds = [member[2] for member in group], [member[3] for member in group]
        sizes = _half_sizes(firsts), _half_sizes(seconds), _radii(firsts), _radii(seconds)
        groups.append(_Group(start, len(pairs), kernel, np.array([member[1] for member in group]), *sizes,
                             np.array([member[4] for member in group], dtype=bool), FAMILY_BOUNDS.get(family),
                             bound_constants(family, sizes[0], sizes[2], sizes[3], [member[5] for member in group],
                                             [member[6] for member in group]), sum(still)))
    body_pairs: dict[tuple[str, str], int] = {}
    body_pair_of = np.array([body_pairs.setdefault((pair.a, pair.b), len(body_pairs)) for pair in pairs],
                            dtype=np.intp)
    return CollisionModel(count, tuple(shapes), tuple(obstacle_list), tuple(pairs), tuple(body_pairs),
                          body_pair_of, tuple(link_rows), np.array(fixed).T.reshape(3, -1), tuple(groups),
                          _BodyMerge.of(body_pair_of))


def _local_rows(shape: Shape) -> list[list[float]]:
    """The homogeneous reference rows of a shape in its own frame: points (w = 1) and directions (w = 0). A
    capsule's start and end, a sphere's centre, a box's centre and three axes."""
    if isinstance(shape, Capsule):
        return [[*shape.start.tolist(), 1.0], [*shape.end.tolist(), 1.0]]
    if isinstance(shape, Sphere):
        return [[*shape.center.tolist(), 1.0]]
    return [[*shape.center.tolist(), 1.0], *([*axis, 0.0] for axis in shape.rotation.T.tolist())]


def _kernel_rows(shape: Shape, rows: list[int], point: bool) -> list[int]:
    """The rows a kernel reads for a shape: a box's four; a round shape's two ends (a sphere's centre twice), or
    its one point where the kernel takes a ``point`` (a sphere's centre, a capsule of length 0's start)."""
    if isinstance(shape, Box):
        return rows
    return rows[:1] if point else [rows[0], rows[-1]]


def _kernel_order(shape: Shape, half_length: float) -> tuple[int, float]:
    """The order of a pair's shapes in its kernel: a box first, then of two round shapes the longer (the bounds
    take the shorter one's middle, and a point comes second); ``half_length``: the shape's
    (:func:`_half_length`)."""
    return (0, 0.0) if isinstance(shape, Box) else (1, -half_length)


def _half_length(shape: Shape) -> float:
    """Half a capsule's length (0 for a sphere; a box is never a round shape's middle: +inf)."""
    if isinstance(shape, Capsule):
        return 0.5 * float(np.linalg.norm(shape.end - shape.start))
    return 0.0 if isinstance(shape, Sphere) else np.inf


def _half_sizes(shapes: list[Shape]) -> np.ndarray | None:
    """(3, P_k, 1): each box's half sizes, for shapes of one family; None for round shapes (no kernel reads it)."""
    if not isinstance(shapes[0], Box):
        return None
    return np.array([shape.half_size.tolist() for shape in shapes]).T[..., None]


def _radii(shapes: list[Shape]) -> np.ndarray | None:
    """(P_k, 1): each round shape's radius, for shapes of one family; None for boxes (no kernel reads it)."""
    if isinstance(shapes[0], Box):
        return None
    return np.array([shape.radius for shape in shapes])[:, None]


# --- validation -----------------------------------------------------------------------------------------------


def _is_index(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _checked_link_count(link_count) -> int:
    if not _is_index(link_count) or link_count < 1:
        raise InvalidInputError(f"link_count must be an integer ≥ 1, not {link_count!r}", location=("link_count",))
    return int(link_count)


def _checked_link_names(link_names, count: int) -> list[str]:
    if link_names is None:
        return [f"link {i}" for i in range(count)]
    names = list(link_names)
    if len(names) != count:
        raise InvalidInputError(f"link_names must name all {count} links, got {len(names)}",
                                location=("link_names",))
    for index, name in enumerate(names):
        if not isinstance(name, str) or not name:
            raise InvalidInputError("a link name must be a non-empty string", location=("link_names", index))
        if names.index(name) != index:
            raise InvalidInputError(f"link name {name!r} is given twice", location=("link_names", index))
    return names


def _checked_link_shapes(link_shapes, count: int) -> list[LinkShape]:
    shapes = list(link_shapes)
    if not shapes:
        raise InvalidInputError("the robot has no collision shapes to check", location=("link_shapes",))
    for index, item in enumerate(shapes):
        if not isinstance(item, LinkShape) or not isinstance(item.shape, _KIND_ORDER):
            raise InvalidInputError("a link shape must be a LinkShape holding a Capsule, Sphere or Box",
                                    location=("link_shapes", index))
        if not _is_index(item.link) or not 0 <= item.link < count:
            raise InvalidInputError(f"link must be a frame index from 0 (the base) to {count - 1} (the flange), "
                                    f"not {item.link!r}", location=("link_shapes", index, "link"))
    return shapes


def _checked_obstacles(obstacles, link_names: set[str]) -> list[Obstacle]:
    items = list(obstacles)
    for index, item in enumerate(items):
        if not isinstance(item, Obstacle) or not isinstance(item.shape, _KIND_ORDER):
            raise InvalidInputError("an obstacle must be an Obstacle holding a Capsule, Sphere or Box",
                                    location=("obstacles", index))
        if not isinstance(item.name, str) or not item.name:
            raise InvalidInputError("an obstacle needs a non-empty name", location=("obstacles", index, "name"))
        if item.name in link_names:
            raise InvalidInputError(f"obstacle name {item.name!r} is the name of a link",
                                    location=("obstacles", index, "name"))
    return items


def _checked_ignore(ignore, count: int) -> set[tuple[int, int]]:
    skipped = set()
    for index, item in enumerate(ignore):
        try:
            first, second = item
        except (TypeError, ValueError):
            raise InvalidInputError("an ignored pair must be two link indices", location=("ignore", index)) from None
        for position, link in enumerate((first, second)):
            if not _is_index(link) or not 0 <= link < count:
                raise InvalidInputError(f"link must be a frame index from 0 to {count - 1}, not {link!r}",
                                        location=("ignore", index, position))
        if first == second:
            raise InvalidInputError(f"an ignored pair needs two different links, not {first} twice",
                                    location=("ignore", index))
        skipped.add((min(first, second), max(first, second)))
    return skipped


def _finite_number(value, location) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"must be a number, not {value!r}", location=location) from None
    if not math.isfinite(number):
        raise InvalidInputError(f"must be finite, not {number}", location=location)
    return number
