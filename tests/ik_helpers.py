"""Helpers shared by the IK tests: requests, random configurations, angles wrapped and matching solutions mod 2π."""

from __future__ import annotations

import numpy as np

from service.kinematics.ik import joint_difference

#: Two joint vectors are the same solution when every joint agrees to this (rad, or length units).
SAME = 1e-7


def wrapped(angle) -> np.ndarray:
    """``angle`` (radians, any shape) wrapped into (−π, π]."""
    return np.pi - np.mod(np.pi - np.asarray(angle), 2 * np.pi)


def angle_gap(a, b) -> np.ndarray:
    """|a − b| modulo 2π, in [0, π] (a and b broadcast)."""
    return np.abs(wrapped(np.asarray(a) - np.asarray(b)))


def random_configurations(robot, count: int, seed: int) -> np.ndarray:
    """Revolute joints uniform in ±π; prismatic joints uniform in (0.1, 1) robot sizes / 2. Shape (count, n)."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (count, robot.dof))
    slides = ~robot.is_revolute
    q[:, slides] = rng.uniform(0.1, 1.0, (count, slides.sum())) * robot.characteristic_length / 2
    return q


def unlimited(robot) -> list[None]:
    """A ``limits`` override with no limits at all: the mathematical solution set, no 2π expansion."""
    return [None] * robot.dof


def slides_non_negative(robot) -> list[dict | None]:
    """A ``limits`` override keeping every prismatic joint ≥ 0 (the textbook's choice) and nothing else."""
    return [None if revolute else {"lower": 0.0, "upper": None} for revolute in robot.is_revolute]


def pose_target(T: np.ndarray, kind: str = "pose") -> dict:
    """A request target from a (4, 4) pose: the whole matrix, or only its position."""
    T = np.asarray(T, dtype=float)
    return {"matrix": T.tolist()} if kind == "pose" else {"position": T[:3, 3].tolist()}


def joints_of(result: dict, key: str = "solutions") -> np.ndarray:
    """The joint vectors of an IK response, shape (k, n) (k may be 0)."""
    rows = [s["joints"] for s in result[key]]
    return np.array(rows, dtype=float).reshape(len(rows), -1)


def find(robot, solutions: np.ndarray, q: np.ndarray, tolerance: float = SAME) -> int | None:
    """Index of the solution equal to q (revolute joints modulo 2π), or None."""
    if len(solutions) == 0:
        return None
    distance = np.abs(joint_difference(robot, solutions, np.asarray(q, dtype=float))).max(axis=1)
    index = int(np.argmin(distance))
    return index if distance[index] <= tolerance else None


def same_set(robot, first: np.ndarray, second: np.ndarray, tolerance: float = SAME) -> bool:
    """Whether two lists of joint vectors hold the same solutions (mod 2π), each once."""
    if len(first) != len(second):
        return False
    return all(find(robot, second, q, tolerance) is not None for q in first) and \
        all(find(robot, first, q, tolerance) is not None for q in second)


def fk_matrix(client, robot_id: str, q) -> np.ndarray:
    """world_T_tool of a catalogue robot at q, through the FK endpoint."""
    response = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": list(map(float, q))})
    assert response.status_code == 200, response.text
    return np.array(response.json()["pose"]["matrix"])


def fk_inline(client, robot: dict, q) -> np.ndarray:
    """world_T_tool of an inline robot description at q."""
    response = client.post("/v1/fk", json={"robot": robot, "joints": list(map(float, q))})
    assert response.status_code == 200, response.text
    return np.array(response.json()["pose"]["matrix"])
