"""The general 6R solver (ik/_general_6r.py): every solution of arms with no decomposable geometry.

Independent references: the arm's own FK (poses from random joint vectors must come back, and every answer
must reproduce its target); a dense multi-start Levenberg–Marquardt search (tests/ik_helpers.py), which knows
nothing of the elimination, for the solution counts; Manocha and Canny's published example (IEEE Trans. Robot.
Autom. 10(5), 1994, Tables I and III), an arm with 16 real solutions; and Pieper's condition, evaluated here
on the DH tables, for the routing.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import CONVENTIONS, Joint, Robot, forward_kinematics, geometric_jacobian
from service.kinematics.ik import joint_difference, solve_ik, solve_ik_batch
from service.kinematics.ik._general_6r import General6RPlan, is_pieper
from service.kinematics.ik._general_6r_elimination import solve_arrangement
from service.kinematics.ik import plan_for, solve_ik_arrays
from service.kinematics.ik._plan import geometry_of
from tests.arms import kinova_j2n6s300, random_general_arm, random_rotation
from tests.ik_helpers import check_general_answers, found, multistart_solutions, singular_configuration


# ---------------------------------------------------------------------------
# recall on random arms, three conventions, with base and tool
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("convention", CONVENTIONS)
def test_every_generating_vector_comes_back_on_random_general_arms(convention):
    rng = np.random.default_rng(CONVENTIONS.index(convention) + 100)
    total = complete = 0
    for _ in range(4):
        robot = random_general_arm(rng, convention)
        q = rng.uniform(-np.pi, np.pi, (90, 6))
        arrays = check_general_answers(robot, q)
        total += len(q)
        complete += int(arrays.complete.sum())
    assert total == 360  # 3 conventions × 4 arms × 90 poses = 1,080 poses in all
    # measured: every one of the 1,080 answers is complete (no ambiguous root, every real root verified)
    assert complete == total


def test_the_same_arm_in_three_conventions_gets_the_same_solution_sets():
    """Craig's modified table of a standard-DH arm describes the same screws; the answers must agree."""
    rng = np.random.default_rng(7)
    standard = random_general_arm(rng, "standard")
    # the same chain in Craig's form: row i of the modified table holds a_{i-1}, α_{i-1}, d_i, θ_i
    a, alpha = np.r_[0.0, standard.a[:-1]], np.r_[0.0, standard.alpha[:-1]]
    last = np.eye(4)
    last[:3, :3] = [[1, 0, 0], [0, np.cos(standard.alpha[-1]), -np.sin(standard.alpha[-1])],
                    [0, np.sin(standard.alpha[-1]), np.cos(standard.alpha[-1])]]
    last[0, 3] = standard.a[-1]
    modified = Robot([Joint(f"q{i + 1}", "revolute", a[i], alpha[i], standard.d[i], standard.theta[i])
                      for i in range(6)], convention="modified", world_T_base=standard.world_T_base,
                     flange_T_tool=last @ standard.flange_T_tool)
    q = rng.uniform(-np.pi, np.pi, (20, 6))
    np.testing.assert_allclose(forward_kinematics(modified, q), forward_kinematics(standard, q), atol=1e-12)
    targets = forward_kinematics(standard, q)
    for first, second in zip(solve_ik_batch(standard, targets), solve_ik_batch(modified, targets)):
        assert len(first.solutions) == len(second.solutions)
        mine = np.array([s.joints for s in second.solutions])
        assert all(found(standard, mine, s.joints) for s in first.solutions)


# ---------------------------------------------------------------------------
# counts against an independent oracle
# ---------------------------------------------------------------------------


def test_solution_counts_agree_with_a_dense_multistart_search():
    rng = np.random.default_rng(11)
    counts = []
    for convention in CONVENTIONS:
        robot = random_general_arm(rng, convention)
        q = rng.uniform(-np.pi, np.pi, (4, 6))
        for result, generator in zip(solve_ik_batch(robot, forward_kinematics(robot, q)), q):
            oracle = multistart_solutions(robot, forward_kinematics(robot, generator), 1500, rng)
            mine = np.array([s.joints for s in result.solutions])
            assert result.complete
            assert all(found(robot, mine, s, 1e-6) for s in oracle), "the search found a solution we missed"
            assert len(mine) == len(oracle)
            counts.append(len(mine))
    assert max(counts) > 2  # the comparison covered poses with several solutions (measured: 2 to 8)


