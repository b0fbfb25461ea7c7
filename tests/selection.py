"""The selection of one IK result, read as records: what the tests of the selection's rules assert on.

The service selects tables (:func:`service.kinematics.ik.select`); these helpers put a test's IK result (or
padded arrays) into a table, call that one selection, and read its rows back as records. Nothing here decides
anything: the rules under test are all in the service.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from service.kinematics import Violation, violations
from service.kinematics.ik import IKArrays, IKResult, Selection, Solution, SolutionTable, select as select_table


@dataclass(frozen=True)
class Selected:
    """A solution as answered: its joints (one equivalent), and whether and how it breaks the limits."""

    solution: Solution
    within_limits: bool
    violations: list[Violation]


@dataclass
class OneSelection:
    """One target's selection as records."""

    status: str
    solutions: list[Selected]
    rejected: list[Selected]
    expansion_truncated: bool
    trimmed: int
    available: int
    notes: list[str]


def table_of_result(robot, result: IKResult) -> SolutionTable:
    """One target's solutions as a table (labels as codes, in order of first appearance)."""
    solutions = result.solutions if result.status == "ok" else []
    names: dict[str, list] = {}
    for solution in solutions:
        for name, value in solution.branch.items():
            values = names.setdefault(name, [])
            if value not in values:
                values.append(value)
    labels = {name: (tuple(values), np.array([values.index(s.branch[name]) if name in s.branch else -1
                                              for s in solutions], dtype=np.int8)) for name, values in names.items()}
    return SolutionTable(np.zeros(len(solutions), dtype=np.int64),
                         np.array([s.joints for s in solutions], dtype=float).reshape(len(solutions), robot.dof),
                         np.ones(len(solutions), dtype=bool), np.array([s.position_residual for s in solutions]),
                         np.array([s.orientation_residual for s in solutions]), labels)


def table_of_arrays(arrays: IKArrays) -> SolutionTable:
    """Padded arrays' solutions as a table, target by target."""
    rows, slots = np.nonzero(arrays.valid)
    return SolutionTable(rows.astype(np.int64), arrays.joints[rows, slots], np.ones(len(rows), dtype=bool),
                         arrays.position[rows, slots], arrays.orientation[rows, slots],
                         {name: (values, codes[rows, slots]) for name, (values, codes) in arrays.labels.items()})


def select(robot, result: IKResult, limits, **options) -> OneSelection:
    """The service's selection of one IK result, its rows read back as :class:`Selected` records."""
    table = table_of_result(robot, result)
    chosen = select_table(robot, table, 1, limits, **options)

    def records(rows: SolutionTable) -> list[Selected]:
        out = []
        for k in range(len(rows)):
            branch = {name: values[codes[k]] for name, (values, codes) in rows.labels.items() if codes[k] >= 0}
            within = bool(rows.within_limits[k])
            out.append(Selected(Solution(rows.joints[k], branch, float(rows.position[k]), float(rows.orientation[k])),
                                within, [] if within else violations(robot, limits, rows.joints[k])))
        return out

    return OneSelection(str(chosen.status[0]), records(chosen.solutions), records(chosen.rejected),
                        bool(chosen.truncated[0]), int(chosen.trimmed[0]), int(chosen.available[0]),
                        chosen.notes.get(0, []))


def select_arrays(robot, arrays: IKArrays, limits, **options) -> Selection:
    """The service's selection of padded arrays' solutions (every target at once)."""
    return select_table(robot, table_of_arrays(arrays), len(arrays.count), limits, **options)
