"""Helpers shared by the IK tests: requests, random configurations, angles wrapped and matching solutions mod 2π,
checks of every answer, an independent multi-start search, and singular configurations."""

from __future__ import annotations

import numpy as np

from benchmarks import general_6r_singular
from service.kinematics import Robot, forward_kinematics, geometric_jacobian, joint_screws
from service.kinematics.ik import joint_difference, solve_ik_arrays
from service.kinematics.ik._general_6r import General6RPlan
from service.kinematics.ik._screws import move_point
from service.kinematics.ik._verify import residuals

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


def mixed_poses(robot, count: int, seed: int) -> np.ndarray:
    """Random reachable poses, poses at singular configurations (joints snapped to 0, ±π/2 or π) and poses
    moved out of reach."""
    rng = np.random.default_rng([seed, 1])  # not random_configurations' stream: which joints snap is its own draw
    q = random_configurations(robot, count, seed)
    snapped = q[: count // 4].copy()
    snap = rng.random(snapped.shape) < 0.3
    snapped[snap] = rng.choice([0.0, np.pi / 2, -np.pi / 2, np.pi], snap.sum())
    T = forward_kinematics(robot, np.concatenate([q, snapped]))
    far = T[: count // 10].copy()
    far[:, :3, 3] *= rng.uniform(1.5, 3.0, (len(far), 1))
    return np.concatenate([T, far])


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


def found(robot, solutions: np.ndarray, q: np.ndarray, tolerance: float = SAME) -> bool:
    """Whether q is among the solutions (revolute joints modulo 2π): :func:`find` found it."""
    return find(robot, solutions, q, tolerance) is not None


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


def check_general_answers(robot: Robot, q: np.ndarray, plan: General6RPlan | None = None,
                          structure: str = "general_6r"):
    """Solve FK(q) for each row of q (N, 6) by the general solver; assert recall, no wrong solution, no
    `unreachable`, an even count. Returns the arrays.

    Without ``plan`` the router must choose the general solver (``structure``); with it, that plan is used (for a
    real arm a closed-form family may one day claim)."""
    targets = forward_kinematics(robot, q)
    arrays = solve_ik_arrays(robot, targets, plan=plan)
    assert arrays is not None and arrays.structure == structure
    assert (arrays.count > 0).all(), "an FK pose was answered unreachable"
    for row in range(len(q)):
        solutions = arrays.joints[row, :arrays.count[row]]
        assert found(robot, solutions, q[row]), f"pose {row}: generating vector missing"
        position, orientation = residuals(robot, solutions, targets[row])
        assert position.max() <= 1e-9 * robot.characteristic_length and orientation.max() <= 1e-9
        assert arrays.count[row] % 2 == 0  # the real roots of a real polynomial of degree 16 come in pairs
    return arrays


def multistart_solutions(robot: Robot, target: np.ndarray, starts: int, rng: np.random.Generator,
                         slide_range: tuple[float, float] = (-np.pi, np.pi)) -> np.ndarray:
    """Every distinct solution a dense Levenberg–Marquardt search finds from ``starts`` random seeds (revolute
    joints uniform in ±π, prismatic ones in ``slide_range``).

    Knows nothing of the elimination: FK and the geometric Jacobian only, error in units of the robot's size.
    """
    scale = robot.characteristic_length
    q = rng.uniform(-np.pi, np.pi, (starts, 6))
    q[:, ~robot.is_revolute] = rng.uniform(*slide_range, (starts, int((~robot.is_revolute).sum())))
    damping = np.full(starts, 1e-2)
    def error_of(q):
        T = forward_kinematics(robot, q)
        position = (target[:3, 3] - T[:, :3, 3]) / scale
        R = target[:3, :3] @ np.swapaxes(T[:, :3, :3], 1, 2)
        rotation = 0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], 1)
        return np.concatenate([position, rotation], axis=1)
    error = error_of(q)
    for _ in range(80):
        J = geometric_jacobian(robot, q)
        J[:, :3] /= scale
        JtJ = np.swapaxes(J, 1, 2) @ J
        step = np.linalg.solve(JtJ + damping[:, None, None] * np.eye(6),
                               np.einsum("kji,kj->ki", J, error)[..., None])[..., 0]
        trial = q + step
        trial_error = error_of(trial)
        better = (trial_error ** 2).sum(1) < (error ** 2).sum(1)
        q[better], error[better] = trial[better], trial_error[better]
        damping = np.where(better, damping / 10, damping * 10).clip(1e-12, 1e6)
    converged = q[np.abs(error).max(axis=1) < 1e-11]
    revolute = robot.is_revolute
    converged[:, revolute] = wrapped(converged[:, revolute])
    distinct: list[np.ndarray] = []
    for candidate in converged:
        if not any(np.abs(joint_difference(robot, candidate[None], other)).max() < 1e-6 for other in distinct):
            distinct.append(candidate)
    return np.array(distinct).reshape(-1, 6)


