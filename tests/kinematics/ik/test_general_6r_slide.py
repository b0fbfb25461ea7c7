"""The general solver on 6-joint arms with one slide (ik/_general_6r.py, its algebra in
ik/_general_6r_elimination.py, "One slide"): every solution of a prismatic joint plus five revolute joints of
general geometry, such as a mobile manipulator's torso lift under a 5R arm.

Independent references: the arm's own FK (poses from random joint vectors must come back, and every answer must
reproduce its target); the dense multi-start Levenberg–Marquardt search of ``test_general_6r`` (FK and the
Jacobian only) for the solution sets; and, for the algebra the module builds on, the 14 Raghavan–Roth quantities
computed here from the robot's own joint screws.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import CONVENTIONS, Joint, Robot, forward_kinematics, joint_screws
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, plan_for, solve_ik, unlimited
from service.kinematics.ik._general_6r import GENERAL_5R1P, General6RPlan
from service.kinematics.ik._general_6r_elimination import Arrangement
from service.kinematics.ik._plan import geometry_of
from service.kinematics.ik._verify import residuals
from tests.arms import random_rotation
from tests.ik_helpers import check_general_answers, found, multistart_solutions

#: Geometry rounded as CAD exports round it (metres to the micrometre).
CAD = 6


def slide_arm(rng: np.random.Generator, slide: int, convention: str, joints: int = 6) -> Robot:
    """A random arm with one prismatic joint at index ``slide`` and revolute joints elsewhere (DH entries uniform
    in ±1, rounded to CAD precision, in the given convention), with a random base and tool."""
    rows = np.round(rng.uniform(-1, 1, (joints, 4)), CAD)
    arm = [Joint(f"q{i + 1}", "prismatic" if i == slide else "revolute", *rows[i]) for i in range(joints)]
    base, tool = np.eye(4), np.eye(4)
    base[:3, :3] = random_rotation(rng)
    base[:3, 3] = np.round(rng.uniform(-1, 1, 3), CAD)
    tool[:3, :3] = random_rotation(rng)
    tool[:3, 3] = np.round(rng.uniform(-0.3, 0.3, 3), CAD)
    return Robot(arm, convention=convention, world_T_base=base, flange_T_tool=tool)


def torso_lift_arm(rng: np.random.Generator, arm_joints: int = 5) -> Robot:
    """A mobile manipulator: a vertical torso lift (0…0.6 m) under an arm of ``arm_joints`` revolute joints of
    general geometry (standard DH, CAD-rounded), its tool offset along the flange."""
    lift = Joint("torso_lift", "prismatic", 0.0, 0.0, 0.35, 0.0, lower=0.0, upper=0.6)
    rows = np.round(np.column_stack([rng.uniform(0.05, 0.4, arm_joints), rng.uniform(-np.pi, np.pi, arm_joints),
                                     rng.uniform(-0.2, 0.2, arm_joints), rng.uniform(-1, 1, arm_joints)]), CAD)
    arm = [Joint(f"arm_{i + 1}", "revolute", *rows[i]) for i in range(arm_joints)]
    tool = np.eye(4)
    tool[2, 3] = 0.12
    return Robot([lift, *arm], convention="standard", flange_T_tool=tool)


def configurations(rng: np.random.Generator, robot: Robot, count: int) -> np.ndarray:
    """Random joint vectors: revolute joints in ±π, prismatic ones within their limits or ±1.5 length units."""
    q = rng.uniform(-np.pi, np.pi, (count, robot.dof))
    for j in np.flatnonzero(~robot.is_revolute):
        low, high = (robot.lower[j], robot.upper[j]) if np.isfinite(robot.upper[j]) else (-1.5, 1.5)
        q[:, j] = rng.uniform(low, high, count)
    return q


def check_every_vector_returns(robot: Robot, q: np.ndarray) -> np.ndarray:
    """``check_general_answers`` of the 6R tests with the slide's structure: every generating vector back, no wrong
    solution, no `unreachable`, an even count. Returns which answers are complete (N,)."""
    return check_general_answers(robot, q, structure=GENERAL_5R1P).complete


# ---------------------------------------------------------------------------
# the algebra: the slide's quantities are quadratic in d, and their d² part has rank 4
# ---------------------------------------------------------------------------


def test_the_slides_quantities_are_quadratic_in_its_value_with_a_rank_4_leading_part():
    """With the slide as joint a, the point p of axis 4 moved by joints 1…3 (from a point of the slide's line)
    and its direction l give p, l, p·l, p×l linear in d and p·p, l(p·p) − 2p(p·l) quadratic; only those four
    of the 14 quantities have a d² part, so the elimination's leading matrix in d has rank 8 of 12 at most (the
    module's reason for the Möbius map rather than a rescaling of d). Computed here from the robot's joint
    screws."""
    rng = np.random.default_rng(41)
    robot = slide_arm(rng, 0, "standard")
    slides = np.linspace(-2.0, 2.0, 5)
    powers = np.vander(slides, 3, increasing=True)  # (5, 3): 1, d, d²
    d_squared = []
    for q2, q3 in rng.uniform(-np.pi, np.pi, (12, 2)):
        rows = []
        for d in slides:
            screws = joint_screws(robot, np.array([d, q2, q3, 0.0, 0.0, 0.0]))
            p = screws.points[3] - screws.points[0]  # the slide's own point stays; axis 4's point moves rigidly
            l = screws.directions[3]
            rows.append(np.concatenate([p, l, [p @ p, p @ l], np.cross(p, l), l * (p @ p) - 2 * p * (p @ l)]))
        rows = np.array(rows)  # (5 slide values, 14)
        fit = np.linalg.lstsq(powers, rows, rcond=None)[0]  # (3, 14)
        assert np.abs(powers @ fit - rows).max() < 1e-10  # exactly quadratic
        d_squared.append(fit[2])
    d_squared = np.abs(np.array(d_squared))  # (12 samples, 14)
    assert d_squared[:, [0, 1, 2, 3, 4, 5, 7, 8, 9, 10]].max() < 1e-10  # p, l, p·l, p×l: linear in d
    assert d_squared[:, 6].min() > 0.5 and d_squared[:, 11:].max() > 0.1  # p·p and l(p·p) − 2p(p·l): quadratic


# ---------------------------------------------------------------------------
# recall on random arms: the slide at each position, three conventions, CAD rounding, base and tool
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("convention", CONVENTIONS)
def test_every_generating_vector_comes_back_with_the_slide_anywhere(convention):
    rng = np.random.default_rng(CONVENTIONS.index(convention) + 300)
    total = complete = 0
    for slide in range(6):
        robot = slide_arm(rng, slide, convention)
        q = configurations(rng, robot, 40)
        answered = check_every_vector_returns(robot, q)
        total += len(q)
        complete += int(answered.sum())
    assert total == 240  # 6 positions of the slide × 40 poses, per convention
    # measured: every one of the 720 answers is complete (no ambiguous root, every real root verified)
    assert complete == total


@pytest.mark.parametrize("slide", [0, 2, 3, 5])
def test_the_slide_as_joint_a_with_its_interval_map(slide):
    """The arrangement with the slide as joint a (Σ quadratic in d with a rank-deficient d² part, mapped per target
    to a half-angle over an interval that holds every solution's d), forced even where the plan prefers another:
    every pose comes back, complete."""
    rng = np.random.default_rng(60 + slide)
    robot = slide_arm(rng, slide, "standard")
    plan = General6RPlan(geometry_of(robot))
    reverse = slide > 2
    first = 5 - slide if reverse else slide
    plan.arrangement = Arrangement(plan.directions, plan.points, plan.revolute, reverse, first)
    assert plan.arrangement.slide and plan.arrangement.order[0] == slide
    q = configurations(rng, robot, 40)
    arrays = check_general_answers(robot, q, plan=plan, structure=GENERAL_5R1P)
    assert arrays.complete.all()  # measured: all 160 complete


@pytest.mark.parametrize("slide, pair", [(0, 4), (0, 2), (3, 0), (3, 4), (5, 0), (2, 0)])
def test_arms_with_two_parallel_axes_are_solved_by_another_arrangement(slide, pair):
    """Joints ``pair`` and ``pair + 1`` parallel (standard DH: α = 0 in row ``pair``). With the slide as joint a
    some of these make the right-hand coefficients or Σ singular (parallel e, f; parallel c, d); the plan must
    find an arrangement that puts the slide elsewhere and still answer every pose completely."""
    rng = np.random.default_rng(50 + 6 * slide + pair)
    robot = slide_arm(rng, slide, "standard")
    rows = [Joint(j.name, j.kind, j.a, 0.0 if i == pair else j.alpha, j.d, j.theta) for i, j in enumerate(robot.joints)]
    robot = Robot(rows, convention="standard", world_T_base=robot.world_T_base, flange_T_tool=robot.flange_T_tool)
    geometry = geometry_of(robot)
    assert geometry.parallel(pair, pair + 1)
    q = configurations(rng, robot, 30)
    assert check_every_vector_returns(robot, q).all()


def test_solution_sets_agree_with_a_dense_multistart_search():
    rng = np.random.default_rng(17)
    counts = []
    for slide, convention in ((0, "standard"), (2, "modified"), (3, "khalil"), (5, "standard")):
        robot = slide_arm(rng, slide, convention)
        q = configurations(rng, robot, 3)
        for result, generator in zip([solve_ik(robot, T) for T in forward_kinematics(robot, q)], q):
            oracle = multistart_solutions(robot, forward_kinematics(robot, generator), 1500, rng, (-6.0, 6.0))
            mine = np.array([s.joints for s in result.solutions])
            assert result.structure == GENERAL_5R1P and result.complete
            assert all(found(robot, mine, s, 1e-6) for s in oracle), "the search found a solution we missed"
            assert len(mine) == len(oracle)
            counts.append(len(mine))
    assert max(counts) > 2  # the comparison covered poses with several solutions


def test_a_torso_lift_under_a_general_5r_arm():
    """The issue's case: a mobile manipulator's lift with a general 5R arm answers in closed form, complete,
    with every solution the multi-start search finds (lift limits lifted, as the solver reports all)."""
    rng = np.random.default_rng(23)
    robot = torso_lift_arm(rng)
    assert plan_for(robot, constrain_orientation=True, reference=None).structure == GENERAL_5R1P
    q = configurations(rng, robot, 30)
    assert check_every_vector_returns(robot, q).all()
    for generator in q[:4]:
        target = forward_kinematics(robot, generator)
        result = solve_ik(robot, target)
        oracle = multistart_solutions(robot, target, 1500, rng, (-3.0, 3.0))
        mine = np.array([s.joints for s in result.solutions])
        assert result.method == "analytic" and result.complete
        assert all(found(robot, mine, s, 1e-6) for s in oracle) and len(mine) == len(oracle)


def test_a_long_rail_under_a_small_arm():
    """A 10 m horizontal rail under a 5R arm of ~1 m: slide values many times the arm's size (its length unit)."""
    rng = np.random.default_rng(27)
    rows = np.round(np.column_stack([rng.uniform(0.05, 0.3, 5), rng.uniform(-np.pi, np.pi, 5),
                                     rng.uniform(-0.1, 0.1, 5), rng.uniform(-1, 1, 5)]), CAD)
    rail = Joint("rail", "prismatic", 0.0, np.pi / 2, 0.5, 0.0, lower=-10.0, upper=10.0)
    robot = Robot([rail, *(Joint(f"arm_{i + 1}", "revolute", *rows[i]) for i in range(5))], convention="standard")
    q = configurations(rng, robot, 40)
    assert np.abs(q[:, 0]).max() > 8.0
    assert check_every_vector_returns(robot, q).all()


def test_unreachable_is_a_promise_the_multistart_search_cannot_break():
    """A slide has no reach bound: `unreachable` with `complete` must come from the eigenproblem alone."""
    rng = np.random.default_rng(29)
    robot = slide_arm(rng, 1, "standard")
    checked = 0
    for _ in range(40):
        target = np.eye(4)
        target[:3, :3] = random_rotation(rng)
        target[:3, 3] = rng.uniform(-2.5, 2.5, 3)
        result = solve_ik(robot, target)
        if result.solutions or not result.complete:
            continue
        assert result.status == "unreachable"
        assert len(multistart_solutions(robot, target, 400, rng, (-8.0, 8.0))) == 0
        checked += 1
        if checked == 4:
            break
    assert checked == 4  # measured: most random poses of this arm are out of reach of its orientation


def test_arms_the_elimination_does_not_cover_are_not_routed_to_it():
    """Two slides, or a slide arm with three consecutive axes through one point (a spherical wrist), are not
    the general solver's."""
    rng = np.random.default_rng(31)
    two = slide_arm(rng, 0, "standard")
    two = Robot([two.joints[0], Joint("q2", "prismatic", 0.3, 1.0, 0.2, 0.4), *two.joints[2:]],
                convention="standard")
    assert General6RPlan.match(geometry_of(two)) is None
    wrist = slide_arm(rng, 1, "standard")
    rows = [Joint(j.name, j.kind, j.a, j.alpha, j.d, j.theta) for j in wrist.joints]
    rows[3] = Joint("q4", "revolute", 0.0, np.pi / 2, 0.5, 0.0)  # standard DH: a_4 = a_5 = 0, d_5 = 0 make
    rows[4] = Joint("q5", "revolute", 0.0, -np.pi / 2, 0.0, 0.0)  # axes 4, 5, 6 meet in one point
    assert General6RPlan.match(geometry_of(Robot(rows, convention="standard"))) is None


# ---------------------------------------------------------------------------
# the 7-joint lift + 6R arm with an arm joint free: the locked arm is P + 5R
# ---------------------------------------------------------------------------


def test_a_torso_lift_and_6r_arm_with_an_arm_joint_free_is_closed_form_at_the_value_asked():
    rng = np.random.default_rng(37)
    robot = torso_lift_arm(rng, arm_joints=6)
    q = configurations(rng, robot, 6)
    for generator in q:
        target = forward_kinematics(robot, generator)
        options = AnswerOptions(limits=unlimited(robot), filter_limits=False,
                                free_joints=[(2, [float(generator[2])], None)])
        answer = answer_ik(robot, IKTargets.poses(target[None], constrain_orientation=True), options)
        view = answer.target(0)
        assert view.solver.method == "analytic" and view.solver.complete
        assert view.solver.structure == f"{GENERAL_5R1P} with q3 free"
        joints = view.solutions.joints
        assert np.all(joints[:, 2] == generator[2])  # the free value asked holds in every solution
        assert found(robot, joints, generator)
        position, orientation = residuals(robot, joints, target)
        assert position.max() <= 1e-9 * robot.characteristic_length and orientation.max() <= 1e-9
