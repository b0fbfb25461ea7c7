"""Arms the tests build: redundant and deficient arms from published parameters, the catalogue arms' classes and
the vendors' source URDFs, seeded random arms of each IK family (with a random base and tool), and arms stated the
way CAD exports and vendors state them (rounded DH values, rounded base and tool quaternions, the exact DH table of
an arm given by its screws, whatever offsets that takes)."""

from __future__ import annotations

import json
from importlib.metadata import distribution
from pathlib import Path

import numpy as np
import pytest
from pydantic import TypeAdapter

from service.kinematics import Joint, Robot, ScrewJoint
from service.robots import robot_from_description
from service.robots.schemas import RobotDescription
from tests.oracles.rotations import axis_angle, matrix_of_quaternion, rpy

#: redundant and deficient arms from published parameters: name → inline description (DH table, limits)
PUBLISHED_ARMS = json.loads((Path(__file__).parent / "data" / "redundant_and_deficient_arms.json").read_text())

#: catalogue robot id → (target kind, generic number of solutions, solver structure): the catalogue arms with a
#: finite generic solution set (tests/api/test_ik_recall.py holds each to its count)
GENERIC_CATALOGUE_ARMS = {
    "spong_ex3_1_planar_rr": ("position", 2, "planar_two_link"),
    "spong_ex3_2_cylindrical_rpp": ("position", 2, "one_revolute_two_prismatic"),
    "spong_ex3_3_spherical_wrist_rrr": ("pose", 2, "spherical_wrist"),
    "spong_ex3_4_cylindrical_with_wrist": ("pose", 4, "one_revolute_two_prismatic+spherical_wrist"),
    "spong_ex3_5_stanford": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "spong_ex3_6_scara_rrpr": ("pose", 2, "parallel_shoulder+roll"),
    "spong_ex4_3_elbow_with_wrist": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "spong_sec4_3_spherical_arm_rrp": ("position", 4, "intersecting_shoulder"),
    "spong_sec4_3_spherical_arm_table3_4_frames": ("position", 4, "intersecting_shoulder"),
    "ex004_1_prp": ("position", 2, "one_revolute_two_prismatic"),
    "ex004_2_polar_rrp": ("position", 4, "intersecting_shoulder"),
    "ex004_3_spherical_rrpr": ("pose", 2, "intersecting_shoulder+roll"),
    "ex004_4_polar_offset_rrp": ("position", 4, "intersecting_shoulder"),
    "assur001_scara_rrp": ("position", 2, "parallel_shoulder"),
    "puma560_modified": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "puma560_khalil": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "puma560_standard": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "ur5": ("pose", 8, "three_parallel"),  # up to 8: see test_ik_recall's test_ur5_counts_are_the_real_solution_counts
    "ur3e": ("pose", 8, "three_parallel"),
    "ur5e": ("pose", 8, "three_parallel"),
    "ur10e": ("pose", 8, "three_parallel"),
    "ur16e": ("pose", 8, "three_parallel"),
    # industrial arms with a spherical wrist (OPW arms and the Lite 6)
    "kuka_kr6_r900_2": ("pose", 8, "offset_shoulder_parallel_elbow+spherical_wrist"),
    "kuka_kr210_r2700": ("pose", 8, "offset_shoulder_parallel_elbow+spherical_wrist"),
    "fanuc_lrmate200id": ("pose", 8, "offset_shoulder_parallel_elbow+spherical_wrist"),
    "abb_irb6700": ("pose", 8, "offset_shoulder_parallel_elbow+spherical_wrist"),
    "abb_irb120": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "ufactory_lite6": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    # URDF arms: the plan is read off their joint screws, as for DH tables
    "kinova_jaco2": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "unitree_z1": ("pose", 8, "three_parallel"),
}

#: a 6R arm with skew axes (no two axes parallel or intersecting): no closed form, the general 6R solver. Its
#: standard DH rows (a, alpha, d: each (6,), rad and m, theta offsets 0), and its inline description
SKEW_6R_DH = dict(a=np.array([0.1, 0.5, 0.2, 0.05, 0.1, 0.03]), alpha=np.array([0.5, -0.9, 1.1, 0.7, -1.3, 0.4]),
                  d=np.array([0.2, 0.1, -0.15, 0.3, 0.05, 0.1]))
