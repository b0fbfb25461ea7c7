"""Core forward kinematics: conventions, batch, frames, screws and the Jacobian."""

import numpy as np
import pytest

from service.kinematics import (
    InvalidInputError,
    Joint,
    Robot,
    check_joint_values,
    forward_kinematics,
    geometric_jacobian,
    joint_screws,
    link_frames,
    link_transforms,
    screw_model,
)
from tests.arms import random_dh_robot, screw_exponential
from tests.oracles.rotations import about, axis_angle


def _rot(axis: str, angle: float) -> np.ndarray:
    """The homogeneous rotation (4, 4) by ``angle`` about ``axis`` ("x", "y" or "z")."""
    T = np.eye(4)
    T[:3, :3] = about(axis, angle)
    return T


def _trans(axis: str, distance: float) -> np.ndarray:
    T = np.eye(4)
    T["xyz".index(axis), 3] = distance
    return T


@pytest.mark.parametrize("convention", ["standard", "modified", "khalil"])
def test_link_transform_is_the_product_of_elementary_motions(convention):
    rng = np.random.default_rng(0)
    for a, alpha, d, theta in rng.uniform(-3, 3, (50, 4)):
        if convention == "standard":
            expected = _rot("z", theta) @ _trans("z", d) @ _trans("x", a) @ _rot("x", alpha)
        else:  # Craig; a Khalil row arrives already renamed to Craig's columns
            expected = _rot("x", alpha) @ _trans("x", a) @ _rot("z", theta) @ _trans("z", d)
        np.testing.assert_allclose(link_transforms(convention, [a], [alpha], [d], [theta])[0], expected, atol=1e-14)


def test_link_transforms_reject_an_unknown_convention():
    with pytest.raises(ValueError, match="unknown convention"):
        link_transforms("paul", [0], [0], [0], [0])


def test_planar_rr_matches_spong_eq_3_25():
    """Spong Example 3.1: o = (a1 c1 + a2 c12, a1 s1 + a2 s12)."""
    arm = Robot([Joint("q1", "revolute", 1.0, 0, 0, 0), Joint("q2", "revolute", 0.5, 0, 0, 0)])
    q1, q2 = 0.5, -0.7
    T = forward_kinematics(arm, [q1, q2])
    np.testing.assert_allclose(T[:2, 3], [np.cos(q1) + 0.5 * np.cos(q1 + q2), np.sin(q1) + 0.5 * np.sin(q1 + q2)])
    np.testing.assert_allclose(T[:2, :2], [[np.cos(q1 + q2), -np.sin(q1 + q2)], [np.sin(q1 + q2), np.cos(q1 + q2)]])


def test_offsets_are_added_to_the_joint_variable():
    with_offset = Robot([Joint("q1", "revolute", 1.0, 0.3, 0.2, 0.4), Joint("q2", "prismatic", 0.1, 0, 0.5, 0)])
    without = Robot([Joint("q1", "revolute", 1.0, 0.3, 0.2, 0.0), Joint("q2", "prismatic", 0.1, 0, 0.0, 0)])
    np.testing.assert_allclose(forward_kinematics(with_offset, [0.1, 0.2]), forward_kinematics(without, [0.5, 0.7]))


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_batch_equals_single_calls_and_base_and_tool_apply(convention):
    rng = np.random.default_rng(1)
    base = _rot("z", 0.3) @ _trans("x", 0.5) @ _rot("x", 1.1)
    tool = _trans("z", 0.2) @ _rot("y", -0.4)
    plain = random_dh_robot(rng, convention, "RRPRRR")
    robot = Robot(plain.joints, convention=convention, world_T_base=base, flange_T_tool=tool)
    q = rng.uniform(-np.pi, np.pi, (20, 6))
    batch = forward_kinematics(robot, q)
    assert batch.shape == (20, 4, 4)
    for row, T in zip(q, batch):
        np.testing.assert_allclose(T, forward_kinematics(robot, row), atol=1e-14)
        np.testing.assert_allclose(T, base @ forward_kinematics(plain, row) @ tool, atol=1e-12)


