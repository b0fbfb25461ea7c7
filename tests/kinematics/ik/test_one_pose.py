"""The families' scalar paths for one pose (``solve_one`` and the labels it gives: ik/_scalar.py) against their
array solvers, and the duplicate scan of many slots against the pairwise scan."""

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import forward_kinematics, geometric_jacobian
from service.kinematics.ik import _verify, joint_difference, solve_ik, wrap_revolute
from service.kinematics.ik import cached_plan
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, results_of
from service.kinematics.ik._closed_form import FEW_TARGETS, _one_pose_candidates
from service.kinematics.ik._goals import PoseGoal
from service.kinematics.ik._verify import accepted, residual_arrays

from tests.arms import random_family_arm
from tests.ik_helpers import mixed_poses, random_configurations

_CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
_PLANS = {entry.description.id: (entry.robot, cached_plan(entry.robot, constrain_orientation=True, reference=None))
          for entry in _CATALOGUE.entries()}
# Robots without an analytic plan (the 7-joint arms: numeric fallback) have no scalar path either.
ONE_POSE_ROBOTS = sorted(robot_id for robot_id, (robot, plan) in _PLANS.items() if hasattr(plan, "solve_one")
                         and plan.solve_one(forward_kinematics(robot, np.full(robot.dof, 0.3))) is not None)
_POSITION_PLANS = {entry.description.id: cached_plan(entry.robot, constrain_orientation=False, reference=None)
                   for entry in _CATALOGUE.entries()}
#: the arms whose position targets (the joints past the third held at 0) have a scalar path
POSITION_ROBOTS = sorted(robot_id for robot_id, plan in _POSITION_PLANS.items() if getattr(plan, "_one_pose", None))


def test_the_hot_families_are_covered():
    """The PUMA type, the OPW type (KUKA, ABB, Fanuc: issue 24 asked for it), the UR type, the Stanford type (its
    slide through axis 2 shares the PUMA's structure name), the SCARA (with its roll, and without), the polar
    arms (a slide through axis 2 or missing it, with a roll or nothing after it), the planar two-joint arm, the
    cylindrical arms and the spherical wrist alone; and position targets (the joints past the third held) of the
    six-joint arms with those shoulders, and of the planar arm. Of the catalogue's arms of six joints or fewer,
    only the xArm 6 (general 6R) and the SO-101 (five joints, its parallel axes rounded) run the array
    program."""
    structures = {cached_plan(_CATALOGUE.get(rid).robot, constrain_orientation=True, reference=None).structure
                  for rid in ONE_POSE_ROBOTS}
    assert structures == {"intersecting_shoulder+spherical_wrist", "offset_shoulder_parallel_elbow+spherical_wrist",
                          "three_parallel", "parallel_shoulder+roll", "parallel_shoulder", "intersecting_shoulder",
                          "intersecting_shoulder+roll", "one_revolute+roll", "spherical_wrist",
                          "one_revolute_two_prismatic", "one_revolute_two_prismatic+spherical_wrist"}
    assert {"puma560_standard", "kuka_kr6_r900_2", "spong_ex3_5_stanford", "ur5", "spong_ex3_1_planar_rr"} <= \
        set(POSITION_ROBOTS)
    without = {entry.description.id for entry in _CATALOGUE.entries() if entry.robot.dof <= 6} - set(ONE_POSE_ROBOTS)
    assert without == {"ufactory_xarm6", "so101"}
    assert "spong_ex3_5_stanford" in ONE_POSE_ROBOTS