SKEW_6R_ROBOT = {"convention": "standard", "angle_unit": "rad",
                 "joints": [{"a": float(a), "alpha": float(al), "d": float(d)}
                            for a, al, d in zip(SKEW_6R_DH["a"], SKEW_6R_DH["alpha"], SKEW_6R_DH["d"])]}

#: Four skew revolute joints and two slides: no closed-form family or general solver covers it, so the numeric
#: search answers (every 6R arm, and every 6-joint arm with one slide, is solved by the general solver, and a 7R
#: one by locking a joint). Modified DH, radians and metres, no limits.
NUMERIC_ARM = {"convention": "modified", "joints": [
    {"type": kind, "a": a, "alpha": alpha, "d": d}
    for kind, a, alpha, d in zip(["revolute"] * 4 + ["prismatic"] * 2, [0.05, 0.3, 0.07, 0.25, 0.04, 0.06],
                                 [0.5, -0.9, 1.1, 0.7, -1.3, 0.4], [0.2, 0.1, -0.15, 0.3, 0.05, 0.1])]}
#: a skew 7R arm (standard DH, radians and metres): a redundant arm whose locked 6R arms go to the general solver
SKEW_7R = {"convention": "standard", "joints": [
    {"type": "revolute", "a": 0.1 * i, "alpha": 0.3 + 0.2 * i, "d": 0.05 * (i % 3)} for i in range(7)]}

_EXAMPLE_ROBOT_DATA = "cmeel.prefix/share/example-robot-data/robots/"

#: catalogue URDF arm id -> (distribution of the test extra, path of the vendor's source URDF inside it)
URDF_SOURCES = {
    "franka_panda": ("example-robot-data", _EXAMPLE_ROBOT_DATA + "panda_description/urdf/panda.urdf"),
    "kinova_jaco2": ("example-robot-data", _EXAMPLE_ROBOT_DATA + "kinova_description/robots/kinova.urdf"),
    "ufactory_xarm7": ("example-robot-data", _EXAMPLE_ROBOT_DATA + "xarm_description/urdf/xarm7.urdf"),
    "unitree_z1": ("example-robot-data", _EXAMPLE_ROBOT_DATA + "z1_description/urdf/z1.urdf"),
    "so101": ("example-robot-data", _EXAMPLE_ROBOT_DATA + "so_arm_description/urdf/so101.urdf"),
    "kuka_iiwa14": ("pybullet", "pybullet_data/kuka_iiwa/model.urdf"),
}


def source_urdf(robot_id: str) -> str:
    """The text of a :data:`URDF_SOURCES` arm's source URDF, as its vendor wrote it."""
    name, path = URDF_SOURCES[robot_id]
    try:
        file = Path(distribution(name).locate_file(path))
    except Exception:  # noqa: BLE001 - a missing distribution
        pytest.fail(f"{name} is not installed: it is in the test extra (pip install -e '.[test]')")
    return file.read_text(encoding="utf-8")


#: three-parallel case → (structure, 0-based standard-DH twists set to 0 or π (axes i+1 ∥ i+2), link lengths a_i
#: set to 0 (axes i+1 and i+2 intersect), the middle parallel joint)
THREE_PARALLEL_CASES = {
    "skew_wrist_234": ("three_parallel_skew_wrist", (1, 2), (), 2),
    "skew_shoulder_345": ("three_parallel_skew_shoulder", (2, 3), (), 3),
    "intersecting_shoulder_345": ("three_parallel_intersecting_shoulder", (2, 3), (0,), 3),
    "at_end_456": ("three_parallel_at_end", (3, 4), (), 4),
    "at_end_456_with_1_2_intersecting": ("three_parallel_at_end", (3, 4), (0,), 4),
    "at_base_123": ("three_parallel_at_base", (0, 1), (), 1),
    "at_base_123_with_5_6_intersecting": ("three_parallel_at_base", (0, 1), (4,), 1),  # EAIK's 3 ∥ + 2 ∩
}