def test_link_frames_start_at_the_base_and_end_at_the_flange():
    rng = np.random.default_rng(2)
    robot = Robot(random_dh_robot(rng, "standard", "RPR").joints, flange_T_tool=_trans("z", 0.3))
    q = rng.uniform(-1, 1, 3)
    frames = link_frames(robot, q)
    assert frames.shape == (4, 4, 4)
    np.testing.assert_allclose(frames[0], np.eye(4))
    np.testing.assert_allclose(frames[-1] @ _trans("z", 0.3), forward_kinematics(robot, q), atol=1e-14)


@pytest.mark.parametrize("convention", ["standard", "modified", "khalil"])
def test_every_link_frame_is_the_product_of_the_elementary_motions_before_it(convention):
    """link_frames runs the chain program; each frame is checked against the rows' elementary motions multiplied
    out here, in batches of several shapes, with a base and prismatic joints."""
    rng = np.random.default_rng(7)
    plain = random_dh_robot(rng, convention, "RPRRPR")
    base = _rot("z", 0.4) @ _trans("x", 0.2) @ _rot("x", -0.3)
    robot = Robot(plain.joints, convention=convention, world_T_base=base)
    q = rng.uniform(-2, 2, (3, 5, 6))
    frames = link_frames(robot, q)
    assert frames.shape == (3, 5, 7, 4, 4)
    for index in np.ndindex(3, 5):
        expected = base
        np.testing.assert_allclose(frames[index][0], base, atol=1e-15)
        for i in range(6):
            theta = robot.theta[i] + (q[index][i] if robot.is_revolute[i] else 0.0)
            d = robot.d[i] + (0.0 if robot.is_revolute[i] else q[index][i])
            if convention == "standard":
                step = _rot("z", theta) @ _trans("z", d) @ _trans("x", robot.a[i]) @ _rot("x", robot.alpha[i])
            else:
                step = _rot("x", robot.alpha[i]) @ _trans("x", robot.a[i]) @ _rot("z", theta) @ _trans("z", d)
            expected = expected @ step
            np.testing.assert_allclose(frames[index][i + 1], expected, atol=1e-13)


@pytest.mark.parametrize("convention,kinds", [("standard", "RRPRRR"), ("modified", "PRRRPR"), ("khalil", "RRRRRR")])
def test_product_of_exponentials_reproduces_dh_forward_kinematics(convention, kinds):
    rng = np.random.default_rng(3)
    plain = random_dh_robot(rng, convention, kinds)
    robot = Robot(plain.joints, convention=convention, world_T_base=_rot("y", 0.7) @ _trans("z", 1.0),
                  flange_T_tool=_trans("x", 0.25))
    model = screw_model(robot)
    np.testing.assert_allclose(np.linalg.norm(model.directions, axis=1), 1.0)
    for q in rng.uniform(-np.pi, np.pi, (30, robot.dof)):
        T = np.eye(4)
        for direction, point, revolute, value in zip(model.directions, model.points, model.is_revolute, q):
            T = T @ screw_exponential(direction, point, revolute, value)
        np.testing.assert_allclose(T @ model.home, forward_kinematics(robot, q), atol=1e-12)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_jacobian_matches_finite_differences_of_fk(convention):
    rng = np.random.default_rng(4)
    robot = Robot(random_dh_robot(rng, convention, "RRPRRP").joints, convention=convention,
                  world_T_base=_rot("x", 0.4), flange_T_tool=_trans("y", 0.3))
    step = 1e-6
    for q in rng.uniform(-np.pi, np.pi, (10, robot.dof)):
        J = geometric_jacobian(robot, q)
        T = forward_kinematics(robot, q)
        for i in range(robot.dof):
            dq = np.zeros(robot.dof)
            dq[i] = step
            T_plus, T_minus = forward_kinematics(robot, q + dq), forward_kinematics(robot, q - dq)
            linear = (T_plus[:3, 3] - T_minus[:3, 3]) / (2 * step)
            dR = (T_plus[:3, :3] - T_minus[:3, :3]) / (2 * step) @ T[:3, :3].T  # = [ω]×
            angular = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
            np.testing.assert_allclose(J[:3, i], linear, atol=1e-8)
            np.testing.assert_allclose(J[3:, i], angular, atol=1e-8)
    batch = geometric_jacobian(robot, rng.uniform(-1, 1, (5, robot.dof)))
    assert batch.shape == (5, 6, robot.dof)