def test_every_solution_of_a_kinova_jaco():
    robot = kinova_j2n6s300()
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (300, 6))
    arrays = check_general_answers(robot, q, plan=General6RPlan(geometry_of(robot)))
    assert arrays.complete.all()
    assert arrays.count.max() >= 10  # measured: 2 to 12 solutions per pose


# ---------------------------------------------------------------------------
# the published 16-solution example
# ---------------------------------------------------------------------------

#: Manocha & Canny 1994, Table I (standard DH, Craig's A_i = Rz(θ) Tz(d) Tx(a) Rx(α)); a slight variation of
#: the Manseur–Doty arm (Int. J. Robot. Res. 8(5), 1989).
MANOCHA_CANNY = {"a": [0.3, 1.0, 0.0, 1.5, 0.0, 0.0], "d": [0.0, 0.0, 0.2, 0.0, 0.0, 0.0],
                 "alpha_deg": [90.0, 1.0, 90.0, 1.0, 90.0, 1.0]}
#: Their end-effector pose, as printed (four decimals).
MANOCHA_CANNY_HAND = np.array([[-0.7601, -0.6416, 0.1022, -1.1401],
                               [0.1333, -0.0000, 0.9910, 0.0000],
                               [-0.6359, 0.7669, 0.0855, 0.0000],
                               [0.0, 0.0, 0.0, 1.0]])
#: Table III: the 16 solutions (degrees, two decimals).
MANOCHA_CANNY_SOLUTIONS = np.array([
    [-96.28, -6.27, 179.96, 38.48, 52.55, -39.40], [-120.78, 172.33, -179.07, 31.33, -146.71, 142.82],
    [88.67, -176.72, -176.72, -63.24, 157.19, 140.43], [113.84, 5.30, -177.74, -55.92, -62.98, -43.37],
    [-178.12, 108.19, -147.73, -5.69, -164.67, 179.58], [168.32, -103.89, 146.60, -17.24, -171.87, 98.16],
    [-12.94, -105.09, -114.97, 3.02, 7.41, -79.42], [2.51, 108.07, 112.04, -10.52, 0.00, -0.10],
    [2.51, 108.07, -67.95, -169.47, 179.99, 179.89], [-12.94, -105.09, 65.02, 176.97, 172.58, 100.57],
    [168.32, -103.89, -33.39, -162.75, -8.12, -81.83], [-178.12, 108.19, 32.26, -174.30, -15.32, -0.41],
    [88.67, -176.72, 3.27, -116.75, 22.80, -39.56], [-96.28, -6.27, -0.03, 141.51, 127.44, 140.59],
    [-120.78, 172.33, 0.92, 148.66, -33.28, -37.17], [113.84, 5.30, 2.25, -124.07, -117.01, 136.62]])


def manocha_canny_arm() -> Robot:
    table = MANOCHA_CANNY
    return Robot([Joint(f"q{i + 1}", "revolute", table["a"][i], np.radians(table["alpha_deg"][i]), table["d"][i],
                        0.0) for i in range(6)], convention="standard")


def test_the_manocha_canny_example_has_its_16_published_solutions():
    robot = manocha_canny_arm()
    U, _, Vt = np.linalg.svd(MANOCHA_CANNY_HAND[:3, :3])  # the printed rotation, made orthonormal again
    hand = MANOCHA_CANNY_HAND.copy()
    hand[:3, :3] = U @ Vt
    result = solve_ik(robot, hand)
    assert result.structure == "general_6r" and result.complete
    solutions = np.degrees(np.array([s.joints for s in result.solutions]))
    assert len(solutions) == 16
    for published in MANOCHA_CANNY_SOLUTIONS:
        gap = np.abs((solutions - published + 180.0) % 360.0 - 180.0).max(axis=1)
        # the table has two decimals and the pose four: measured worst 0.04°
        assert gap.min() < 0.1, published


# ---------------------------------------------------------------------------
# θ = π, a near-singular leading matrix, near-singular poses
# ---------------------------------------------------------------------------