def published_arm(name: str) -> Robot:
    """A :data:`PUBLISHED_ARMS` arm, built from its inline description as the service builds one."""
    description = TypeAdapter(RobotDescription).validate_python({"id": name.replace("_", "-"), **PUBLISHED_ARMS[name]})
    return robot_from_description(description, max_joints=16)


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A random rotation matrix (3, 3): the orthogonal factor of a Gaussian matrix, turned proper."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def random_rigid(rng: np.random.Generator, scale: float) -> np.ndarray:
    """A random rigid transform (4, 4): :func:`random_rotation`, then a translation uniform in ±``scale``."""
    T = np.eye(4)
    T[:3, :3] = random_rotation(rng)
    T[:3, 3] = rng.uniform(-scale, scale, 3)
    return T


def restated_6r(a: np.ndarray, alpha: np.ndarray, d: np.ndarray, theta: np.ndarray, convention: str,
                world_T_base: np.ndarray, flange_T_tool: np.ndarray, kinds: str = "RRRRRR") -> Robot:
    """The 6-joint arm of standard-DH rows (a, alpha, d, theta: each shape (6,)) with the given base and tool,
    restated in ``convention``: Craig's rows shift a_i and alpha_i down one joint, the last pair going into the
    tool; a Khalil row holds the same numbers as a Craig row, renamed. The same arm (the same FK) in every
    convention. ``kinds``: R (revolute) or P (prismatic) per joint; a prismatic joint's d is its offset."""
    tool = flange_T_tool
    if convention == "standard":
        rows = zip(a, alpha, d, theta)
    else:
        rows = zip(np.r_[0.0, a[:5]], np.r_[0.0, alpha[:5]], d, theta)
        c, s = np.cos(alpha[5]), np.sin(alpha[5])
        tool = np.array([[1, 0, 0, a[5]], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]]) @ tool
    joints = [Joint(f"j{i + 1}", "revolute" if kind == "R" else "prismatic", *row)
              for i, (kind, row) in enumerate(zip(kinds, rows))]
    return Robot(joints, convention=convention, world_T_base=world_T_base, flange_T_tool=tool)


class RandomDHRows:
    """Random standard-DH row entries drawn from one generator, in the order they are asked for: link lengths
    uniform in 0.1–0.5, twists of size 0.3–2.8 rad and either sign, joint offsets uniform in ±π."""

    def __init__(self, rng: np.random.Generator):
        self.rng = rng

    def length(self) -> float:
        return float(self.rng.uniform(0.1, 0.5))

    def twist(self) -> float:
        return float(self.rng.uniform(0.3, 2.8) * self.rng.choice([-1, 1]))

    def offset(self) -> float:
        return float(self.rng.uniform(-np.pi, np.pi))

    def free(self) -> tuple[float, float, float, float]:
        """A row (a, alpha, d, theta offset) with no special relation to its neighbours."""
        return (self.length(), self.twist(), self.length(), self.offset())

    def spherical_wrists(self) -> tuple[list[tuple], list[tuple]]:
        """A spherical wrist's rows after a positioner (three rows: axes 4, 5, 6 meet) and a wrist's rows at the
        base (two rows: axes 1, 2, 3 meet), drawn in that order. Wrist twists of equal size, as in every real
        wrist (±90°): only then can the outer axes align."""
        t = self.twist()
        wrist = [(0.0, t, self.length(), self.offset()), (0.0, t * self.rng.choice([-1, 1]), 0.0, self.offset()),
                 self.free()]
        t = self.twist()
        base_wrist = [(0.0, t, self.length(), self.offset()), (0.0, t * self.rng.choice([-1, 1]), 0.0, self.offset())]
        return wrist, base_wrist


