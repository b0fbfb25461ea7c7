"""Self-checks of the robot catalogue (robots/*.yaml) and the golden test data.

These tests use their own small Denavit-Hartenberg product (``world_T_tool``
below), deliberately independent of the service core, and compare it with the
textbook's closed forms (``tests/oracles/closed_forms.py``) and with the printed
test vectors of textbook.md §8 (``tests/data/textbook_fk_vectors.json``).

Units: robot files give angles in degrees and lengths in metres (mm for the
Assur SCARA); joint vectors in the JSON data are radians and lengths.
"""

from __future__ import annotations

import importlib.util
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.oracles.closed_forms import CLOSED_FORMS, ORACLE_PARAMETERS

REPO_ROOT = Path(__file__).resolve().parents[1]
ROBOTS_DIR = REPO_ROOT / "robots"
DATA_DIR = Path(__file__).resolve().parent / "data"

ROBOT_ID_PATTERN = re.compile(r"[a-z0-9][a-z0-9_-]{0,63}")

EXPECTED_ROBOT_IDS = {
    "spong_ex3_1_planar_rr",
    "spong_ex3_2_cylindrical_rpp",
    "spong_ex3_3_spherical_wrist_rrr",
    "spong_ex3_4_cylindrical_with_wrist",
    "spong_ex3_5_stanford",
    "spong_ex3_6_scara_rrpr",
    "spong_ex4_3_elbow_with_wrist",
    "spong_sec4_3_elbow_shoulder_offset_with_wrist",
    "spong_sec4_3_spherical_arm_rrp",
    "spong_sec4_3_spherical_arm_table3_4_frames",
    "ex004_1_prp",
    "ex004_2_polar_rrp",
    "ex004_3_spherical_rrpr",
    "ex004_4_polar_offset_rrp",
    "assur001_scara_rrp",
    "puma560_modified",
    "puma560_khalil",
    "puma560_standard",
    "ur5",
    "ur3e",
    "ur5e",
    "ur10e",
    "ur16e",
    # industrial arms held to their sources in tests/robots/test_industrial_arms.py
    "kuka_kr6_r900_2",
    "kuka_kr210_r2700",
    "abb_irb120",
    "ufactory_xarm6",
    "ufactory_lite6",
    "fanuc_lrmate200id",
    "abb_irb6700",
    # a 7-joint arm from its vendor's DH table (tests/robots/test_industrial_arms.py)
    "kinova_gen3",
}

REQUIRED_KEYS = (
    "id", "name", "source", "convention", "angle_unit", "length_unit",
    "parameters", "limits_source", "joints", "base", "tool",
)
OPTIONAL_KEYS = ("notes", "licence", "collision", "collision_source")

#: The shape kinds a catalogue link-geometry entry may carry (../shared/api.md, Collisions).
SHAPE_KINDS = {"capsule", "sphere", "box"}

#: Keys of one joint mapping per convention, in the required order (``d`` last:
#: openapi-python-client binds the parsed dict to a local named ``d``).
JOINT_KEYS = {
    "standard": ("name", "type", "a", "alpha", "theta", "limits", "d"),
    "modified": ("name", "type", "a", "alpha", "theta", "limits", "d"),
    "khalil": ("name", "type", "alpha", "theta", "r", "limits", "d"),
}

#: How many random joint vectors each randomized check uses.
N_RANDOM = 50
#: Agreement required between two exact computations of the same pose.
EXACT_ATOL = 1e-9


# ---------------------------------------------------------------------------
# Loading
# ---------------------------------------------------------------------------


def robot_files() -> list[Path]:
    """Every DH robot file, sorted by name (the URDF sidecars ``*.urdf.yaml`` are checked in tests/robots/)."""
    return sorted(p for p in ROBOTS_DIR.glob("*.yaml") if not p.name.endswith(".urdf.yaml"))