def singular_configuration(robot: Robot, rng: np.random.Generator) -> np.ndarray:
    """A configuration with det J = 0: bisection along the first random segment on which det J changes sign."""
    return general_6r_singular.singular_configuration(robot, rng)[0]


def stretched_elbow(plan, q: np.ndarray) -> float:
    """The value of joint 3 at which the wrist point (PUMA type) or the point on axis 4 (UR5 type) is farthest
    from axis 2, for the other joints of q (n,), on the arm of ``plan`` (a closed-form plan of either type): the
    stretched elbow, by golden-section search about a grid maximum."""
    model = plan.model if hasattr(plan, "model") else plan.positioner.model
    if plan.structure == "three_parallel":
        point, anchor, axis = model.points[3], model.points[1], model.directions[1]
    else:
        point, anchor, axis = plan.point, plan.positioner.centre, None

    def reach(value: float) -> float:
        joints = q.copy()
        joints[2] = value
        offset = move_point(model.directions, model.points, model.is_revolute, joints[:3], point) - \
            move_point(model.directions, model.points, model.is_revolute, joints[:1], anchor)
        if axis is not None:  # in the plane normal to the parallel axes
            turned = move_point(model.directions[:1], np.zeros((1, 3)), model.is_revolute[:1], joints[:1], axis)
            offset = offset - (offset @ turned) * turned
        return float(np.linalg.norm(offset))

    grid = np.linspace(-np.pi, np.pi, 721)
    best = grid[int(np.argmax([reach(v) for v in grid]))]
    low, high = best - 2 * np.pi / 720, best + 2 * np.pi / 720
    ratio = (np.sqrt(5) - 1) / 2
    for _ in range(80):
        a, b = high - ratio * (high - low), low + ratio * (high - low)
        low, high = (a, high) if reach(a) < reach(b) else (low, b)
    return (low + high) / 2


def centred_configurations(robot: Robot, count: int, seed: int) -> np.ndarray:
    """Revolute joints uniform in ±π; prismatic joints uniform in ±0.5 (about 0, unlike
    :func:`random_configurations`). Shape (count, n)."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (count, robot.dof))
    q[:, ~robot.is_revolute] = rng.uniform(-0.5, 0.5, (count, int((~robot.is_revolute).sum())))
    return q


def assert_every_solution(robot: Robot, q: np.ndarray, targets: np.ndarray, answer,
                          joints: list[int] | None = None, tolerance: float = 1e-7) -> None:
    """Recall 100 %, 0 wrong solutions (checked by an FK computed here), nothing unreachable.

    ``joints`` limits the recall comparison to those joints (near a singularity the others are determined
    only to rounding divided by the distance from it).
    """
    assert (answer.count >= 1).all(), f"{(answer.count == 0).sum()} of the arm's own FK poses answered unreachable"
    scale = robot.characteristic_length
    rows, slots = np.nonzero(answer.valid)
    reached = forward_kinematics(robot, answer.joints[rows, slots])
    position = np.linalg.norm(reached[:, :3, 3] - targets[rows, :3, 3], axis=-1)
    # ‖R₁ − R₂‖_F = 2√2 sin(θ/2): the rotation angle between them to first order, without arccos' loss near 0
    angle = np.linalg.norm(reached[:, :3, :3] - targets[rows, :3, :3], axis=(-2, -1)) / np.sqrt(2)
    wrong = (position > 1e-9 * scale) | (angle > 1e-9)
    assert not wrong.any(), f"{wrong.sum()} wrong solutions"
    joints = list(range(robot.dof)) if joints is None else joints
    missed = [row for row in range(len(q)) if np.abs(joint_difference(
        robot, answer.joints[row, :answer.count[row]], q[row]))[:, joints].max(axis=1).min() > tolerance]
    assert not missed, f"generating vector missing for {len(missed)} of {len(q)} poses, e.g. {q[missed[0]]}"


def positioner_determinant(robot: Robot, q: np.ndarray, joints: tuple[int, ...], centre) -> np.ndarray:
    """det of the positioner's 3 × 3 Jacobian of the wrist centre at joint values q (M, n)."""
    screws = joint_screws(robot, q)
    point = centre(q)  # (M, 3)
    columns = []
    for j in joints:
        if robot.is_revolute[j]:
            columns.append(np.cross(screws.directions[:, j], point - screws.points[:, j]))
        else:
            columns.append(screws.directions[:, j])
    return np.linalg.det(np.stack(columns, axis=-1))