def stated_three_ways(rng: np.random.Generator, table: list[tuple[float, float, float, float]], kinds: str,
                      limits: tuple[float, float] | None = None) -> list[Robot]:
    """One arm in the standard, modified and Khalil conventions (same base, tool, FK): standard DH rows ``table``
    (a, alpha, d, theta offset) of joints ``kinds`` ("R" or "P" each), some axes reversed at random (each with
    probability 0.4), with a random base (translation in ±0.5) and tool (in ±0.2) drawn from ``rng``.
    ``limits``: (lower, upper) of every prismatic joint; by default none."""
    n = len(kinds)
    rows = [list(row) for row in table]
    base = random_rigid(rng, 0.5)
    for joint in np.flatnonzero(rng.random(n) < 0.4):
        base = _reverse_axis(rows, int(joint), base)
    tool = random_rigid(rng, 0.2)
    joint_kind = {"R": "revolute", "P": "prismatic"}
    bounds = [limits if (k == "P" and limits) else (-np.inf, np.inf) for k in kinds]
    standard = Robot([Joint(f"j{i + 1}", joint_kind[k], *row, *bound)
                      for i, (row, k, bound) in enumerate(zip(rows, kinds, bounds))],
                     convention="standard", world_T_base=base, flange_T_tool=tool)
    # Craig: row i holds (a_{i−1}, alpha_{i−1}, d_i, theta_i); the last (a_n, alpha_n) moves into the tool
    craig = [(0.0 if i == 0 else rows[i - 1][0], 0.0 if i == 0 else rows[i - 1][1], rows[i][2], rows[i][3])
             for i in range(n)]
    last = np.eye(4)
    a, alpha = rows[-1][0], rows[-1][1]
    last[:3, :3] = [[1, 0, 0], [0, np.cos(alpha), -np.sin(alpha)], [0, np.sin(alpha), np.cos(alpha)]]
    last[0, 3] = a
    modified_joints = [Joint(f"j{i + 1}", joint_kind[k], *row, *bound)
                       for i, (row, k, bound) in enumerate(zip(craig, kinds, bounds))]
    modified = Robot(modified_joints, convention="modified", world_T_base=base, flange_T_tool=last @ tool)
    khalil = Robot(modified_joints, convention="khalil", world_T_base=base, flange_T_tool=last @ tool)
    return [standard, modified, khalil]


def _reverse_axis(rows: list[list[float]], joint: int, base: np.ndarray) -> np.ndarray:
    """Flip joint ``joint``'s axis (standard DH, in place): frame joint−1 turns by π about its x axis.

    Row ``joint − 1`` (or the base) gains π of twist; row ``joint`` measures θ and d along the flipped z
    and loses π of twist. The arm is the same; its joint variable changes sign.
    """
    if joint == 0:
        base = base @ np.diag([1.0, -1.0, -1.0, 1.0])
    else:
        rows[joint - 1][1] += np.pi
    a, alpha, d, theta = rows[joint]
    rows[joint] = [a, alpha - np.pi, -d, -theta]
    return base


def random_dh_robot(rng: np.random.Generator, convention: str, kinds: str) -> Robot:
    """A random arm of joints ``kinds`` ("R" revolute or "P" prismatic each), every DH entry (a, alpha, d, theta)
    uniform in ±1, in the given convention, with no base or tool."""
    joints = [Joint(f"q{i + 1}", "revolute" if k == "R" else "prismatic", *rng.uniform(-1, 1, 4))
              for i, k in enumerate(kinds)]
    return Robot(joints, convention=convention)


def random_general_arm(rng: np.random.Generator, convention: str) -> Robot:
    """A random 6R arm with no decomposable geometry (DH entries uniform in ±1, in the given convention) with a
    random base (translation in ±1) and tool (translation in ±0.3)."""
    joints = random_dh_robot(rng, convention, "RRRRRR").joints
    base, tool = random_rigid(rng, 1.0), random_rigid(rng, 0.3)
    return Robot(joints, convention=convention, world_T_base=base, flange_T_tool=tool)


def kinova_j2n6s300() -> Robot:
    """Kinova Jaco 2 6-DOF with its curved 60° wrist: Kinova's published standard DH table (no axes meet at
    the wrist, so no closed-form family)."""
    D1, D2, D3, D4, D5, D6, e2 = 0.2755, 0.41, 0.2073, 0.0741, 0.0741, 0.16, 0.0098
    aa = np.pi / 6
    ratio = np.sin(aa) / np.sin(2 * aa)
    alpha = [np.pi / 2, np.pi, np.pi / 2, 2 * aa, 2 * aa, np.pi]
    a = [0.0, D2, 0.0, 0.0, 0.0, 0.0]
    d = [D1, 0.0, -e2, -(D3 + ratio * D4), -(ratio * D4 + ratio * D5), -(ratio * D5 + D6)]
    return Robot([Joint(f"q{i + 1}", "revolute", a[i], alpha[i], d[i], 0.0) for i in range(6)], name="j2n6s300")