def load_robot(robot_id: str) -> dict:
    """The parsed description robots/<robot_id>.yaml."""
    with open(ROBOTS_DIR / f"{robot_id}.yaml", encoding="utf-8") as stream:
        return yaml.safe_load(stream)


def load_json(name: str):
    """A JSON file from tests/data."""
    with open(DATA_DIR / name, encoding="utf-8") as stream:
        return json.load(stream)


# ---------------------------------------------------------------------------
# Independent DH product (test helper; not the service core)
# ---------------------------------------------------------------------------


def standard_link_T(a: float, alpha: float, d: float, theta: float) -> np.ndarray:
    """^{i-1}T_i in standard DH: Rot_z(theta) Trans_z(d) Trans_x(a) Rot_x(alpha).

    Angles in rad, lengths in the robot's unit. Returns shape (4, 4).
    """
    ct, st = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array([
        [ct, -st * ca, st * sa, a * ct],
        [st, ct * ca, -ct * sa, a * st],
        [0.0, sa, ca, d],
        [0.0, 0.0, 0.0, 1.0],
    ])


def modified_link_T(a_prev: float, alpha_prev: float, d: float, theta: float) -> np.ndarray:
    """^{i-1}T_i in Craig's modified DH: Rot_x(alpha_{i-1}) Trans_x(a_{i-1}) Rot_z(theta_i) Trans_z(d_i).

    Angles in rad, lengths in the robot's unit. Returns shape (4, 4).
    """
    ct, st = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha_prev), math.sin(alpha_prev)
    return np.array([
        [ct, -st, 0.0, a_prev],
        [st * ca, ct * ca, -sa, -sa * d],
        [st * sa, ct * sa, ca, ca * d],
        [0.0, 0.0, 0.0, 1.0],
    ])


def khalil_link_T(alpha: float, d: float, theta: float, r: float) -> np.ndarray:
    """^{j-1}T_j in Khalil-Kleinfinger: Rot_x(alpha_j) Trans_x(d_j) Rot_z(theta_j) Trans_z(r_j).

    d_j is along x_{j-1}, r_j along z_j. Angles in rad. Returns shape (4, 4).
    """
    ct, st = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array([
        [ct, -st, 0.0, d],
        [ca * st, ca * ct, -sa, -r * sa],
        [sa * st, sa * ct, ca, r * ca],
        [0.0, 0.0, 0.0, 1.0],
    ])


def _to_rad(robot: dict, angle: float) -> float:
    """An angle from a robot file, converted from its angle_unit to rad."""
    units = {"deg": math.pi / 180.0, "rad": 1.0}
    return float(angle) * units[robot["angle_unit"]]


def world_T_tool(robot: dict, q) -> np.ndarray:
    """Pose of the tool in the world: world_T_base @ A_1(q_1) ... A_n(q_n) @ flange_T_tool.

    ``robot`` is a parsed robot file; ``q`` has shape (n,), rad for revolute
    joints and the robot's length unit for prismatic ones. The table value of
    each joint's variable (theta, or d / r) is an offset added to q_i; a null
    base or tool is the identity. Returns shape (4, 4).
    """
    q = np.asarray(q, dtype=float)
    joints = robot["joints"]
    assert q.shape == (len(joints),)
    T = np.eye(4) if robot["base"] is None else np.array(robot["base"], dtype=float)
    for joint, qi in zip(joints, q):
        revolute = joint["type"] == "revolute"
        theta = _to_rad(robot, joint["theta"]) + (qi if revolute else 0.0)
        alpha = _to_rad(robot, joint["alpha"])
        if robot["convention"] == "khalil":
            r = joint["r"] + (0.0 if revolute else qi)
            T = T @ khalil_link_T(alpha, joint["d"], theta, r)
        else:
            d = joint["d"] + (0.0 if revolute else qi)
            link_T = standard_link_T if robot["convention"] == "standard" else modified_link_T
            T = T @ link_T(joint["a"], alpha, d, theta)
    if robot["tool"] is not None:
        T = T @ np.array(robot["tool"], dtype=float)
    return T


