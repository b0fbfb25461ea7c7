"""The one form of an IK answer's solutions: a columnar table, one row per solution, grouped by target.

Every solver's candidates are verified into a :class:`SolutionTable`
(:func:`~._verify.verify`); the selection takes that table and returns two
(kept and rejected); :class:`~._answer.IKAnswer` holds them and the boundary
encodes them as they stand. Label codes are merged in one place
(:func:`merged_labels`); per-target singular conditions travel beside it as
:class:`~._types.SingularFlags`.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from ..collision import Contacts
from ._types import LabelCodes


@functools.lru_cache(maxsize=64)
def branch_labels(names: tuple[str, ...], values: tuple[tuple[str, ...], ...]) -> Mapping[tuple[int, ...], dict]:
    """Every branch labels can word: codes (a tuple, one per name of ``names``, −1 where the label is left out) →
    its dict, name → label (``values`` per name). A family has a few names of two values each, and a table merges
    its parts' vocabularies, so the combinations are few (27 for a shoulder, an elbow and a wrist); the dicts are
    shared, read-only by convention (a caller copies the one it hands out), and kept for the next answer of the
    same vocabularies (a few dozen of them at most). The one place labels are worded."""
    choices = [range(-1, len(labels)) for labels in values]
    return {codes: {name: labels[code] for name, labels, code in zip(names, values, codes) if code >= 0}
            for codes in itertools.product(*choices)}


@dataclass(frozen=True)
class SolutionTable:
    """Solutions of many targets, one row each, grouped by target in output order.

    Attributes
    ----------
    target : ndarray of int, shape (S,)
        The row's target index, non-decreasing.
    joints : ndarray, shape (S, n)
        Radians / length units.
    within_limits : ndarray of bool, shape (S,)
        Whether the row fits the limits (True before any selection).
    position, orientation : ndarrays, shape (S,)
        FK residuals: length units and radians (the angle between tool axis and direction for a direction
        target; NaN for a position-only target).
    labels : dict
        Branch labels: name → (values, codes (S,) int8), ``values[code]`` the row's label, −1 where it has none.
    clearance : ndarray, shape (S,), optional
    contacts : Contacts, optional
        With a collision check (:mod:`service.kinematics.collision`): the smallest signed distance over the
        checked pairs, and each row's pairs closer than the margin (:class:`~..collision.Contacts`, S rows).
        None without.
    roll : ndarray, shape (S,), optional
        A direction target solved over its free roll (:mod:`._direction`): the row's roll of the tool about the
        tool axis, radians in (−π, π] (:func:`~._direction.rolls_of`); NaN for rows of other targets. None when
        no row has one.
    """

    target: np.ndarray
    joints: np.ndarray
    within_limits: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    labels: LabelCodes
    clearance: np.ndarray | None = None
    contacts: Contacts | None = None
    roll: np.ndarray | None = None

    @classmethod
    def empty(cls, dof: int) -> "SolutionTable":
        """A table of no rows for an arm of ``dof`` joints."""
        return cls(np.zeros(0, dtype=np.int64), np.zeros((0, dof)), np.zeros(0, dtype=bool), np.zeros(0),
                   np.zeros(0), {})

    def __len__(self) -> int:
        return len(self.target)

    def take(self, index: np.ndarray, *, joints: np.ndarray | None = None,
             within_limits: np.ndarray | None = None) -> "SolutionTable":
        """The rows ``index`` (indices, a boolean mask or a slice), in that order; with ``joints`` (K, n) and
        ``within_limits`` (K,), listed at those values and flags instead of their own (a selection's
        2π-equivalents: the rows' own are then not gathered)."""
        if isinstance(index, np.ndarray) and index.dtype != bool and not len(index):
            index = slice(0, 0)  # none (a selection's usual rejected rows): views, not nine gathers of nothing
        return SolutionTable(self.target[index], self.joints[index] if joints is None else joints,
                             self.within_limits[index] if within_limits is None else within_limits,
                             self.position[index], self.orientation[index],
                             {name: (values, codes[index]) for name, (values, codes) in self.labels.items()},
                             None if self.clearance is None else self.clearance[index],
                             None if self.contacts is None else self.contacts.take(index),
                             None if self.roll is None else self.roll[index])

    def listed_at(self, joints: np.ndarray, within_limits: np.ndarray) -> "SolutionTable":
        """The same rows listed at other joint values (S, n) and limit flags (S,): a selection's 2π-equivalents."""
        return SolutionTable(self.target, joints, within_limits, self.position, self.orientation, self.labels,
                             self.clearance, self.contacts, self.roll)

    def with_targets(self, target: np.ndarray) -> "SolutionTable":
        """The same rows numbered by other targets (``target`` (S,) non-decreasing), as when a part's rows
        take their place among a whole answer's."""
        return SolutionTable(np.asarray(target, dtype=np.int64), self.joints, self.within_limits, self.position,
                             self.orientation, self.labels, self.clearance, self.contacts, self.roll)

    def with_clearances(self, clearance: np.ndarray, contacts: Contacts) -> "SolutionTable":
        """The same rows with their collision check (see the class docstring)."""
        return replace(self, clearance=clearance, contacts=contacts)

    def with_roll(self, roll: np.ndarray) -> "SolutionTable":
        """The same rows with each one's tool roll (S,), radians (see the class docstring)."""
        return replace(self, roll=np.asarray(roll, dtype=float))

    @classmethod
    def concat(cls, tables: list["SolutionTable"], dof: int) -> "SolutionTable":
        """The rows of ``tables`` in turn (regrouped by target, stably, when they interleave), their labels on
        one vocabulary per name (:func:`merged_labels`)."""
        tables = [table for table in tables if len(table)]
        if not tables:
            return cls.empty(dof)
        if len(tables) == 1:
            return tables[0]
        checked = any(t.clearance is not None for t in tables)
        table = cls(np.concatenate([t.target for t in tables]), np.concatenate([t.joints for t in tables]),
                    np.concatenate([t.within_limits for t in tables]),
                    np.concatenate([t.position for t in tables]), np.concatenate([t.orientation for t in tables]),
                    merged_labels([t.labels for t in tables], [len(t) for t in tables]),
                    np.concatenate([t.clearance if t.clearance is not None else np.full(len(t), np.inf)
                                    for t in tables]) if checked else None,
                    Contacts.concat([t.contacts if t.contacts is not None else Contacts.none(len(t))
                                     for t in tables]) if checked else None,
                    np.concatenate([t.roll if t.roll is not None else np.full(len(t), np.nan) for t in tables])
                    if any(t.roll is not None for t in tables) else None)
        if (np.diff(table.target) < 0).any():
            table = table.take(np.argsort(table.target, kind="stable"))
        return table

    def branches(self, *, own: bool = False) -> list[dict]:
        """Each row's branch labels as a dict, name → label (a name left out where the row's code is −1), worded
        once per combination of codes (:func:`branch_labels`). Rows with the same codes, in this table and in
        others of the same vocabularies, share one dict (read-only by convention): an answer has a handful of
        distinct branches among thousands of rows. With ``own``, each row has a dict of its own (the caller's to
        keep)."""
        if not self.labels or not len(self.target):
            if own:
                return [{} for _ in range(len(self.target))]
            empty: dict = {}
            return [empty] * len(self.target)
        names = tuple(self.labels)
        by_codes = branch_labels(names, tuple(tuple(self.labels[name][0]) for name in names))
        keys = zip(*(self.labels[name][1].tolist() for name in names))  # each row's codes
        if own:
            return [by_codes[key].copy() for key in keys]
        return list(map(by_codes.__getitem__, keys))

    def bounds(self, n_targets: int) -> tuple[np.ndarray, np.ndarray]:
        """Each target's rows as [start, stop), shape (N,) each."""
        edges = np.searchsorted(self.target, np.arange(n_targets + 1))
        return edges[:-1], edges[1:]

    def counts(self, n_targets: int) -> np.ndarray:
        """Rows per target, shape (N,)."""
        return np.bincount(self.target, minlength=n_targets)[:n_targets]


def merged_labels(pieces: list[LabelCodes], lengths: list[int]) -> LabelCodes:
    """The label codes of several pieces laid end to end (codes along axis 0; ``lengths`` their sizes there):
    one vocabulary per name, its values in order of first appearance; −1 where a piece lacks the name or the
    value."""
    vocabularies: dict[str, list] = {}
    for piece in pieces:
        for name, (values, _) in piece.items():
            vocabulary = vocabularies.setdefault(name, [])
            vocabulary.extend(value for value in values if value not in vocabulary)
    merged: LabelCodes = {}
    for name, vocabulary in vocabularies.items():
        columns = []
        for piece, length in zip(pieces, lengths):
            if name not in piece:
                columns.append(np.full(length, -1, dtype=np.int8))
                continue
            values, codes = piece[name]
            if list(values) == vocabulary[:len(values)]:
                columns.append(codes.astype(np.int8, copy=False))
                continue
            lookup = np.array([*(vocabulary.index(value) for value in values), -1], dtype=np.int8)
            columns.append(lookup[codes])
        merged[name] = (tuple(vocabulary), np.concatenate(columns) if len(columns) > 1 else columns[0])
    return merged