def random_three_parallel_arm(case: str, convention: str, seed: int) -> Robot:
    """A random arm of a :data:`THREE_PARALLEL_CASES` class, with anti-parallel axes among the parallel ones, in
    standard DH restated in ``convention``, with a random base and tool."""
    _, parallel, intersecting, _ = THREE_PARALLEL_CASES[case]
    rng = np.random.default_rng(seed)
    alpha = rng.choice([-1, 1], 6) * rng.uniform(0.3, 2.8, 6)
    a, d, theta = rng.uniform(-0.4, 0.4, 6), rng.uniform(-0.4, 0.4, 6), rng.uniform(-np.pi, np.pi, 6)
    alpha[list(parallel)] = rng.choice([0.0, np.pi], len(parallel))  # π: anti-parallel, a reversed axis
    a[list(intersecting)] = 0.0
    base, tool = random_rigid(rng, 0.3), random_rigid(rng, 0.3)
    return restated_6r(a, alpha, d, theta, convention, base, tool)


def random_family_arm(family: str, convention: str, seed: int, wrist_singular: bool = False) -> Robot:
    """A random arm of one of the scalar path's families, ``"intersecting_shoulder+spherical_wrist"``,
    ``"offset_shoulder_parallel_elbow+spherical_wrist"`` (axes 2 ∥ 3, a spherical wrist) or ``"three_parallel"``
    (axes 2 ∥ 3 ∥ 4, axes 5 and 6 meeting), in standard DH restated in ``convention``, with
    a random base and tool. ``wrist_singular`` (three-parallel family): the twists of axes 4–5 and 5–6 equal in
    size, so that axis 6 can lie along the parallel axes, as on the UR arms (the same random draws otherwise)."""
    rng = np.random.default_rng(seed)
    a, d, theta = rng.uniform(0.1, 0.5, 6) * rng.choice([-1, 1], 6), rng.uniform(-0.4, 0.4, 6), \
        rng.uniform(-np.pi, np.pi, 6)
    alpha = rng.uniform(0.3, 2.8, 6) * rng.choice([-1, 1], 6)
    if family == "intersecting_shoulder+spherical_wrist":
        a[0] = 0.0  # axes 1 and 2 meet
        a[3] = a[4] = d[4] = 0.0  # axes 4, 5 and 6 meet
        alpha[4] = abs(alpha[3]) * rng.choice([-1, 1])  # equal wrist twists, as in every real wrist
    elif family == "offset_shoulder_parallel_elbow+spherical_wrist":
        alpha[1] = rng.choice([0.0, np.pi])  # axes 2 ∥ 3, axis 1 offset from axis 2 by a[0] (the OPW arms)
        a[3] = a[4] = d[4] = 0.0
        alpha[4] = abs(alpha[3]) * rng.choice([-1, 1])
    else:
        alpha[1] = rng.choice([0.0, np.pi])  # axes 2 ∥ 3 ∥ 4 (π: a reversed axis)
        alpha[2] = rng.choice([0.0, np.pi])
        a[4] = 0.0  # axes 5 and 6 meet
        if wrist_singular:
            alpha[4] = abs(alpha[3]) * np.sign(alpha[4])
    base, tool = random_rigid(rng, 0.5), random_rigid(rng, 0.2)
    return restated_6r(a, alpha, d, theta, convention, base, tool)