def random_joint_vectors(robot: dict, rng: np.random.Generator, n: int = N_RANDOM) -> np.ndarray:
    """n random joint vectors, shape (n, dof): revolute in [-2pi, 2pi] rad,
    prismatic in [-1.5, 1.5] m (x100 for a robot in mm)."""
    scale = 100.0 if robot["length_unit"] == "mm" else 1.0
    columns = [
        rng.uniform(-2 * math.pi, 2 * math.pi, n) if j["type"] == "revolute"
        else rng.uniform(-1.5, 1.5, n) * scale
        for j in robot["joints"]
    ]
    return np.column_stack(columns)


def printed_value_tolerance(robot: dict, printed: np.ndarray) -> np.ndarray:
    """Tolerance for values printed with 6 significant digits (textbook.md §8).

    5e-6 absolute for robots in metres; 5e-6 * max(1, |value|) for robots in mm.
    """
    printed = np.asarray(printed, dtype=float)
    if robot["length_unit"] == "mm":
        return 5e-6 * np.maximum(1.0, np.abs(printed))
    return np.full_like(printed, 5e-6)


def rot_z(angle_rad: float) -> np.ndarray:
    """Homogeneous rotation about z, shape (4, 4)."""
    return standard_link_T(0.0, 0.0, 0.0, angle_rad)


# ---------------------------------------------------------------------------
# 1. The files themselves
# ---------------------------------------------------------------------------


def test_catalogue_has_every_robot_of_the_brief():
    assert {path.stem for path in robot_files()} == EXPECTED_ROBOT_IDS


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check_transform(name: str, value) -> None:
    if value is None:
        return
    matrix = np.array(value, dtype=float)
    assert matrix.shape == (4, 4), f"{name} must be 4x4"
    np.testing.assert_allclose(matrix[3], [0, 0, 0, 1], atol=0)
    rotation = matrix[:3, :3]
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-12)
    assert np.linalg.det(rotation) > 0


@pytest.mark.parametrize("path", robot_files(), ids=lambda p: p.stem)
def test_robot_file_is_well_formed(path: Path):
    with open(path, encoding="utf-8") as stream:
        robot = yaml.safe_load(stream)

    assert isinstance(robot, dict)
    missing = [key for key in REQUIRED_KEYS if key not in robot]
    assert not missing, f"missing keys {missing}"
    unknown = set(robot) - set(REQUIRED_KEYS) - set(OPTIONAL_KEYS)
    assert not unknown, f"unknown keys {sorted(unknown)}"

    assert robot["id"] == path.stem
    assert ROBOT_ID_PATTERN.fullmatch(robot["id"])
    for key in ("name", "source", "limits_source"):
        assert isinstance(robot[key], str) and robot[key].strip()
    assert isinstance(robot.get("notes", ""), str)
    _check_collision(robot)
    assert robot["convention"] in JOINT_KEYS
    assert robot["angle_unit"] == "deg"
    assert robot["length_unit"] in ("m", "mm")
    assert isinstance(robot["parameters"], dict)
    assert all(_is_number(v) for v in robot["parameters"].values())
    _check_transform("base", robot["base"])
    _check_transform("tool", robot["tool"])

    joints = robot["joints"]
    assert isinstance(joints, list) and joints
    names = [joint["name"] for joint in joints]
    assert len(set(names)) == len(names), "joint names must be unique"
    for joint in joints:
        assert tuple(joint) == JOINT_KEYS[robot["convention"]], joint
        assert list(joint)[-1] == "d"
        assert joint["type"] in ("revolute", "prismatic")
        for key in JOINT_KEYS[robot["convention"]][2:]:
            if key != "limits":
                assert _is_number(joint[key]), f"{joint['name']}.{key}"
        limits = joint["limits"]
        if limits is None:
            continue
        assert set(limits) == {"lower", "upper"}
        lower, upper = limits["lower"], limits["upper"]
        assert lower is None or _is_number(lower)
        assert upper is None or _is_number(upper)
        assert lower is not None or upper is not None, "use limits: null instead"
        if lower is not None and upper is not None:
            assert lower < upper
        if joint["type"] == "revolute":
            assert lower is not None and upper is not None, "revolute limits are two-sided"
        elif lower is not None:
            assert lower >= 0, "no prismatic joint in this catalogue extends negatively"