@pytest.mark.parametrize("robot_id", ONE_POSE_ROBOTS)
def test_scalar_candidates_are_the_array_candidates(robot_id):
    """Same slots, same valid slots and joints, and no singularity, wherever the scalar path answers; the
    same branch labels wherever its labeller answers."""
    robot = _CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    answered = labelled = as_array = 0
    for T in mixed_poses(robot, 400, seed=11):
        one_pose = plan.solve_one(T)
        if one_pose is None:
            continue
        answered += 1
        array = plan.solve(T[None], None)
        assert (one_pose.valid == array.valid).all()
        assert not array.singularities.entries
        valid = array.valid[0]
        assert np.abs(joint_difference(robot, one_pose.joints[0, valid], array.joints[0, valid])).max() <= 1e-9
        assert np.isnan(one_pose.joints[0, ~valid]).any(axis=-1).all()
        if one_pose.slots_as_array:  # and the array solver's empty slots are undefined too (no least-squares value)
            assert not np.isfinite(array.joints[0, ~valid]).all(axis=-1).any()
            as_array += 1
        joints = wrap_revolute(robot, np.nan_to_num(one_pose.joints))
        # as solve_ik: label the slots the FK check keeps (not the least-squares ones it rejects)
        position, orientation = residual_arrays(robot, joints, T[None])
        valid = one_pose.valid[0] & accepted(robot, position[0], orientation[0], True)
        labels = one_pose.label_codes(valid.tolist())
        if labels is not None:
            labelled += 1
            expected = plan.label_codes(joints[0])
            assert list(labels) == list(expected)
            for name, (values, codes) in labels.items():
                assert values == expected[name][0]
                assert (codes[valid] == expected[name][1][valid]).all()
    assert answered >= 450  # generic poses are the common case (of 400 random, 100 snapped, 40 far)
    assert labelled >= 0.9 * answered
    assert as_array == (answered if plan.structure == "three_parallel" else 0)


@pytest.mark.parametrize("robot_id", ONE_POSE_ROBOTS)
def test_single_pose_answers_do_not_depend_on_the_path(robot_id, monkeypatch):
    """solve_ik with and without the scalar candidates: the same solutions with the same labels, residuals and
    singularities, for random, singular and unreachable poses; in the same order without a reference, and
    nearest first with one (two solutions at the same distance, e.g. sharing the joint that moves most, may
    swap: the paths' last bits differ)."""
    robot = _CATALOGUE.get(robot_id).robot
    poses = mixed_poses(robot, 200, seed=12)
    references = [None, random_configurations(robot, 1, seed=13)[0]]
    one_pose = [solve_ik(robot, T, reference=references[i % 2]) for i, T in enumerate(poses)]
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    monkeypatch.setattr(type(plan), "solve_one", lambda self, world_T_target, reference=None: None)
    for i, (T, fast) in enumerate(zip(poses, one_pose)):
        reference = references[i % 2]
        slow = solve_ik(robot, T, reference=reference)
        assert (fast.status, fast.structure, fast.singularities, fast.free_joints, fast.detail) == \
               (slow.status, slow.structure, slow.singularities, slow.free_joints, slow.detail)
        assert len(fast.solutions) == len(slow.solutions)
        slow_joints = np.array([s.joints for s in slow.solutions]).reshape(-1, robot.dof)
        for index, a in enumerate(fast.solutions):
            gaps = np.abs(joint_difference(robot, slow_joints, a.joints)).max(axis=1)
            b = slow.solutions[int(np.argmin(gaps))]
            assert gaps.min() <= 1e-9
            assert a.branch == b.branch
            assert abs(a.position_residual - b.position_residual) <= 1e-12 * robot.characteristic_length
            assert abs(a.orientation_residual - b.orientation_residual) <= 1e-12
            if reference is None:
                assert b is slow.solutions[index]
        if reference is not None and fast.solutions:
            def distances(result):
                return np.abs(joint_difference(robot, np.array([s.joints for s in result.solutions]),
                                               reference)).max(axis=1)
            np.testing.assert_allclose(distances(fast), distances(slow), rtol=0, atol=1e-12)