def random_stanford_type_arm(convention: str, seed: int) -> Robot:
    """A random arm of the Stanford type: axes 1 and 2 meeting at a random angle, a slide normal to axis 2 whose
    line crosses it at a random height (the shoulder offset), a spherical wrist centred on the slide's line
    (random twists, equal in size), in standard DH restated in ``convention``, with a random base and tool."""
    rng = np.random.default_rng(seed)
    a, d, theta = np.zeros(6), rng.uniform(-0.4, 0.4, 6), rng.uniform(-np.pi, np.pi, 6)
    alpha = rng.uniform(0.3, 2.8, 6) * rng.choice([-1, 1], 6)
    alpha[1] = rng.choice([-1, 1]) * np.pi / 2  # the slide (axis 3) normal to axis 2, its line crossing it (a2 = 0)
    d[3] = d[4] = 0.0  # axes 4, 5 and 6 meet on the slide's line
    alpha[4] = abs(alpha[3]) * rng.choice([-1, 1])
    a[5] = rng.uniform(-0.2, 0.2)
    base, tool = random_rigid(rng, 0.5), random_rigid(rng, 0.2)
    return restated_6r(a, alpha, d, theta, convention, base, tool, kinds="RRPRRR")


def random_ur_type_arm(seed: int, convention: str, two_arcs: bool, skew: bool = False) -> Robot:
    """A random UR-type arm (standard DH rows a, alpha, d, theta, restated in ``convention``) whose axis 6 lies
    along axes 2–4 at q5 = 0 exactly (the twists of rows 4 and 5 cancel, or add to π: anti-parallel), with a
    random base and tool. ``two_arcs``: the offset between axes 4 and 6 (d5) longer than the shorter planar link,
    so that the reachable q6 can form two arcs; else shorter than half of it (the UR5's proportions: one arc).
    ``skew``: axes 5 and 6 skew (a5 ≠ 0, the three_parallel_skew_wrist family)."""
    rng = np.random.default_rng(seed)
    upper, fore = rng.uniform(0.3, 0.5) * rng.choice([-1, 1]), rng.uniform(0.1, 0.25) * rng.choice([-1, 1])
    wrist = rng.uniform(0.3, 0.45) if two_arcs else rng.uniform(0.02, 0.5 * abs(fore))
    a = np.array([0.0, upper, fore, 0.0, 0.0, 0.0])
    if skew:
        a[4] = rng.uniform(0.03, 0.12) * rng.choice([-1, 1])
    d = np.r_[rng.uniform(0.05, 0.2), rng.uniform(-0.1, 0.1, 2), rng.uniform(0.05, 0.2), wrist * rng.choice([-1, 1]),
              rng.uniform(0.05, 0.2)]
    twist = rng.uniform(0.3, 2.8) * rng.choice([-1, 1])
    alpha = np.array([rng.uniform(0.3, 2.8) * rng.choice([-1, 1]), rng.choice([0.0, np.pi]), rng.choice([0.0, np.pi]),
                      twist, rng.choice([-twist, np.pi - twist]), rng.uniform(-2.8, 2.8)])
    theta = rng.uniform(-np.pi, np.pi, 6)
    theta[4] = 0.0  # the singular wrist at q5 = 0
    base, tool = random_rigid(rng, 0.5), random_rigid(rng, 0.2)
    return restated_6r(a, alpha, d, theta, convention, base, tool)


def moved(robot: Robot, rng: np.random.Generator, sigma: float) -> Robot:
    """A DH arm with each of its parameters (a, alpha, d, theta) moved by N(0, sigma): metres and radians."""
    return Robot([Joint(j.name, j.kind, j.a + rng.normal(0, sigma), j.alpha + rng.normal(0, sigma),
                        j.d + rng.normal(0, sigma), j.theta + rng.normal(0, sigma)) for j in robot.joints],
                 name="moved", convention=robot.convention, world_T_base=robot.world_T_base,
                 flange_T_tool=robot.flange_T_tool)