def positioner_singular_configurations(robot: Robot, plan, count: int, seed: int, search: int | None = None,
                                       pool: int = 2) -> np.ndarray:
    """Random joint vectors moved, along one positioner joint (``search``; by default the third), onto a zero of
    the positioner's Jacobian.

    The 6 × 6 Jacobian about the wrist centre is block-triangular, so these are exactly the arm's singular
    configurations other than the wrist's: a stretched or folded elbow, a shoulder at its boundary, two
    positioner solutions merging.
    """
    if hasattr(plan, "inner"):  # wrist at the base: its centre is fixed in the world
        n = robot.dof
        joints = tuple(sorted(n - 1 - j for j in plan.inner.positioner.joints))
        search = joints[0]  # the inverse chain's third positioner joint (its first one never matters)
        fixed = plan.inner.point

        def centre(q):
            return np.broadcast_to(fixed, (len(q), 3))
    else:
        joints = plan.positioner.joints
        search = joints[2] if search is None else search
        home_inverse = np.linalg.inv(forward_kinematics(robot, np.zeros(robot.dof)))

        def centre(q):
            return (forward_kinematics(robot, q) @ home_inverse @ np.append(plan.point, 1.0))[:, :3]
    grid = np.linspace(-np.pi, np.pi, 721) * (1.0 if robot.is_revolute[search] else 1 / np.pi)
    q = centred_configurations(robot, pool * count, seed)  # the first ``count`` whose Jacobian changes sign on the grid
    trial = np.repeat(q[:, None], len(grid), axis=1)
    trial[..., search] = grid
    det = positioner_determinant(robot, trial.reshape(-1, robot.dof), joints, centre).reshape(len(q), -1)
    change = np.sign(det[:, :-1]) != np.sign(det[:, 1:])
    rows = np.flatnonzero(change.any(axis=1))[:count]
    first = change[rows].argmax(axis=1)
    low, high, f_low = grid[first], grid[first + 1], det[rows, first]
    q = q[rows]
    for _ in range(60):  # bisection on every row at once
        q[:, search] = 0.5 * (low + high)
        f_mid = positioner_determinant(robot, q, joints, centre)
        same = np.sign(f_mid) == np.sign(f_low)
        low, f_low, high = np.where(same, q[:, search], low), np.where(same, f_mid, f_low), \
            np.where(same, high, q[:, search])
    q[:, search] = 0.5 * (low + high)
    found = q
    assert len(found) == count
    return found


def aligning_value(robot: Robot, q: np.ndarray, wrist: tuple[int, int, int]) -> float:
    """The middle wrist joint's value that aligns the outer wrist axes (the same for every q: a wrist property).

    The signed ``(a × c)·b`` changes sign through the alignment as c turns about b; bisection finds it to
    rounding, starting from the best of a grid.
    """
    a, b, c = wrist

    def signed(values: np.ndarray) -> np.ndarray:
        trial = np.repeat(q[None], len(values), axis=0)
        trial[:, b] = values
        axes = joint_screws(robot, trial).directions
        return np.einsum("ni,ni->n", np.cross(axes[:, a], axes[:, c]), axes[:, b]), \
            np.linalg.norm(np.cross(axes[:, a], axes[:, c]), axis=-1)

    grid = np.linspace(-np.pi, np.pi, 3601)
    value, size = signed(grid)
    best = int(np.argmin(size))
    low, high = grid[max(best - 1, 0)], grid[min(best + 1, len(grid) - 1)]
    f_low = signed(np.array([low]))[0][0]
    for _ in range(80):
        mid = 0.5 * (low + high)
        f_mid = signed(np.array([mid]))[0][0]
        if np.sign(f_mid) == np.sign(f_low):
            low, f_low = mid, f_mid
        else:
            high = mid
    assert signed(np.array([low]))[1][0] < 1e-12
    return 0.5 * (low + high)