@pytest.mark.parametrize("robot_id", POSITION_ROBOTS)
def test_single_position_answers_do_not_depend_on_the_path(robot_id, monkeypatch):
    """Position targets (the joints past the third held at the reference, or 0) with and without the scalar path:
    the same statuses, promises, words and solutions with the same labels (in the same order without a
    reference), for random, singular and unreachable positions, and positions the held joints cannot reach
    (searched over every joint on both paths)."""
    robot = _CATALOGUE.get(robot_id).robot
    references = [None, random_configurations(robot, 1, seed=15)[0]]
    held = random_configurations(robot, 32, seed=16)  # positions the held joints reach, then mixed ones
    held[::2, 3:], held[1::2, 3:] = 0.0, references[1][3:]
    poses = np.concatenate([forward_kinematics(robot, held), mixed_poses(robot, 32, seed=14)])
    plan = _POSITION_PLANS[robot_id]
    assert sum(plan.solve_one(T) is not None for T in poses[:32:2]) >= 8
    fast = [solve_ik(robot, T, constrain_orientation=False, reference=references[i % 2])
            for i, T in enumerate(poses)]
    monkeypatch.setattr(type(plan), "solve_one", lambda self, world_T_target, reference=None: None)
    for i, (T, a) in enumerate(zip(poses, fast)):
        b = solve_ik(robot, T, constrain_orientation=False, reference=references[i % 2])
        assert (a.status, a.complete, a.singularities, a.free_joints, a.detail) == \
               (b.status, b.complete, b.singularities, b.free_joints, b.detail)
        assert len(a.solutions) == len(b.solutions)
        for index, solution in enumerate(a.solutions):
            gaps = np.abs(joint_difference(robot, np.array([s.joints for s in b.solutions]), solution.joints))
            match = int(np.argmin(gaps.max(axis=1)))
            # the joints are fixed to rounding over how well they steer the point (the xArm 7's point, 3.4e-6 off
            # axis 3 with the joints after it held, steers with σ_min ~1e-7: the paths' last bits differ by 1e-9)
            steering = geometric_jacobian(robot, solution.joints)[:3, :3] / robot.characteristic_length
            tolerance = max(1e-9, 1e-16 / max(np.linalg.svd(steering, compute_uv=False)[-1], 1e-10))
            assert gaps[match].max() <= tolerance and solution.branch == b.solutions[match].branch
            if references[i % 2] is None:
                assert match == index


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "kuka_kr6_r900_2", "spong_ex3_5_stanford"])
def test_a_few_targets_answer_as_each_alone_and_as_the_arrays(robot_id, monkeypatch):
    """Batches of up to FEW_TARGETS targets go through the scalar path one target at a time: each target's answer
    (status, solutions in order, labels, residuals, singularities, detail) is the one it gets alone, with the
    catalogue limits and with a reference; and the arrays' (the scalar path switched off) within 1e-9. A batch
    with a pose the scalar path declines (snapped to a singular configuration, or out of reach) takes the
    arrays as a whole, and answers the same."""
    robot = _CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    poses = mixed_poses(robot, 48, seed=31)
    sizes = [2, 3, 5, FEW_TARGETS, FEW_TARGETS + 1]
    batches, start = [], 0
    while start < len(poses):
        size = sizes[len(batches) % len(sizes)]
        batches.append(poses[start:start + size])
        start += size
    reference = random_configurations(robot, 1, seed=32)[0]
    scalar_answers = 0
    counted = type(plan).solve_one

    def counting(self, world_T_target, reference=None):
        nonlocal scalar_answers
        one_pose = counted(self, world_T_target, reference)
        scalar_answers += one_pose is not None
        return one_pose

    for options in (AnswerOptions(), AnswerOptions(reference=reference)):
        monkeypatch.setattr(type(plan), "solve_one", counting)
        few = [results_of(answer_ik(robot, IKTargets.poses(batch), options)) for batch in batches]
        monkeypatch.undo()
        alone = [[results_of(answer_ik(robot, IKTargets.poses(T[None]), options))[0] for T in batch]
                 for batch in batches]
        monkeypatch.setattr(type(plan), "solve_one", lambda self, world_T_target, reference=None: None)
        arrays = [results_of(answer_ik(robot, IKTargets.poses(batch), options)) for batch in batches]
        monkeypatch.undo()
        for few_results, alone_results, array_results in zip(few, alone, arrays):
            for result, single, array in zip(few_results, alone_results, array_results):
                _assert_same_answer(robot, result, single, ordered=options.reference is None)
                _assert_same_answer(robot, result, array, ordered=options.reference is None)
    # each pose of a batch of up to FEW_TARGETS answered on floats, but the few that the scalar path declines (and
    # their batches' other poses, which take the arrays with them)
    assert scalar_answers >= 0.7 * 2 * sum(len(batch) for batch in batches if len(batch) <= FEW_TARGETS)