def test_roots_at_pi_and_a_singular_leading_matrix():
    """q_a = π makes the leading matrix Σ(π) singular (x_a → ∞): the solver must shift the half-angle's origin
    and still return the solution; every joint at or within 1e-12…1e-6 of π is exercised."""
    rng = np.random.default_rng(3)
    for convention in CONVENTIONS:
        robot = random_general_arm(rng, convention)
        plan = plan_for(robot, constrain_orientation=True, reference=None)
        q = rng.uniform(-np.pi, np.pi, (6 * 4, 6))
        for joint in range(6):
            for k, offset in enumerate((0.0, 1e-12, 1e-9, -1e-6)):
                q[4 * joint + k, joint] = np.pi + offset
        check_general_answers(robot, q)
        # the leading matrix was singular for the exact-π poses of joint a, and the shift moved it away
        a = plan.arrangement.order[0]
        targets = forward_kinematics(robot, q[4 * a:4 * a + 1])
        targets[:, :3, 3] /= plan.scale
        roots = solve_arrangement(plan.arrangement, targets @ plan.home_inverse)
        assert roots.shift[0] != 0.0 and roots.conditioned[0]


def test_near_singular_configurations_are_found_and_said_incomplete_or_counted():
    """At a configuration where det J = 0 two solutions merge (a double root): the generating vector must still
    come back, and the answer may not claim completeness unless its count is consistent (the real roots are even
    in number) or, where it reports the singularity (a double root is listed once), unless a multistart search
    finds no solution it lacks."""
    rng = np.random.default_rng(5)
    robot = random_general_arm(rng, "standard")
    for trial in range(6):
        start, end = rng.uniform(-np.pi, np.pi, (2, 6))
        det = lambda t: np.linalg.det(geometric_jacobian(robot, start + t * (end - start)))
        low, high = 0.0, 1.0
        if np.sign(det(low)) == np.sign(det(high)):
            continue
        for _ in range(60):  # bisection to a configuration with det J = 0
            middle = 0.5 * (low + high)
            low, high = (middle, high) if np.sign(det(middle)) == np.sign(det(low)) else (low, middle)
        for offset in (0.0, 1e-9, 1e-6):
            q = start + (low + offset) * (end - start)
            result = solve_ik(robot, forward_kinematics(robot, q))
            mine = np.array([s.joints for s in result.solutions]).reshape(-1, 6)
            assert found(robot, mine, q, 1e-4), (trial, offset)
            if result.complete and not result.singularities:
                assert len(mine) % 2 == 0, (trial, offset)
            elif result.complete:  # a double root is listed once: the count alone proves nothing
                oracle = multistart_solutions(robot, forward_kinematics(robot, q), 300, np.random.default_rng(trial))
                assert all(found(robot, mine, s, 1e-4) for s in oracle), (trial, offset)


# ---------------------------------------------------------------------------
# routing: Pieper arms never come here
# ---------------------------------------------------------------------------

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


def pieper_arm(rng: np.random.Generator, kind: str, start: int, convention: str) -> Robot:
    """A random 6R arm whose axes start, start+1, start+2 meet in one point or are parallel (standard DH:
    axis i+1 is z_i, so a_i = 0 makes axes i+1, i+2 meet, α_i = 0 makes them parallel)."""
    a, alpha, d, theta = rng.uniform(-1, 1, (4, 6))
    if kind == "intersecting":  # a_{start+1} = a_{start+2} = 0 (0-based rows) and no offset between them
        a[start:start + 2] = 0.0
        d[start + 1] = 0.0
    else:
        alpha[start:start + 2] = 0.0
    if convention == "modified":  # the same conditions one row later in Craig's table
        a, alpha = np.r_[0.0, a[:-1]], np.r_[0.0, alpha[:-1]]
    return Robot([Joint(f"q{i + 1}", "revolute", a[i], alpha[i], d[i], theta[i]) for i in range(6)],
                 convention=convention)


def test_pieper_arms_are_never_routed_to_the_general_solver():
    rng = np.random.default_rng(2)
    # the catalogue's 6-joint Pieper arms (the xArm 6, whose wrist axes do not meet, is a general 6R arm)
    arms = [entry.robot for entry in CATALOGUE.entries() if entry.robot.dof == 6 and is_pieper(geometry_of(entry.robot))]
    assert len(arms) >= 4  # PUMA in three conventions, UR5, the Stanford arm, the textbook elbows
    for kind in ("intersecting", "parallel"):
        for start in range(4):
            for convention in ("standard", "modified"):
                arms.append(pieper_arm(rng, kind, start, convention))
    for arm in arms:
        geometry = geometry_of(arm)
        plan = plan_for(arm, constrain_orientation=True, reference=None)
        assert plan is None or plan.structure != "general_6r", arm
        assert General6RPlan.match(geometry) is None, arm