def rounded(robot: Robot, seed: int, *, base_and_tool: bool = True) -> Robot:
    """``robot`` as a CAD export writes it: angles in radians to 4 decimals (π/2 → 1.5708), parallel axes
    (α = 0 or π) 1e-5 rad off, lengths to 0.1 mm (the robot's unit taken as metres), and, with
    ``base_and_tool``, a random base and tool whose quaternions are written to 6 decimals (0.707107) and
    translations to 0.1 mm. A robot given by its screws is rounded as a URDF export writes it: see
    :func:`_rounded_screws`."""
    rng = np.random.default_rng(seed)
    if robot.convention == "screws":
        return _rounded_screws(robot, rng, base_and_tool)
    joints = []
    for joint in robot.joints:
        alpha = round(joint.alpha, 4)
        if abs(np.sin(alpha)) < 1e-3:
            alpha += rng.choice([-1.0, 1.0]) * 1e-5
        joints.append(Joint(joint.name, joint.kind, round(joint.a, 4), alpha, round(joint.d, 4),
                            round(joint.theta, 4)))
    transforms = {}
    if base_and_tool:
        for key in ("world_T_base", "flange_T_tool"):
            transforms[key] = _rounded_transform(rng)
    return Robot(joints, convention=robot.convention, **transforms)


def _rounded_screws(robot: Robot, rng: np.random.Generator, base_and_tool: bool) -> Robot:
    """A screw robot as a URDF/CAD export writes it: axis components to 6 decimals (then normalised, as a reader
    does), an axis parallel to the one before (within 1e-3 rad after rounding: the DH path's α = 0 or π) tilted 1e-5 rad
    off it, points on
    the axes and the home translation to 0.1 mm, the home rotation through a quaternion written to 6 decimals."""
    joints, axes = [], []
    for joint in robot.joints:
        axis = np.round(np.asarray(joint.axis, dtype=float), 6)
        axis /= np.linalg.norm(axis)
        if axes and np.linalg.norm(np.cross(axis, axes[-1])) < 1e-3:
            axis = _tilted(axis, 1e-5, rng)
        axes.append(axis)
        joints.append(ScrewJoint(joint.name, joint.kind, tuple(axis), tuple(np.round(joint.point, 4)),
                                 joint.lower, joint.upper))
    home = np.linalg.multi_dot(list(robot.chain_transforms))  # F_0 · F_1 ⋯ F_n = base_T_flange
    transforms = {}
    if base_and_tool:
        for key in ("world_T_base", "flange_T_tool"):
            transforms[key] = _rounded_transform(rng)
    return Robot.from_screws(joints, _rounded_transform(rng, home), name=robot.name, **transforms)


def _tilted(axis: np.ndarray, angle: float, rng: np.random.Generator) -> np.ndarray:
    """``axis`` turned by ``angle`` towards a random perpendicular direction."""
    normal = np.cross(axis, rng.normal(size=3))
    normal /= np.linalg.norm(normal)
    return np.cos(angle) * axis + np.sin(angle) * normal


def _rounded_transform(rng: np.random.Generator, transform: np.ndarray | None = None) -> np.ndarray:
    """``transform`` (random when None) with its quaternion written to 6 decimals, its translation to 0.1 mm."""
    if transform is None:
        quaternion, translation = rng.normal(size=4) / 2, rng.uniform(-0.2, 0.2, 3)
    else:
        quaternion, translation = _quaternion(transform[:3, :3]), transform[:3, 3]
    w, x, y, z = quaternion = np.round(quaternion, 6)
    w, x, y, z = quaternion / np.linalg.norm(quaternion)  # a reader normalises the written quaternion
    T = np.eye(4)
    T[:3, :3] = matrix_of_quaternion(w, x, y, z)
    T[:3, 3] = np.round(translation, 4)
    return T


def _quaternion(R: np.ndarray) -> np.ndarray:
    """(w, x, y, z) of a rotation matrix (Shepperd: from the largest of the four squared components)."""
    squares = 0.25 * np.array([1 + R[0, 0] + R[1, 1] + R[2, 2], 1 + R[0, 0] - R[1, 1] - R[2, 2],
                               1 - R[0, 0] + R[1, 1] - R[2, 2], 1 - R[0, 0] - R[1, 1] + R[2, 2]])
    k = int(np.argmax(squares))
    q = np.empty(4)
    q[k] = np.sqrt(squares[k])
    cross = {(0, 1): R[2, 1] - R[1, 2], (0, 2): R[0, 2] - R[2, 0], (0, 3): R[1, 0] - R[0, 1],
             (1, 2): R[0, 1] + R[1, 0], (1, 3): R[0, 2] + R[2, 0], (2, 3): R[1, 2] + R[2, 1]}
    for j in range(4):
        if j != k:
            q[j] = cross[(min(j, k), max(j, k))] / (4 * q[k])
    return q