def _check_collision(robot: dict) -> None:
    """A link-geometry list comes with its source, and each entry is one known shape on a link of the arm."""
    if "collision" not in robot:
        assert "collision_source" not in robot, "a collision_source without a collision list"
        return
    assert isinstance(robot.get("collision_source"), str) and robot["collision_source"].strip(), (
        "every capsule model names its source"
    )
    shapes = robot["collision"]
    assert isinstance(shapes, list) and shapes
    for shape in shapes:
        assert 0 <= shape["link"] <= len(robot["joints"]), shape
        kinds = set(shape) - {"link", "name"}
        assert len(kinds) == 1 and kinds <= SHAPE_KINDS, shape


#: (robot id, joint index) of the slides whose negative extension the textbook discards.
SLIDES_WITH_ZERO_LOWER_LIMIT = [
    ("spong_ex3_2_cylindrical_rpp", 2),
    ("spong_ex3_4_cylindrical_with_wrist", 2),
    ("spong_sec4_3_spherical_arm_rrp", 2),
    ("spong_sec4_3_spherical_arm_table3_4_frames", 2),
    ("ex004_1_prp", 2),
    ("ex004_2_polar_rrp", 2),
    ("ex004_3_spherical_rrpr", 2),
    ("ex004_4_polar_offset_rrp", 2),
]

#: Robots whose sources give no limits: only the slides above may be limited.
TEXTBOOK_ONLY_ROBOTS = EXPECTED_ROBOT_IDS - {
    "spong_ex3_5_stanford", "puma560_modified", "puma560_khalil", "puma560_standard", "ur5",
    "ur3e", "ur5e", "ur10e", "ur16e",
    "kuka_kr6_r900_2", "kuka_kr210_r2700", "abb_irb120", "ufactory_xarm6", "ufactory_lite6",
    "fanuc_lrmate200id", "abb_irb6700", "kinova_gen3",
}


def test_limits_follow_the_textbook_where_it_gives_none():
    zero_lower = set(SLIDES_WITH_ZERO_LOWER_LIMIT)
    for robot_id in sorted(TEXTBOOK_ONLY_ROBOTS):
        for index, joint in enumerate(load_robot(robot_id)["joints"]):
            if (robot_id, index) in zero_lower:
                assert joint["type"] == "prismatic"
                assert joint["limits"] == {"lower": 0, "upper": None}, (robot_id, index)
            else:
                assert joint["limits"] is None, (robot_id, joint["name"])


def test_published_limits():
    """The manufacturer / model limits, in each file's own frames (deg, m)."""
    def limits(robot_id):
        return [
            None if j["limits"] is None else (j["limits"]["lower"], j["limits"]["upper"])
            for j in load_robot(robot_id)["joints"]
        ]

    corke_puma = [(-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266)]
    assert limits("puma560_standard") == corke_puma
    assert limits("ur5") == [(-360, 360)] * 6
    for robot_id in ("ur5e", "ur10e", "ur16e"):
        assert limits(robot_id) == [(-360, 360)] * 6
    assert limits("ur3e") == [(-360, 360)] * 5 + [None]  # wrist 3: infinite rotation
    stanford = limits("spong_ex3_5_stanford")
    assert stanford[2][0] >= 0, "the Stanford slide d3 cannot be negative"
    assert stanford == [(-170, 170), (-170, 170), (0.3048, 1.27), (-260, 80), (-90, 90), (-170, 170)]