def test_general_arms_are_routed_to_the_general_solver_with_no_labels():
    robot = random_general_arm(np.random.default_rng(9), "khalil")
    plan = plan_for(robot, constrain_orientation=True, reference=None)
    assert plan.structure == "general_6r" and plan.generic_count == 16
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, 6)
    result = solve_ik(robot, forward_kinematics(robot, q))
    assert result.method == "analytic" and all(s.branch == {} for s in result.solutions)


def test_on_pieper_arms_the_elimination_agrees_with_the_closed_forms():
    """The router keeps PUMA- and UR5-type arms away, but the elimination itself (in the arrangement the plan
    picks) still solves them: its solution sets must equal the closed-form families' — an independent check of
    both."""
    rng = np.random.default_rng(4)
    compared = 0
    for entry in CATALOGUE.entries():
        robot = entry.robot
        # the arms this check was written for; on other Pieper arms (a Jaco2's wrist) the vanishing polynomial
        # loses roots, which is why the router never sends a Pieper arm here
        if entry.description.id not in ("puma560_standard", "puma560_modified", "puma560_khalil", "ur5"):
            continue
        closed = plan_for(robot, constrain_orientation=True, reference=None)
        general = General6RPlan(geometry_of(robot))
        if closed is None or general.arrangement is None:
            continue
        q = rng.uniform(-np.pi, np.pi, (40, 6))
        targets = forward_kinematics(robot, q)
        mine = solve_ik_arrays(robot, targets, plan=general)
        theirs = solve_ik_arrays(robot, targets, plan=closed)
        for row in range(len(q)):
            ours, textbook = mine.joints[row, :mine.count[row]], theirs.joints[row, :theirs.count[row]]
            assert len(ours) == len(textbook), (robot.name, row)
            assert all(found(robot, ours, s, 1e-7) for s in textbook), (robot.name, row)
        compared += 1
    assert compared >= 4  # PUMA 560 in three conventions and the UR5 (the Spong elbows: no arrangement fits)


def test_unreachable_is_a_promise_the_multistart_search_cannot_break():
    """Random targets within the arm's reach sphere: where the answer is `unreachable` and complete, a dense
    search finds no solution either; where it is not, the search's solutions are among ours."""
    rng = np.random.default_rng(21)
    robot = random_general_arm(rng, "modified")
    reach = robot.characteristic_length
    unreachable = 0
    for _ in range(8):
        target = np.eye(4)
        target[:3, :3] = random_rotation(rng)
        target[:3, 3] = robot.world_T_base[:3, 3] + rng.uniform(-0.5, 0.5, 3) * reach
        result = solve_ik(robot, target)
        assert result.structure == "general_6r" and result.complete
        oracle = multistart_solutions(robot, target, 600, rng)
        mine = np.array([s.joints for s in result.solutions]).reshape(-1, 6)
        assert all(found(robot, mine, s, 1e-6) for s in oracle)
        unreachable += result.status == "unreachable"
    assert 0 < unreachable < 8  # both kinds of answer were put to the test


@pytest.mark.parametrize("distance", [3.0, 1e3, 1e6])
def test_targets_beyond_the_reach_bound_are_unreachable_and_complete(distance):
    """Every turn keeps the distance to a point of its axis, so no tool position is farther from axis 1's point
    than |home − p6| + Σ|p_i+1 − p_i|; beyond it the answer is a certain `unreachable`."""
    robot = random_general_arm(np.random.default_rng(8), "standard")
    target = np.eye(4)
    target[:3, 3] = [distance * robot.characteristic_length, 0.0, 0.0]
    result = solve_ik(robot, target)
    assert result.structure == "general_6r" and result.status == "unreachable" and result.complete
    assert result.solutions == []


def test_a_target_whose_eigenvectors_are_dependent_gets_unbounded_conditions():
    """The error bound of a complex root near the axis needs the left eigenvectors, the rows of V⁻¹. A target
    whose eigenvectors are dependent (a defective eigenvalue) has none: its eigenvalues' conditions are inf
    (each such root then counts as ambiguous), and the targets beside it keep their own."""
    from service.kinematics.ik._general_6r_elimination import _eigenvalue_conditions

    well = np.array([[2.0, 1.0], [0.0, 1.0]])  # columns (2, 0) and (1, 1): V⁻¹ rows (0.5, −0.5) and (0, 1)
    dependent = np.array([[1.0, 1.0], [0.0, 0.0]])
    conditions = _eigenvalue_conditions(np.stack([well, dependent, well]))
    expected = np.array([np.hypot(0.5, 0.5) * 2.0, 1.0 * np.sqrt(2.0)])
    np.testing.assert_allclose(conditions[[0, 2]], [expected, expected], rtol=1e-15)
    assert np.isinf(conditions[1]).all()