def standard_dh_from_screws(directions: np.ndarray, points: np.ndarray, home: np.ndarray) -> Robot:
    """The exact standard-DH robot (all revolute) whose joint i turns about the line (points[i], directions[i]) and
    whose tool is at ``home`` at q = 0 (world frame). Frame 0 is put on axis 1 by ``world_T_base``; frame i's
    origin is the foot on axis i+1 of its common normal with axis i, wherever that is (kilometres away for
    nearly parallel axes: the table then carries the huge compensating offsets a CAD converter would write)."""
    n = len(directions)
    z = directions[0] / np.linalg.norm(directions[0])
    x = _perpendicular(z)
    frame = np.eye(4)
    frame[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    frame[:3, 3] = points[0]
    world_T_base = frame.copy()
    joints = []
    for i in range(n):
        origin, x_prev, z_prev = frame[:3, 3], frame[:3, 0], frame[:3, 2]
        if i + 1 < n:
            k, p = directions[i + 1] / np.linalg.norm(directions[i + 1]), points[i + 1]
        else:
            k, p = z_prev, origin
        normal = np.cross(z_prev, k)
        sine = np.linalg.norm(normal)
        if sine > 1e-15:
            # the common normal: along n = z_prev × k, of signed length (p − origin)·n̂ (well conditioned); its
            # foot on axis i at origin + s z_prev, s = ((p − origin) × k)·n / |n|²
            unit = normal / sine
            s = float(np.cross(p - origin, k) @ normal) / sine ** 2
            foot_prev = origin + s * z_prev
            length = float((p - origin) @ unit)
            x_new = unit if length >= 0 else -unit
            gap = abs(length) * x_new
        else:
            foot_prev = origin
            gap = p + k * ((origin - p) @ k) - origin
            x_new = gap / np.linalg.norm(gap) if np.linalg.norm(gap) > 1e-12 else x_prev
        foot = foot_prev + gap
        theta = np.arctan2(np.cross(x_prev, x_new) @ z_prev, x_prev @ x_new)
        alpha = np.arctan2(np.cross(z_prev, k) @ x_new, z_prev @ k)
        joints.append(Joint(f"q{i + 1}", "revolute", float(gap @ x_new), float(alpha),
                            float((foot_prev - origin) @ z_prev), float(theta)))
        frame = np.eye(4)
        frame[:3, :3] = np.column_stack([x_new, np.cross(k, x_new), k])
        frame[:3, 3] = foot
    flange_T_tool = np.linalg.inv(frame) @ home
    return Robot(joints, convention="standard", world_T_base=world_T_base, flange_T_tool=flange_T_tool)


def _perpendicular(k: np.ndarray) -> np.ndarray:
    trial = np.eye(3)[np.argmin(np.abs(k))]
    u = np.cross(k, trial)
    return u / np.linalg.norm(u)


def urdf_chain_screws(joints: list[dict]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint axes (n, 3), points on them (n, 3) and the tool pose at q = 0 (4, 4) of a URDF chain of revolute
    joints with ``<axis xyz="0 0 1">``, each given by its ``<origin>`` (``xyz``, ``rpy``: fixed-axis roll, pitch,
    yaw, R = Rz(y) Ry(p) Rx(r)); the tool is the last joint's frame."""
    frame = np.eye(4)
    directions, points = [], []
    for joint in joints:
        r, p, y = joint["rpy"]
        origin = np.eye(4)
        origin[:3, :3] = rpy(r, p, y)
        origin[:3, 3] = joint["xyz"]
        frame = frame @ origin
        directions.append(frame[:3, 2].copy())
        points.append(frame[:3, 3].copy())
    return np.array(directions), np.array(points), frame


def screw_exponential(direction, point, revolute, q):
    """exp([S] q) for a unit screw, written independently of the core (Rodrigues)."""
    T = np.eye(4)
    if revolute:
        R = axis_angle(direction, q)
        T[:3, :3] = R
        T[:3, 3] = (np.eye(3) - R) @ point
    else:
        T[:3, 3] = direction * q
    return T