def test_joint_screws_follow_the_convention_axis():
    """Standard DH: joint 1 turns about z0 of the base; Craig: about z1, which coincides with z0 at alpha_0 = 0."""
    spong = Robot([Joint("q1", "revolute", 0, np.pi / 2, 0.5, 0), Joint("q2", "revolute", 1, 0, 0, 0)])
    directions, points, _ = joint_screws(spong, np.array([0.3, 0.2]))
    np.testing.assert_allclose(directions[0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(directions[1], [np.sin(0.3), -np.cos(0.3), 0], atol=1e-15)  # z1 = (s1, -c1, 0)
    np.testing.assert_allclose(points[1], [0, 0, 0.5], atol=1e-15)


def test_robot_validation_names_the_joint():
    with pytest.raises(InvalidInputError, match="lower limit 2 is greater than upper limit 1") as error:
        Robot([Joint("q1", "revolute", 0, 0, 0, 0), Joint("q2", "revolute", 0, 0, 0, 0, 2.0, 1.0)])
    assert error.value.location == ("joints", 1, "limits")
    with pytest.raises(InvalidInputError, match="at least one joint"):
        Robot([])
    with pytest.raises(InvalidInputError, match="finite") as error:
        Robot([Joint("q1", "revolute", float("nan"), 0, 0, 0)])
    assert error.value.location == ("joints", 0, "a")


def test_joint_values_are_checked_for_shape_and_finiteness():
    robot = Robot([Joint("q1", "revolute", 1, 0, 0, 0), Joint("q2", "prismatic", 0, 0, 0, 0)])
    with pytest.raises(InvalidInputError, match=r"shape \(2,\).*got shape \(3,\)"):
        check_joint_values(robot, [1, 2, 3])
    with pytest.raises(InvalidInputError, match="finite") as error:
        check_joint_values(robot, [[0, 1], [np.inf, 0]], batch=True)
    assert error.value.location == (1, 0)


def test_ragged_batch_rows_are_named():
    robot = Robot([Joint("q1", "revolute", 1, 0, 0, 0), Joint("q2", "prismatic", 0, 0, 0, 0)])
    with pytest.raises(InvalidInputError, match="row 1 has 3") as error:
        check_joint_values(robot, [[0, 1], [1, 2, 3]], batch=True)
    assert error.value.location == (1,)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_scalar_residuals_of_a_few_candidates_equal_the_array_ones(convention, monkeypatch):
    """One pose's candidates are verified by the scalar FK; it must give the array path's residuals."""
    from service.kinematics.ik import _goals, _verify

    rng = np.random.default_rng(3)
    tool = _trans("z", 0.2) @ _rot("y", -0.4)
    robot = Robot(random_dh_robot(rng, convention, "RRPRRR").joints, convention=convention,
                  world_T_base=_rot("z", 0.3) @ _trans("x", 0.5), flange_T_tool=tool)
    q = rng.uniform(-np.pi, np.pi, (2, 8, 6))
    targets = forward_kinematics(robot, q[:, 0] + rng.normal(0, 1e-3, (2, 6)))
    scalar = _verify.residual_arrays(robot, q, targets)
    monkeypatch.setattr(_goals, "SCALAR_CANDIDATES", 0)
    arrays = _verify.residual_arrays(robot, q, targets)
    for a, b in zip(scalar, arrays):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-13)


@pytest.mark.parametrize("shapes", [((3,), (3,)), ((3,), (5, 3)), ((5, 3), (3,)), ((4, 2, 3), (4, 1, 3)),
                                    ((2, 1, 3), (3,))])
def test_the_core_cross_product_is_numpys_bit_for_bit(shapes):
    """_forward.cross (two 3-vectors multiplied as floats, arrays without np.cross's axis bookkeeping) gives
    np.cross's values to the last bit, in every broadcast the core uses, on random values of many magnitudes."""
    from service.kinematics._forward import cross

    rng = np.random.default_rng(11)
    for _ in range(200):
        a, b = (rng.normal(size=shape) * 10.0 ** rng.integers(-12, 6, size=shape) for shape in shapes)
        ours, numpys = cross(a, b), np.cross(a, b)
        assert ours.shape == numpys.shape and ours.dtype == numpys.dtype
        np.testing.assert_array_equal(ours, numpys)


def _scalar_chain_arms() -> list:
    """Arms of every operation the chain program has: three conventions of random DH rows with revolute and
    prismatic joints, offsets (θ, d) zero or not, quarter and general twists, a base and a tool; the same arms
    as screws (fixed motions between joints)."""
    from tests.arms import stated_three_ways

    rng = np.random.default_rng(29)
    arms = []
    for kinds in ("RRRRRR", "RRPRRR", "PRRPRR", "RPR"):
        table = [(float(rng.uniform(-1, 1)) if rng.random() < 0.7 else 0.0,
                  float(rng.choice([np.pi / 2, -np.pi / 2, 0.0, rng.uniform(-3, 3)])),
                  float(rng.uniform(-1, 1)) if rng.random() < 0.6 else 0.0,
                  float(rng.uniform(-1, 1)) if rng.random() < 0.5 else 0.0) for _ in kinds]
        arms += stated_three_ways(rng, table, kinds)
    return arms + [_as_screws(arm) for arm in arms[:6]]


def _as_screws(robot: Robot) -> Robot:
    """The same arm from its joint screws at q = 0 (fixed motions between the joints)."""
    from service.kinematics import ScrewJoint
    from service.kinematics._forward import joint_screws

    screws = joint_screws(robot, np.zeros(robot.dof))
    joints = [ScrewJoint(f"s{i}", "revolute" if revolute else "prismatic", tuple(axis), tuple(point))
              for i, (revolute, axis, point) in enumerate(zip(robot.is_revolute, screws.directions, screws.points))]
    return Robot.from_screws(joints, screws.world_T_tool)


def test_the_scalar_chain_is_the_array_chain_bit_for_bit(client):
    """tool_columns_scalar_rows runs the chain program as straight-line float code compiled per program shape;
    on every kind of operation it must give tool_columns's values to the last bit, for rows that share their
    first joints with the row before them (resumed from a kept frame), equal rows and rows that share none: on
    random arms, every catalogue arm and CAD-rounded ones."""
    from service.kinematics._forward import tool_columns, tool_columns_scalar_rows
    from tests.arms import rounded

    rng = np.random.default_rng(31)
    catalogue = [entry.robot for entry in client.app.state.catalogue.entries()]
    for arm in _scalar_chain_arms() + catalogue + [rounded(arm, seed=3) for arm in catalogue[:8]]:
        q = rng.uniform(-3, 3, (7, arm.dof))
        q[1, :2] = q[0, :2]
        q[3] = q[2]
        q[4, :-1] = q[3, :-1]
        q[6, :1] = q[5, :1]
        x, y, z, p = tool_columns(arm, q)
        scalar = np.array(tool_columns_scalar_rows(arm, q.tolist()))  # (7, 4 columns, 3)
        assert np.array_equal(scalar, np.stack([x, y, z, p]).transpose(2, 0, 1)), arm.convention


def test_forward_kinematics_of_a_few_rows_is_the_array_chains_bit_for_bit(monkeypatch):
    """Up to SCALAR_ROWS joint vectors take the scalar chain: the same matrices to the last bit as the array chain
    (SCALAR_ROWS 0), in every batch shape; a row with an infinite value (which math.cos refuses) takes the array
    chain and gives NaN there, as every row did before, and its neighbours their own poses."""
    from service.kinematics import _forward
    from tests.arms import rounded

    rng = np.random.default_rng(37)
    arms = _scalar_chain_arms()[:8]
    arms += [rounded(arm, seed=5) for arm in arms[:3]]
    for arm in arms:
        for shape in [(arm.dof,), (1, arm.dof), (5, arm.dof), (2, 3, arm.dof), (_forward.SCALAR_ROWS, arm.dof)]:
            q = rng.uniform(-3, 3, shape)
            few = forward_kinematics(arm, q)
            with monkeypatch.context() as patch:
                patch.setattr(_forward, "SCALAR_ROWS", 0)
                arrays = forward_kinematics(arm, q)
            assert few.shape == shape[:-1] + (4, 4)
            np.testing.assert_array_equal(few, arrays)
    q = rng.uniform(-3, 3, (3, arms[0].dof))
    q[1, 0] = np.inf
    with np.errstate(invalid="ignore"):
        poses = forward_kinematics(arms[0], q)
    assert np.isnan(poses[1, :3]).any() and np.isfinite(poses[[0, 2]]).all()
    np.testing.assert_array_equal(poses[2], forward_kinematics(arms[0], q[2]))


def test_the_jacobian_of_a_few_rows_is_the_array_jacobian(monkeypatch):
    """Up to SCALAR_ROWS joint vectors, the Jacobian's columns come from the scalar chain's frames (each joint's
    axis and a point on it, just before its motion): the array path's (the link matrices' products, SCALAR_ROWS 0)
    to rounding, on arms of every operation (revolute and prismatic joints, three conventions, screws), rounded
    ones, in every batch shape; a row with an infinite value takes the array path."""
    from service.kinematics import _forward
    from tests.arms import rounded

    rng = np.random.default_rng(43)
    arms = _scalar_chain_arms()
    arms += [rounded(arm, seed=7) for arm in arms[:3]]
    for arm in arms:
        scale = max(1.0, float(np.abs(np.concatenate([arm.a, arm.d])).max()) if arm.convention != "screws" else 1.0)
        for shape in [(arm.dof,), (1, arm.dof), (4, arm.dof), (2, 3, arm.dof)]:
            q = rng.uniform(-3, 3, shape)
            few = geometric_jacobian(arm, q)
            with monkeypatch.context() as patch:
                patch.setattr(_forward, "SCALAR_ROWS", 0)
                arrays = geometric_jacobian(arm, q)
            assert few.shape == arrays.shape == shape[:-1] + (6, arm.dof)
            np.testing.assert_allclose(few, arrays, rtol=0, atol=1e-13 * scale)
    q = rng.uniform(-3, 3, (2, arms[0].dof))
    q[0, -1] = np.inf
    with np.errstate(invalid="ignore"):
        J = geometric_jacobian(arms[0], q)
    assert np.isfinite(J[1]).all() and not np.isfinite(J[0]).all()


def test_the_pose_error_is_half_the_sum_of_the_columns_cross_products():
    """pose_error's rotation rows, ½ Σ_i r_i × r*_i over the columns of the current and target rotations, against
    np.cross on the columns (to the last bit: the core's cross is np.cross's), and sin(angle)·axis for a small
    turn about a known axis; its position rows the difference over the length scale."""
    from service.kinematics.ik._goals import pose_error

    rng = np.random.default_rng(41)
    current, target = rng.normal(size=(2, 7, 4, 4))
    error = pose_error(current, target, 0.5)
    expected = 0.5 * np.sum(np.cross(current[:, :3, :3], target[:, :3, :3], axis=-2), axis=-1)
    np.testing.assert_array_equal(error[:, 3:], expected)
    np.testing.assert_array_equal(error[:, :3], (target[:, :3, 3] - current[:, :3, 3]) / 0.5)
    axis = np.array([2.0, -1.0, 0.5]) / np.linalg.norm([2.0, -1.0, 0.5])
    start = np.eye(4)
    start[:3, :3] = axis_angle(np.array([0.6, 0.0, 0.8]), 0.7)
    turned = start.copy()
    turned[:3, :3] = axis_angle(axis, 1e-3) @ start[:3, :3]
    np.testing.assert_allclose(pose_error(start, turned, 1.0)[3:], np.sin(1e-3) * axis, rtol=0, atol=1e-9)


def test_radius_about_is_the_distance_from_the_axis():
    """radius_about(axis, v): the distance of v from the line along the unit vector axis, against the
    projection v − (v·axis) axis, on single vectors and broadcast batches; for a unit v, the sine of the angle."""
    from service.kinematics._forward import radius_about

    rng = np.random.default_rng(17)
    for _ in range(50):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        v = rng.normal(size=(4, 5, 3)) * 10.0 ** rng.uniform(-6, 3)
        expected = np.linalg.norm(v - (v @ axis)[..., None] * axis, axis=-1)
        np.testing.assert_allclose(radius_about(axis, v), expected, rtol=1e-12, atol=1e-15 * np.abs(v).max())
        assert radius_about(axis, v[0, 0]).shape == ()
    angle = 0.3
    assert np.isclose(radius_about(np.array([0.0, 0.0, 1.0]), np.array([np.sin(angle), 0.0, np.cos(angle)])),
                      np.sin(angle))


def test_a_nan_joint_gives_the_same_residuals_on_floats_and_on_arrays(monkeypatch):
    """A candidate whose last joint is NaN keeps a finite position on an arm whose last joint moves no point, and a
    NaN orientation error on both paths (a clamped arcsine must not turn it into π, a miss the check would trust):
    verify_one then leaves the candidate to the array path, as before the chord formula."""
    from service.kinematics.ik import _goals, _verify

    robot = Robot([Joint("q1", "revolute", 0.4, 0.3, 0.2, 0.0), Joint("q2", "revolute", 0.0, 0.0, 0.0, 0.0)])
    q = np.array([[[0.3, np.nan], [0.3, 0.2]]])
    targets = forward_kinematics(robot, np.array([[0.3, 0.1]]))
    scalar = _verify.residual_arrays(robot, q, targets)
    monkeypatch.setattr(_goals, "SCALAR_CANDIDATES", 0)
    arrays = _verify.residual_arrays(robot, q, targets)
    for a, b in zip(scalar, arrays):
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
        np.testing.assert_allclose(a[~np.isnan(a)], b[~np.isnan(b)], rtol=0, atol=1e-14)
    assert np.isnan(scalar[1][0, 0]) and np.isfinite(scalar[0][0, 0])


@pytest.mark.parametrize("rows", [1, 8, 255, 256, 257, 2000])
def test_cross_is_numpys_cross_at_every_size(rows):
    """The core's cross product (its component slices for many vectors, gathered components for a few, floats for
    two 3-vectors) gives np.cross's values at every size and broadcast, bit for bit."""
    from service.kinematics._forward import cross

    rng = np.random.default_rng(rows)
    a, b = rng.normal(size=(rows, 3)), rng.normal(size=(rows, 3))
    assert cross(a, b).tobytes() == np.cross(a, b).tobytes()
    assert cross(a[0], b).tobytes() == np.cross(a[0], b).tobytes()  # one vector against many
    assert cross(a[:, None], b[None, :2]).tobytes() == np.cross(a[:, None], b[None, :2]).tobytes()  # broadcast
    assert cross(a[0], b[0]).tobytes() == np.cross(a[0], b[0]).tobytes()