@pytest.mark.parametrize("size", [1e-12, 1e-9])
def test_an_arm_of_tiny_links_answers_a_direction_target_out_of_reach(client, size):
    """Every link 1e-12 long, each twist 90°: a direction target 0.24 away gave a 500 (the elimination's
    eigenvectors were exactly dependent and V⁻¹ failed). It is out of reach, and said so; a target the arm
    reaches, at its own scale, is answered with solutions the service verified."""
    robot = {"convention": "standard",
             "joints": [{"type": "revolute", "a": size, "d": size, "alpha": np.pi / 2}] * 6}
    far = {"position": [0.1, 0.1, 0.2], "orientation": {"type": "direction", "world_direction": [0, 0, 1]}}
    response = client.post("/v1/ik", json={"robot": robot, "target": far})
    assert response.status_code == 200, response.text
    assert response.json()["status"] == "unreachable"
    near = {"position": [0.1 * size, 0.1 * size, 0.2 * size],
            "orientation": {"type": "direction", "world_direction": [0, 0, 1]}}
    response = client.post("/v1/ik", json={"robot": robot, "target": near})
    assert response.status_code == 200, response.text
    assert response.json()["status"] == "ok" and response.json()["solutions"]


def test_a_batch_larger_than_a_chunk_is_answered_in_one_piece():
    """The solver gives each chunk of targets only the slots it needs; chunks of different widths are merged."""
    from service.kinematics.ik import _closed_form

    robot = random_general_arm(np.random.default_rng(12), "standard")
    q = np.random.default_rng(13).uniform(-np.pi, np.pi, (3 * 64 + 5, 6))
    chunk = _closed_form.CHUNK
    _closed_form.CHUNK = 64
    try:
        whole = solve_ik_arrays(robot, forward_kinematics(robot, q), threads=2)
    finally:
        _closed_form.CHUNK = chunk
    assert len(whole.count) == len(q) and (whole.count > 0).all()
    pieces = [solve_ik_arrays(robot, forward_kinematics(robot, q[start:start + 64]))
              for start in range(0, len(q), 64)]
    assert len({p.joints.shape[1] for p in pieces}) > 1  # the chunks really had different widths
    np.testing.assert_array_equal(whole.count, np.concatenate([p.count for p in pieces]))
    for row in range(len(q)):
        assert found(robot, whole.joints[row, :whole.count[row]], q[row])


def test_the_api_reports_the_general_solvers_completeness_per_target(client):
    """An arm given inline: the response's solver block says general_6r, and `complete` is the core's promise for
    that very target (true at three random configurations; at a singular configuration found by bisection on
    det J, a promise that lists the generating configuration and reports the singularity)."""
    rng = np.random.default_rng(5)
    robot = random_general_arm(rng, "standard")
    robot = Robot(robot.joints, convention="standard")  # the inline description below has no base or tool
    body = {"convention": "standard", "angle_unit": "rad",
            "joints": [{"a": j.a, "alpha": j.alpha, "d": j.d, "theta": j.theta} for j in robot.joints]}
    singular = singular_configuration(robot, np.random.default_rng(1))
    configurations = [singular, *np.random.default_rng(2).uniform(-np.pi, np.pi, (3, 6))]
    promises = []
    for q in configurations:
        target = forward_kinematics(robot, q)
        response = client.post("/v1/ik", json={"robot": body, "target": {"matrix": target.tolist()},
                                                "filter_limits": False})
        assert response.status_code == 200, response.text
        answer = response.json()
        core = solve_ik(robot, target)
        if core.complete:
            assert answer["solver"]["structure"] == "general_6r" and answer["solver"]["method"] == "analytic"
        # a target the elimination cannot promise is completed by the numeric search, seeded with its roots
        assert answer["solver"]["complete"] is core.complete
        assert len(answer["solutions"]) == len(core.solutions)
        promises.append(core.complete)
        if core.complete and q is singular:  # two roots meet: the promise must still hold the generating one
            listed = np.array([s["joints"] for s in answer["solutions"]])
            assert np.abs(joint_difference(robot, listed, q)).max(axis=1).min() <= 1e-6
            assert answer["singularities"] and core.singularities
    assert promises[1:] == [True, True, True]