# ---------------------------------------------------------------------------
# 2. DH product versus the textbook's closed forms and printed vectors
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id", sorted(CLOSED_FORMS))
def test_oracle_uses_the_file_parameters(robot_id: str):
    assert load_robot(robot_id)["parameters"] == ORACLE_PARAMETERS[robot_id]


@pytest.mark.parametrize("robot_id", sorted(CLOSED_FORMS))
def test_dh_product_matches_closed_form(robot_id: str):
    robot = load_robot(robot_id)
    closed_form = CLOSED_FORMS[robot_id]
    rng = np.random.default_rng(0)
    for q in random_joint_vectors(robot, rng):
        np.testing.assert_allclose(
            world_T_tool(robot, q), closed_form(q), rtol=0, atol=EXACT_ATOL,
            err_msg=f"{robot_id} at q = {q.tolist()}",
        )


def test_fk_vectors_cover_every_closed_form_robot():
    vectors = load_json("textbook_fk_vectors.json")
    assert set(vectors) == set(CLOSED_FORMS)
    for robot_id, entries in vectors.items():
        assert len(entries) == 3
        dof = len(load_robot(robot_id)["joints"])
        for entry in entries:
            assert set(entry) == {"joints", "matrix"}
            assert len(entry["joints"]) == dof
            assert np.array(entry["matrix"]).shape == (4, 4)


def _fk_vector_cases():
    vectors = load_json("textbook_fk_vectors.json")
    return [
        pytest.param(robot_id, i, entry, id=f"{robot_id}-{i}")
        for robot_id, entries in sorted(vectors.items())
        for i, entry in enumerate(entries)
    ]


@pytest.mark.parametrize("robot_id, index, entry", _fk_vector_cases())
def test_dh_product_reproduces_textbook_vector(robot_id: str, index: int, entry: dict):
    robot = load_robot(robot_id)
    printed = np.array(entry["matrix"])
    tolerance = printed_value_tolerance(robot, printed)
    for label, pose in (
        ("DH product", world_T_tool(robot, entry["joints"])),
        ("closed form", CLOSED_FORMS[robot_id](entry["joints"])),
    ):
        error = np.abs(pose - printed)
        assert np.all(error <= tolerance), f"{label} off by {error.max():.2e}"