def _assert_same_answer(robot, a, b, *, ordered: bool) -> None:
    """The same record, and each solution of ``a`` in ``b`` (in the same place when ``ordered``: nearest first may
    swap two at one distance, the paths' last bits differing) within 1e-9, with its labels and residuals."""
    assert _record(a) == _record(b)
    b_joints = _joints(robot, b)
    for index, solution in enumerate(a.solutions):
        gaps = np.abs(joint_difference(robot, b_joints, solution.joints)).max(axis=1)
        match = index if ordered else int(np.argmin(gaps))
        assert gaps[match] <= 1e-9
        other = b.solutions[match]
        assert solution.branch == other.branch
        assert abs(solution.position_residual - other.position_residual) <= 1e-12 * robot.characteristic_length
        assert abs(solution.orientation_residual - other.orientation_residual) <= 1e-12


def _record(result) -> tuple:
    return (result.status, result.structure, result.singularities, result.free_joints, result.detail,
            len(result.solutions))


def _joints(robot, result) -> np.ndarray:
    return np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)


@pytest.mark.parametrize("robot_id", ["puma560_standard", "spong_ex3_5_stanford"])
def test_the_scan_of_many_slots_is_the_pairwise_scan(robot_id, monkeypatch):
    """A target of many slots (the numeric search's starts) is scanned against the solutions kept so far; it must
    keep exactly the slots the pairwise scan of few slots keeps, near-duplicates and wrapped values included."""
    robot = _CATALOGUE.get(robot_id).robot
    rng = np.random.default_rng(5)
    for _ in range(100):
        q = random_configurations(robot, 40, seed=int(rng.integers(1 << 30)))[None]
        copies = rng.integers(0, 40, 20)
        q[0, copies[:10]] = q[0, copies[10:]] + rng.choice([0.0, 1e-7, 1e-5, 2 * np.pi], (10, 1)) * robot.is_revolute
        q[0, :, robot.is_revolute] = wrap_revolute(robot, q[0])[:, robot.is_revolute].T
        ok = rng.random((1, 40)) < 0.8
        scanned = _verify.first_of_each(robot, q, ok)
        monkeypatch.setattr(_verify, "_PAIRWISE_SLOTS", 64)
        pairwise = _verify.first_of_each(robot, np.repeat(q, 3, axis=0), np.repeat(ok, 3, axis=0))
        monkeypatch.undo()
        assert (scanned[0] == pairwise[0]).all() and (pairwise[1:] == pairwise[0]).all()


@pytest.mark.parametrize("robot_id", ["puma560_khalil", "spong_ex3_5_stanford"])
def test_the_scan_of_one_target_is_the_scan_of_many_on_random_slots(robot_id):
    """first_of_each_slot screens each pair by the last joint before the others: on random slots with copies
    moved within and beyond the tolerance, in the last joint or only in earlier ones, the last joint near the 2π
    wrap and some slots not ok, it keeps what first_of_each keeps."""
    robot = _CATALOGUE.get(robot_id).robot
    rng = np.random.default_rng(21)
    for _ in range(300):
        m = int(rng.integers(2, 10))
        joints = random_configurations(robot, m, seed=int(rng.integers(1 << 30)))
        if robot.is_revolute[-1]:
            joints[rng.random(m) < 0.4, -1] = np.pi - rng.choice([0.0, 1e-12, 1e-8], m)[:1]
        for row in range(1, m):
            if rng.random() < 0.6:
                joints[row] = joints[int(rng.integers(row))]
                joint = int(rng.integers(robot.dof))
                joints[row, joint] += rng.choice([0.0, 1e-12, 1e-7, 1e-3, -2 * np.pi * robot.is_revolute[joint]])
        joints = wrap_revolute(robot, joints)
        ok = (rng.random(m) < 0.85).tolist()
        # two targets: first_of_each screens them pairwise (one target it would hand to first_of_each_slot)
        expected = _verify.first_of_each(robot, np.repeat(joints[None], 2, axis=0), np.array([ok, ok]))
        assert _verify.first_of_each_slot(robot, joints.tolist(), ok) == expected[0].tolist()