def _extractor():
    path = DATA_DIR / "extract_textbook_vectors.py"
    spec = importlib.util.spec_from_file_location("extract_textbook_vectors", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_fk_vectors_file_is_current_with_the_textbook():
    extractor = _extractor()
    if not extractor.DEFAULT_TEXTBOOK.exists():
        pytest.skip(f"{extractor.DEFAULT_TEXTBOOK} not found")
    text = extractor.DEFAULT_TEXTBOOK.read_text(encoding="utf-8")
    expected = extractor.to_json(extractor.catalogue_vectors(text))
    assert (DATA_DIR / "textbook_fk_vectors.json").read_text(encoding="utf-8") == expected


# ---------------------------------------------------------------------------
# 3. Robots without a printed closed form: zero poses derived by hand
# ---------------------------------------------------------------------------


def test_puma560_standard_zero_pose_is_the_L_shape():
    """Corke's qz: upper arm along +x0, forearm up, shoulder offset towards -y0."""
    expected = np.array([
        [1.0, 0.0, 0.0, 0.4318 + 0.0203],
        [0.0, 1.0, 0.0, -0.15005],
        [0.0, 0.0, 1.0, 0.4318],
        [0.0, 0.0, 0.0, 1.0],
    ])
    np.testing.assert_allclose(world_T_tool(load_robot("puma560_standard"), np.zeros(6)),
                               expected, atol=1e-12)


def test_ur5_zero_pose_is_stretched_along_minus_x():
    """At q = 0: flange at (a2 + a3, -(d4 + d6), d1 - d5), x6 = x0, y6 = z0, z6 = -y0."""
    d1, a2, a3, d4, d5, d6 = 0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823
    expected = np.array([
        [1.0, 0.0, 0.0, a2 + a3],
        [0.0, 0.0, -1.0, -(d4 + d6)],
        [0.0, 1.0, 0.0, d1 - d5],
        [0.0, 0.0, 0.0, 1.0],
    ])
    robot = load_robot("ur5")
    assert robot["parameters"] == {"d1": d1, "a2": a2, "a3": a3, "d4": d4, "d5": d5, "d6": d6}
    np.testing.assert_allclose(world_T_tool(robot, np.zeros(6)), expected, atol=1e-12)


# ---------------------------------------------------------------------------
# 4. The three PUMA 560 descriptions
# ---------------------------------------------------------------------------


def _alignment(from_id: str, to_id: str) -> dict:
    relations = load_json("puma_frame_alignment.json")["relations"]
    (relation,) = [r for r in relations if r["from"] == from_id and r["to"] == to_id]
    return relation


def test_puma560_modified_and_khalil_give_the_same_pose():
    craig, khalil = load_robot("puma560_modified"), load_robot("puma560_khalil")
    rng = np.random.default_rng(0)
    for q in random_joint_vectors(craig, rng):
        np.testing.assert_allclose(world_T_tool(khalil, q), world_T_tool(craig, q),
                                   rtol=0, atol=EXACT_ATOL)


@pytest.mark.parametrize("to_id", ["puma560_khalil", "puma560_standard"])
def test_puma_frame_alignment(to_id: str):
    """T_to(q + joint_offset) = to_base_T_from_base @ T_from(q) @ from_flange_T_to_flange."""
    relation = _alignment("puma560_modified", to_id)
    from_robot, to_robot = load_robot("puma560_modified"), load_robot(to_id)
    joint_offset = np.deg2rad(relation["joint_offset_deg"])
    to_base_T_from_base = np.array(relation["to_base_T_from_base"], dtype=float)
    from_flange_T_to_flange = np.array(relation["from_flange_T_to_flange"], dtype=float)
    rng = np.random.default_rng(0)
    for q in random_joint_vectors(from_robot, rng):
        np.testing.assert_allclose(
            world_T_tool(to_robot, q + joint_offset),
            to_base_T_from_base @ world_T_tool(from_robot, q) @ from_flange_T_to_flange,
            rtol=0, atol=EXACT_ATOL,
        )


def test_puma_standard_alignment_base_is_a_half_turn_about_z():
    relation = _alignment("puma560_modified", "puma560_standard")
    np.testing.assert_array_equal(relation["to_base_T_from_base"], rot_z(math.pi).round(12))
    np.testing.assert_array_equal(relation["from_flange_T_to_flange"], np.eye(4))


def _hand_eye_smallest_singular_value(joint_offset: np.ndarray) -> float:
    """Smallest singular value of the stacked hand-eye system A(q) X = X B(q).

    A(q) = S(o)^-1 S(q + o) and B(q) = C(0)^-1 C(q), with S the standard and C
    the Craig PUMA. Constant base and tool transforms with
    S(q + o) = base @ C(q) @ tool exist only if X = tool^-1 is a nonzero
    solution, i.e. only if this value is ~0.
    """
    standard, craig = load_robot("puma560_standard"), load_robot("puma560_modified")
    rng = np.random.default_rng(0)
    S0 = world_T_tool(standard, joint_offset)
    C0 = world_T_tool(craig, np.zeros(6))
    blocks = []
    for q in random_joint_vectors(craig, rng, 20):
        A = np.linalg.solve(S0, world_T_tool(standard, q + joint_offset))
        B = np.linalg.solve(C0, world_T_tool(craig, q))
        # column-major vec: vec(A X - X B) = (I kron A - B^T kron I) vec(X)
        blocks.append(np.kron(np.eye(4), A) - np.kron(B.T, np.eye(4)))
    return float(np.linalg.svd(np.vstack(blocks), compute_uv=False)[-1])


def test_puma_standard_and_craig_need_the_joint_offset():
    recorded = np.deg2rad(_alignment("puma560_modified", "puma560_standard")["joint_offset_deg"])
    assert _hand_eye_smallest_singular_value(recorded) < 1e-9
    assert _hand_eye_smallest_singular_value(np.zeros(6)) > 1e-2


@pytest.mark.parametrize("craig_frames_id", ["puma560_modified", "puma560_khalil"])
def test_puma_limits_are_mapped_through_the_alignment(craig_frames_id: str):
    """Corke's limits (standard frames) shifted by -joint_offset give the Craig-frame limits."""
    offset_deg = _alignment("puma560_modified", "puma560_standard")["joint_offset_deg"]
    standard = load_robot("puma560_standard")["joints"]
    craig = load_robot(craig_frames_id)["joints"]
    for std_joint, craig_joint, offset in zip(standard, craig, offset_deg):
        assert craig_joint["limits"] == {
            "lower": std_joint["limits"]["lower"] - offset,
            "upper": std_joint["limits"]["upper"] - offset,
        }


# ---------------------------------------------------------------------------
# 5. Inverse-kinematics example (Spong Example 4.1)
# ---------------------------------------------------------------------------


def _within_limits(robot: dict, q) -> bool:
    for joint, value in zip(robot["joints"], q):
        if joint["limits"] is None:
            continue
        if joint["type"] == "revolute":
            value = math.degrees(value)
        lower, upper = joint["limits"]["lower"], joint["limits"]["upper"]
        if (lower is not None and value < lower - 1e-9) or (upper is not None and value > upper + 1e-9):
            return False
    return True


def test_stanford_example_4_1():
    (example,) = load_json("textbook_ik_examples.json")["spong_ex3_5_stanford"]
    robot = load_robot("spong_ex3_5_stanford")
    assert example["parameters"] == robot["parameters"]
    target = np.array(example["target"])
    residual = example["tolerance"]["fk_residual"]

    np.testing.assert_allclose(world_T_tool(robot, example["book_solution"]), target,
                               rtol=0, atol=residual)
    d6 = robot["parameters"]["d6"]
    np.testing.assert_allclose(target[:3, 3] - d6 * target[:3, 2], example["wrist_centre"],
                               atol=1e-12)

    branches = [tuple(sorted(s["branch"].items())) for s in example["solutions"]]
    assert len(set(branches)) == len(branches) == 3
    for solution in example["solutions"]:
        q = np.array(solution["joints"])
        np.testing.assert_allclose(world_T_tool(robot, q), target, rtol=0, atol=residual)
        if "printed" in solution:
            np.testing.assert_allclose(q, solution["printed"], rtol=0,
                                       atol=example["tolerance"]["printed_digits"])
        if solution["singularities"]:
            # theta5 = 0: every (theta4, value - theta4) reaches the same pose.
            (singularity,) = solution["singularities"]
            assert singularity == {"kind": "wrist", "joints": [3, 5], "relation": "sum",
                                   "value": pytest.approx(math.pi)}
            assert abs(math.sin(q[4])) < 1e-12
            for theta4 in np.linspace(-math.pi, math.pi, 7):
                member = q.copy()
                member[3], member[5] = theta4, singularity["value"] - theta4
                np.testing.assert_allclose(world_T_tool(robot, member), target,
                                           rtol=0, atol=residual)
        else:
            assert abs(math.sin(q[4])) > 0.1

    # What the notes say about the catalogue limits.
    assert not _within_limits(robot, example["book_solution"])
    assert [_within_limits(robot, s["joints"]) for s in example["solutions"]] == [False, False, True]
    reachable_member = np.array(example["solutions"][0]["joints"])
    reachable_member[3], reachable_member[5] = math.radians(10), math.radians(170)
    assert _within_limits(robot, reachable_member)
    np.testing.assert_allclose(world_T_tool(robot, reachable_member), target, atol=residual)