def test_the_scan_of_one_target_is_the_scan_of_many():
    """first_of_each_slot (one target's slots, the one-pose path) keeps the slots first_of_each keeps for a batch
    (several targets, screened pairwise), whatever the values: duplicates beside rows that are not finite, whose
    gaps compare false, must still be dropped."""
    robot = _CATALOGUE.get("puma560_khalil").robot
    a = np.array([0.3, -1.2, 0.4, 2.0, -0.5, 1.0])
    cases = [np.array([a, a, np.full(6, np.nan), np.full(6, np.nan)]),
             np.array([a, np.full(6, np.inf), a + 1e-12, a + 2 * np.pi * robot.is_revolute]),
             np.array([a, a + 0.1, a + 0.2, a + 0.3])]
    for joints in cases:
        ok = [True] * len(joints)
        with np.errstate(invalid="ignore"):  # inf − inf
            expected = _verify.first_of_each(robot, np.repeat(joints[None], 2, axis=0),
                                             np.ones((2, len(joints)), bool))
            assert _verify.first_of_each_slot(robot, joints, ok) == expected[0].tolist() == expected[1].tolist()
    assert _verify.first_of_each_slot(robot, cases[0], [True] * 4) == [True, False, True, True]


def test_the_error_size_of_one_pair_of_floats_is_the_arrays():
    """error_size of one (position, orientation) pair of floats, as verify_one takes it, is its value on arrays
    (np.maximum's rule): NaN wherever either error is NaN, so that the one-pose path hands such a pose over."""
    robot = _CATALOGUE.get("puma560_standard").robot
    values = [0.0, 1e-12, 0.3, 2.0, np.inf, np.nan]
    for position in values:
        for orientation in values:
            for constrained in (True, False):
                on_floats = _verify.error_size(robot, float(position), float(orientation), constrained)
                on_arrays = _verify.error_size(robot, np.array([position]), np.array([orientation]), constrained)
                assert type(on_floats) is float
                assert on_floats == on_arrays[0] or (np.isnan(on_floats) and np.isnan(on_arrays[0]))


@pytest.mark.parametrize("robot_id", ["puma560_standard", "spong_ex3_2_cylindrical_rpp", "spong_ex3_5_stanford"])
def test_the_distances_of_a_few_rows_on_floats_are_the_arrays(robot_id):
    """linf_distances_of_rows (verify_one's nearest-first order) is distance_to_reference bit for bit: references
    within a turn, several turns away, and exactly half a turn from a row (where the wrap decides), on arms with
    and without slides."""
    robot = _CATALOGUE.get(robot_id).robot
    rng = np.random.default_rng(31)
    for case in range(300):
        rows = rng.uniform(-np.pi, np.pi, (int(rng.integers(1, 9)), robot.dof))
        reference = rng.choice([1.0, 4.0, 30.0]) * rng.uniform(-np.pi, np.pi, robot.dof)
        if case % 3 == 0:
            reference = rows[0] + rng.choice([-1.0, 1.0], robot.dof) * np.pi
        on_floats = _verify.linf_distances_of_rows(robot, rows.tolist(), reference.tolist())
        assert np.array(on_floats).tobytes() == _verify.distance_to_reference(robot, rows, reference).tobytes(), case


@pytest.mark.parametrize("robot_id", ONE_POSE_ROBOTS)
def test_the_float_check_of_one_pose_is_verify(robot_id):
    """verify_one (the FK check, the duplicate scan and the labels of one pose's scalar slots, on floats) gives
    the table, promise and nearest miss that verify gives for the same slots as candidates, bit for bit, with and
    without a reference; where a valid slot's label is unclear (verify is then not given the scalar slots), it
    gives the array path's rows and labels. The slots come wrapped, as verify would wrap them."""
    robot = _CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    exact, against_arrays = _float_check_against_verify(robot, plan, mixed_poses(robot, 200, seed=15),
                                                        [None, random_configurations(robot, 1, seed=14)[0]])
    assert exact >= 150


@pytest.mark.parametrize("convention", ["standard", "modified", "khalil"])
@pytest.mark.parametrize("family", ["intersecting_shoulder+spherical_wrist",
                                    "offset_shoulder_parallel_elbow+spherical_wrist", "three_parallel"])
def test_the_float_check_of_one_pose_is_verify_on_random_arms(family, convention):
    """The same on random arms of the three families with random base and tool frames (on the UR type most poses
    have a least-squares slot without a clear label, so most of its poses are compared with the array path)."""
    exact = compared = 0
    for seed in range(3):
        robot = random_family_arm(family, convention, seed)
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        poses = forward_kinematics(robot, np.random.default_rng(seed).uniform(-np.pi, np.pi, (40, 6)))
        counts = _float_check_against_verify(robot, plan, poses, [None, random_configurations(robot, 1, seed)[0]])
        exact, compared = exact + counts[0], compared + sum(counts)
    assert compared >= 0.75 * 3 * 40 and exact >= 10


def _float_check_against_verify(robot, plan, poses: np.ndarray, references: list) -> tuple[int, int]:
    """Assert verify_one against verify on each pose the scalar path answers (references taken in turn); returns
    how many were compared bit for bit and how many against the array path."""
    checked = against_arrays = 0
    for i, T in enumerate(poses):
        one_pose = plan.solve_one(T)
        if one_pose is None:
            continue
        valid = one_pose.valid[0]
        assert (wrap_revolute(robot, one_pose.joints[0, valid]) == one_pose.joints[0, valid]).all()
        goal, reference = PoseGoal(T[None]), references[i % len(references)]
        fast = _verify.verify_one(robot, goal, one_pose, reference)
        if fast is None:
            continue
        candidates = _one_pose_candidates(one_pose)
        if candidates is None:  # a slot the FK check rejects has no clear label: against the array path
            against_arrays += 1
            slow = _verify.verify(robot, goal, plan.solve(T[None], reference), reference, plan.label_codes)
            assert np.abs(joint_difference(robot, fast.table.joints, slow.table.joints)).max(initial=0) <= 1e-9
        else:
            checked += 1
            slow = _verify.verify(robot, goal, candidates, reference)
            np.testing.assert_array_equal(fast.table.joints, slow.table.joints)
            np.testing.assert_array_equal(fast.table.position, slow.table.position)
            np.testing.assert_array_equal(fast.table.orientation, slow.table.orientation)
            np.testing.assert_array_equal(fast.nearest, slow.nearest)
        np.testing.assert_array_equal(fast.table.target, slow.table.target)
        # contiguous columns, as the arrays form encodes them (orjson refuses strided arrays: a 500)
        assert all(column.flags.c_contiguous for column in (fast.table.joints, fast.table.position,
                                                            fast.table.orientation,
                                                            *(codes for _, codes in fast.table.labels.values())))
        np.testing.assert_array_equal(fast.table.within_limits, slow.table.within_limits)
        np.testing.assert_array_equal(fast.complete, slow.complete)
        assert list(fast.table.labels) == list(slow.table.labels)
        for name, (values, codes) in fast.table.labels.items():
            assert values == slow.table.labels[name][0]
            np.testing.assert_array_equal(codes, slow.table.labels[name][1])
    return checked, against_arrays


def test_the_two_wrist_roots_are_equally_near_the_wrists_singularity():
    """The scalar spherical wrist reads the volume |u cos q_b + w sin q_b| at its first root only: the last axis's
    two images mirror each other across the plane of the first two axes, so both roots are equally near aligned.
    On random wrists (perpendicular or not) and goals, subproblem 2's two roots give the same volume."""
    from service.kinematics.ik import _scalar as scalar

    rng = np.random.default_rng(41)
    compared = 0
    for _ in range(2000):
        a, b, c = (v / np.linalg.norm(v) for v in rng.normal(size=(3, 3)))
        if rng.random() < 0.5:  # the usual wrist: consecutive axes perpendicular
            b = np.cross(a, b) / np.linalg.norm(np.cross(a, b))
            c = np.cross(b, c) / np.linalg.norm(np.cross(b, c))
        goal = rng.normal(size=3)
        goal /= np.linalg.norm(goal)
        turns = scalar.TwoTurns(tuple(a), tuple(b))
        try:
            pairs = turns.angles(turns.start(tuple(c)), turns.goal(tuple(goal)))
        except scalar.NotGeneric:
            continue
        if pairs[1] is None:
            continue
        u, w = float(a @ np.cross(b, c)), float(a @ np.cross(b, np.cross(b, c)))
        first, second = (abs(u * np.cos(qb) + w * np.sin(qb)) for _, qb in pairs)
        assert first == pytest.approx(second, abs=1e-12)
        compared += 1
    assert compared > 500
