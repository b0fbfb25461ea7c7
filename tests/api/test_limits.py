"""Joint limits through HTTP: the limits endpoints, and limits, 2π expansion and ordering in IK.

The expected answers are computed here, independently of service/kinematics/_limits.py: bounds are read from
the served robot description (degrees, metres) and every 2π-equivalent θ + 2kπ is tried bound by bound.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from service.api.schemas.limits import LimitsResponse
from tests.conftest import assert_problem, catalogue_robot
from tests.ik_helpers import wrapped

DEG = math.pi / 180
TOL = 1e-9  # the documented inclusive-bound tolerance (radians; times the robot's size for slides)


# --- helpers -----------------------------------------------------------------------------------------------

def served_limits(client, robot_id: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lower, upper, revolute) in radians / metres, from GET /v1/robots/{id} (the files are in degrees)."""
    description = client.get(f"/v1/robots/{robot_id}").json()
    assert description["angle_unit"] == "deg"
    lower, upper, revolute = [], [], []
    for joint in description["joints"]:
        scale = DEG if joint["type"] == "revolute" else 1.0
        limits = joint["limits"] or {"lower": None, "upper": None}
        lower.append(-math.inf if limits["lower"] is None else limits["lower"] * scale)
        upper.append(math.inf if limits["upper"] is None else limits["upper"] * scale)
        revolute.append(joint["type"] == "revolute")
    return np.array(lower), np.array(upper), np.array(revolute)


def targets_of(client, robot_id: str, q: np.ndarray) -> list[dict]:
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": np.asarray(q).tolist()}).json()["poses"]
    return [{"matrix": pose["matrix"]} for pose in poses]


def fk_matrices(client, robot_id: str, q: np.ndarray) -> np.ndarray:
    """FK through the FK batch endpoint, in chunks the service accepts."""
    chunks = [client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q[i:i + 5000].tolist()})
              for i in range(0, len(q), 5000)]
    return np.array([pose["matrix"] for chunk in chunks for pose in chunk.json()["poses"]])


def ik_batch(client, robot_id: str, targets: list[dict], **options) -> list[dict]:
    response = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": targets, **options})
    assert response.status_code == 200, response.text
    return response.json()["results"]


def ik(client, robot_id: str, target: dict, **options) -> dict:
    response = client.post(f"/v1/robots/{robot_id}/ik", json={"target": target, **options})
    assert response.status_code == 200, response.text
    return response.json()


def joints(entries: list[dict], dof: int = 6) -> np.ndarray:
    """The joint vectors of IK solutions, shape (k, dof) even when k is 0."""
    return np.array([entry["joints"] for entry in entries], dtype=float).reshape(len(entries), dof)


def independent_check(raw: np.ndarray, lower, upper, revolute):
    """Each unfiltered solution, every 2π-equivalent, bound by bound.

    Returns the expected kept vectors (every combination of fitting equivalents of a solution whose every joint
    has one) and, for each other solution, the joints that no equivalent fits.
    """
    kept, rejected = [], []
    for solution in raw:
        per_joint = []
        for j, value in enumerate(solution):
            turns = range(-4, 5) if revolute[j] else [0]
            per_joint.append([value + 2 * np.pi * k for k in turns
                              if lower[j] - TOL <= value + 2 * np.pi * k <= upper[j] + TOL])
        bad = [j for j, values in enumerate(per_joint) if not values]
        if bad:
            rejected.append((solution, bad))
        else:
            kept.extend(itertools.product(*per_joint))
    return np.array(kept).reshape(len(kept), raw.shape[1]), rejected


def assert_same_vectors(actual: np.ndarray, expected: np.ndarray, tol: float = 1e-9) -> None:
    """The same multiset of joint vectors: a one-to-one match within ``tol``."""
    assert actual.shape == expected.shape, (actual.shape, expected.shape)
    if not len(actual):
        return
    close = np.abs(actual[:, None, :] - expected[None, :, :]).max(axis=-1) <= tol
    assert (close.sum(axis=1) == 1).all() and (close.sum(axis=0) == 1).all()


def assert_within(q: np.ndarray, lower, upper) -> None:
    assert np.all(q >= lower - TOL) and np.all(q <= upper + TOL), q


# --- PUMA 560: the filtered solutions equal an independent check of each of the 8 ---------------------------

@pytest.mark.parametrize("robot_id", ["puma560_modified", "puma560_standard"])
def test_puma_filtering_matches_an_independent_check(client, robot_id):
    lower, upper, revolute = served_limits(client, robot_id)
    assert np.isfinite(lower).all() and np.isfinite(upper).all()
    rng = np.random.default_rng(560)
    q = rng.uniform(-np.pi, np.pi, (500, 6))  # poses anywhere, so that many solutions break a limit
    targets = targets_of(client, robot_id, q)
    raw_results = ik_batch(client, robot_id, targets, limits=[None] * 6)
    results = ik_batch(client, robot_id, targets)
    tally = {"kept": 0, "rejected": 0, "no_solution": 0, "beyond_pi": 0}
    for raw_result, result in zip(raw_results, results):
        raw = joints(raw_result["solutions"])
        assert len(raw) == 8
        expected_kept, expected_rejected = independent_check(raw, lower, upper, revolute)
        kept = joints(result["solutions"])
        assert_same_vectors(kept, expected_kept)
        for entry in result["solutions"]:
            assert entry["within_limits"] is True and entry["violations"] == []
            assert_within(np.array(entry["joints"]), lower, upper)
        # rejected: the rest, each a 2π-equivalent of one unfiltered solution, with exactly the unfixable joints
        assert len(result["rejected"]) == len(expected_rejected)
        unmatched = list(expected_rejected)
        for entry in result["rejected"]:
            r = np.array(entry["joints"])
            match = next(i for i, (s, _) in enumerate(unmatched) if np.abs(wrapped(r - s)).max() < 1e-9)
            _, bad = unmatched.pop(match)
            assert entry["within_limits"] is False
            assert [v["joint"] for v in entry["violations"]] == bad
            for v in entry["violations"]:
                j = v["joint"]
                assert (v["value"], v["lower"], v["upper"]) == (r[j], lower[j], upper[j])
                assert r[j] < lower[j] - TOL or r[j] > upper[j] + TOL
            fine = [j for j in range(6) if j not in bad]
            assert_within(r[fine], lower[fine], upper[fine])
        if not len(expected_kept):
            assert result["status"] == "no_solution_within_limits" and len(result["rejected"]) == 8
            assert "All 8 solutions violate a joint limit" in result["detail"]
        else:
            assert result["status"] == "ok"
        assert result["truncated"] is False and result["available"] == len(expected_kept)
        tally["kept"] += len(kept)
        tally["rejected"] += len(result["rejected"])
        tally["no_solution"] += result["status"] == "no_solution_within_limits"
        tally["beyond_pi"] += int((np.abs(kept) > np.pi).any(axis=1).sum()) if len(kept) else 0
    # the sample exercises every case: kept, rejected, all rejected, and equivalents beyond ±180° (q6: ±266°)
    assert min(tally.values()) > 0, tally


# --- UR5 with ±360°: the 2π expansion, every expanded solution checked by FK ---------------------------------

def test_ur5_counts_match_the_expansion_and_every_solution_passes_fk(client):
    rng = np.random.default_rng(5)
    q = rng.uniform(-np.pi, np.pi, (30, 6))
    targets = targets_of(client, "ur5", q)
    raw_results = ik_batch(client, "ur5", targets, limits=[None] * 6)
    results = ik_batch(client, "ur5", targets)
    lower, upper, revolute = served_limits(client, "ur5")
    np.testing.assert_array_equal(upper, np.full(6, 2 * np.pi))
    solutions, expected_targets = [], []
    for raw_result, result, target in zip(raw_results, results, targets):
        raw = joints(raw_result["solutions"])
        # count per solution: the product over joints of the number of equivalents within ±2π
        per_solution = [math.prod(sum(abs(v + 2 * np.pi * k) <= 2 * np.pi + TOL for k in range(-2, 3)) for v in s)
                        for s in raw]
        assert len(result["solutions"]) == sum(per_solution) == result["available"]
        assert_same_vectors(joints(result["solutions"]), independent_check(raw, lower, upper, revolute)[0])
        assert result["rejected"] == [] and result["truncated"] is False
        solutions.extend(result["solutions"])
        expected_targets.extend([target["matrix"]] * len(result["solutions"]))
    assert max(len(r["solutions"]) for r in results) == 8 * 2 ** 6
    matrices = fk_matrices(client, "ur5", joints(solutions))
    assert np.abs(matrices - np.array(expected_targets)).max() < 1e-9
    assert np.abs(joints(solutions)).max() > 1.5 * np.pi  # the expansion reaches well past ±π


def test_expansion_cap_keeps_the_nearest_and_says_so(client):
    q = np.array([0.3, -1.2, 1.0, -0.4, 1.1, 0.2])
    target = targets_of(client, "ur5", q[None])[0]
    reference = [3.0, -3.0, 2.0, -2.0, 1.0, -1.0]
    full = ik(client, "ur5", target, reference=reference)
    capped = ik(client, "ur5", target, reference=reference, max_equivalents=100)
    assert len(full["solutions"]) == full["available"] == 512 and full["truncated"] is False
    assert len(capped["solutions"]) == 100 and capped["truncated"] is True and capped["available"] == 512
    assert capped["trimmed"] == 0
    assert "512 solutions fit; max_equivalents = 100 kept the nearest 100" in capped["detail"]
    np.testing.assert_array_equal(joints(capped["solutions"]), joints(full["solutions"][:100]))
    # without a reference the cap keeps each of the 8 branches, as it needs the fewest turns, before any repeat
    first_eight = ik(client, "ur5", target, max_equivalents=8)
    raw = ik(client, "ur5", target, limits=[None] * 6)
    assert first_eight["truncated"] is True
    assert_same_vectors(joints(first_eight["solutions"]), joints(raw["solutions"]))


# --- A continuous joint: never expanded, measured across the wrap -------------------------------------------

def test_a_continuous_joint_is_never_expanded(client):
    q = np.array([0.3, -1.2, 1.0, -0.4, 1.1, 0.2])
    target = targets_of(client, "ur5", q[None])[0]
    continuous_base = [None] + [{"lower": -360, "upper": 360}] * 5
    result = ik(client, "ur5", target, limits=continuous_base, angle_unit="deg")
    raw = np.degrees(joints(ik(client, "ur5", target, limits=[None] * 6)["solutions"]))
    base = joints(result["solutions"])[:, 0]
    assert np.all((base > -180) & (base <= 180))
    per_solution = [math.prod(sum(abs(v + 360 * k) <= 360 for k in range(-2, 3)) for v in s[1:]) for s in raw]
    assert len(result["solutions"]) == sum(per_solution) == 8 * 32
    assert sorted(set(np.round(base, 9))) == sorted(set(np.round(raw[:, 0], 9)))


PLANAR = {"convention": "standard", "angle_unit": "rad",
          "joints": [{"type": "revolute", "a": 1.0, "limits": None}, {"type": "revolute", "a": 1.0, "limits": None}]}


def test_nearest_only_across_the_wrap_continuous(client):
    q_true = np.array([np.pi - 0.1, 0.5])
    pose = client.post("/v1/fk", json={"robot": PLANAR, "joints": q_true.tolist()}).json()["pose"]
    reference = np.array([-np.pi + 0.05, 0.5])
    response = client.post("/v1/ik", json={"robot": PLANAR, "target": {"position": pose["position"]},
                                           "reference": reference.tolist()})
    assert response.status_code == 200, response.text
    found = joints(response.json()["solutions"], dof=2)
    assert len(found) == 2  # continuous joints: no equivalents added
    np.testing.assert_allclose(found[0], q_true, atol=1e-9)
    # measured without the wrap, the other solution would have been nearer: the order really is wrap-aware
    naive = np.abs(found - reference).max(axis=1)
    assert naive[0] > naive[1]
    assert np.abs(wrapped(found[0] - reference)).max() == pytest.approx(0.15)


def test_nearest_only_across_the_wrap_multi_turn(client):
    """PUMA q6 has ±266°: with q6 = −178° and the reference at 175°, the nearest solution is its 182° twin."""
    q = np.radians([10.0, 30.0, -60.0, 20.0, 40.0, -178.0])
    target = targets_of(client, "puma560_standard", q[None])[0]
    reference = np.radians([10.0, 30.0, -60.0, 20.0, 40.0, 175.0])
    result = ik(client, "puma560_standard", target, reference=reference.tolist())
    nearest = np.array(result["solutions"][0]["joints"])
    np.testing.assert_allclose(nearest, np.radians([10.0, 30.0, -60.0, 20.0, 40.0, 182.0]), atol=1e-9)
    # the generating vector itself, the same branch a turn away, is 353° from the reference: last of the four
    assert len(result["solutions"]) == 4
    np.testing.assert_allclose(result["solutions"][-1]["joints"], q, atol=1e-9)


# --- Boundary values ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("unit", ["rad", "deg"])
def test_limits_endpoint_boundaries(client, unit):
    scale = 1 / DEG if unit == "deg" else 1.0
    def row(q5):
        return [0.0, 90 * DEG * scale, -90 * DEG * scale, 0.0, q5 * scale, 0.0]
    response = client.post("/v1/robots/puma560_standard/limits", json={"angle_unit": unit, "joints": [
        row(100 * DEG + 0.5 * TOL), row(-100 * DEG - 0.5 * TOL), row(100 * DEG + 1.5 * TOL), row(-100 * DEG - 1.5 * TOL),
    ]})
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["tolerance"] == TOL
    assert [r["within_limits"] for r in body["results"]] == [True, True, False, False]
    assert body["results"][0]["violations"] == [] and body["results"][0]["equivalent"] is None
    for result, sign in zip(body["results"][2:], (1, -1)):
        (violation,) = result["violations"]
        assert violation["joint"] == 4
        assert violation["value"] == pytest.approx(sign * (100 * DEG + 1.5 * TOL) * scale, abs=1e-12)
        assert (violation["lower"], violation["upper"]) == pytest.approx((-100 * DEG * scale, 100 * DEG * scale))
        assert result["equivalent"] is None  # −260° / 260° do not fit either


def test_limits_endpoint_boundaries_prismatic(client):
    size = catalogue_robot(client, "spong_ex3_5_stanford").characteristic_length
    rows = [[0, 0, d, 0, 0, 0] for d in (1.27 + 0.5 * TOL * size, 0.3048 - 0.5 * TOL * size,
                                         1.27 + 1.5 * TOL * size, 0.3048 - 1.5 * TOL * size)]
    body = client.post("/v1/robots/spong_ex3_5_stanford/limits", json={"joints": rows}).json()
    assert [r["within_limits"] for r in body["results"]] == [True, True, False, False]
    assert [r["violations"][0]["joint"] for r in body["results"][2:]] == [2, 2]


@pytest.mark.parametrize("delta, accepted", [(0.5 * TOL, True), (1.5 * TOL, False)])
def test_ik_boundaries(client, delta, accepted):
    q = np.radians([10.0, 30.0, -60.0, 20.0, 100.0, 40.0])
    q[4] += delta
    result = ik(client, "puma560_standard", targets_of(client, "puma560_standard", q[None])[0])
    kept = joints(result["solutions"])
    rejected = joints(result["rejected"])
    in_kept = len(kept) and (np.abs(kept - q).max(axis=1) < 1e-7).any()
    in_rejected = len(rejected) and (np.abs(rejected - q).max(axis=1) < 1e-7).any()
    assert bool(in_kept) is accepted and bool(in_rejected) is not accepted
    if not accepted:
        entry = next(e for e in result["rejected"] if np.abs(np.array(e["joints"]) - q).max() < 1e-7)
        assert [v["joint"] for v in entry["violations"]] == [4]
        assert entry["violations"][0]["value"] == pytest.approx(q[4], abs=1e-12)


# --- Ordering ----------------------------------------------------------------------------------------------

def _sorted_by(distances: np.ndarray) -> bool:
    return bool(np.all(np.diff(distances) >= -1e-12))


def test_linf_l2_and_weights_order_as_defined(client):
    """Over 50 poses: each norm's order is nondecreasing in its own distance, and the norms disagree somewhere."""
    rng = np.random.default_rng(50)
    lower, upper, _ = served_limits(client, "puma560_standard")
    q = rng.uniform(lower, upper, (50, 6))
    targets = targets_of(client, "puma560_standard", q)
    reference = np.radians([5.0, 80.0, -100.0, 10.0, 20.0, 30.0])
    weights = np.array([1.0, 1.0, 1.0, 0.1, 0.1, 0.1])

    def distances(result, weight=np.ones(6), norm=np.max):
        moves = np.abs(joints(result["solutions"]) - reference) * weight  # finite limits: actual travel
        return norm(moves, axis=1) if norm is np.max else np.sqrt(np.sum(moves ** 2, axis=1))

    plain = ik_batch(client, "puma560_standard", targets)
    linf = ik_batch(client, "puma560_standard", targets, reference=reference.tolist())
    l2 = ik_batch(client, "puma560_standard", targets, reference=reference.tolist(), ordering={"norm": "l2"})
    weighted = ik_batch(client, "puma560_standard", targets, reference=reference.tolist(),
                        ordering={"weights": weights.tolist()})
    l2_differs = weights_differ = 0
    for p, a, b, c in zip(plain, linf, l2, weighted):
        for ordered in (a, b, c):
            assert_same_vectors(joints(ordered["solutions"]), joints(p["solutions"]))
        assert _sorted_by(distances(a))
        assert _sorted_by(distances(b, norm=np.sum))
        assert _sorted_by(distances(c, weights))
        l2_differs += not _sorted_by(distances(a, norm=np.sum))
        weights_differ += not _sorted_by(distances(a, weights))
    assert l2_differs > 0 and weights_differ > 0


def test_order_does_not_depend_on_the_angle_unit(client):
    """Stanford mixes radians and metres: weights and distances are in radians/metres whatever the request says."""
    q = np.array([0.4, 0.6, 0.8, 0.2, 0.9, 1.0])
    target = targets_of(client, "spong_ex3_5_stanford", q[None])[0]
    reference = np.array([0.0, 0.5, 0.5, 0.0, 0.5, 0.0])
    options = {"ordering": {"norm": "l2", "weights": [1, 1, 5, 1, 1, 1]}, "filter_limits": False}
    in_rad = ik(client, "spong_ex3_5_stanford", target, reference=reference.tolist(), **options)
    scale = np.array([1 / DEG, 1 / DEG, 1.0, 1 / DEG, 1 / DEG, 1 / DEG])
    in_deg = ik(client, "spong_ex3_5_stanford", target, reference=(reference * scale).tolist(), angle_unit="deg",
                **options)
    np.testing.assert_allclose(joints(in_deg["solutions"]) / scale, joints(in_rad["solutions"]), atol=1e-9)


def test_nearest_k_and_max_joint_move(client):
    q = np.array([0.3, -1.2, 1.0, -0.4, 1.1, 0.2])
    target = targets_of(client, "ur5", q[None])[0]
    reference = [0.0, -1.0, 1.0, 0.0, 1.0, 0.0]
    full = ik(client, "ur5", target, reference=reference)
    distance = np.abs(joints(full["solutions"]) - reference).max(axis=1)
    nearest = ik(client, "ur5", target, reference=reference, max_solutions=3)
    np.testing.assert_array_equal(joints(nearest["solutions"]), joints(full["solutions"][:3]))
    assert nearest["trimmed"] == 512 - 3 and nearest["truncated"] is False

    bound = float(np.median(distance))
    within_move = ik(client, "ur5", target, reference=reference, max_joint_move=bound)
    expected = joints(full["solutions"])[distance <= bound]
    assert 0 < len(expected) < 512
    np.testing.assert_array_equal(joints(within_move["solutions"]), expected)
    assert within_move["trimmed"] == 512 - len(expected) == 512 - within_move["available"]

    in_deg = ik(client, "ur5", target, reference=np.degrees(reference).tolist(), angle_unit="deg",
                max_joint_move=np.degrees(bound))
    np.testing.assert_allclose(np.radians(joints(in_deg["solutions"])), expected, atol=1e-12)

    nothing = ik(client, "ur5", target, reference=reference, max_joint_move=0.0)
    assert nothing["status"] == "ok" and nothing["solutions"] == [] and nothing["trimmed"] == 512
    assert "none is within max_joint_move" in nothing["detail"]


def test_max_joint_move_per_joint_with_a_slide(client):
    """Stanford in degrees: revolute bounds in degrees, the slide's in metres, one list."""
    q = np.array([0.4, 0.6, 0.8, 0.2, 0.9, 1.0])
    target = targets_of(client, "spong_ex3_5_stanford", q[None])[0]
    scale = np.array([1 / DEG, 1 / DEG, 1.0, 1 / DEG, 1 / DEG, 1 / DEG])
    reference = np.array([0.4, 0.6, 0.5, 0.2, 0.9, 1.0]) * scale
    options = {"reference": reference.tolist(), "angle_unit": "deg", "filter_limits": False,
               "limits": [None, None, {"lower": -2, "upper": 2}, None, None, None]}
    everything = joints(ik(client, "spong_ex3_5_stanford", target, **options)["solutions"])
    assert len(everything) == 8 and set(np.round(everything[:, 2], 9)) == {0.8, -0.8}
    slide_only = ik(client, "spong_ex3_5_stanford", target, max_joint_move=[None, None, 0.85, None, None, None],
                    **options)
    np.testing.assert_allclose(joints(slide_only["solutions"])[:, 2], 0.8)  # |Δd3| = 0.3 kept, 1.3 not
    assert len(slide_only["solutions"]) == 4
    # one number bounds every joint in its own unit: 60° for the revolute joints, 60 m (no bound) for the slide
    scalar = ik(client, "spong_ex3_5_stanford", target, max_joint_move=60, **options)
    revolute = [0, 1, 3, 4, 5]
    expected = everything[np.abs(everything[:, revolute] - reference[revolute]).max(axis=1) <= 60]
    assert 0 < len(expected) < 8
    assert_same_vectors(joints(scalar["solutions"]), expected)


# --- Stanford: a negative slide extension is rejected --------------------------------------------------------

def test_stanford_negative_extension_is_rejected(client):
    q = np.array([30 * DEG, 40 * DEG, 0.8, 20 * DEG, 50 * DEG, 60 * DEG])
    target = targets_of(client, "spong_ex3_5_stanford", q[None])[0]
    raw = joints(ik(client, "spong_ex3_5_stanford", target, limits=[None] * 6)["solutions"])
    assert sorted(np.round(raw[:, 2], 9)) == [-0.8] * 4 + [0.8] * 4
    result = ik(client, "spong_ex3_5_stanford", target)
    assert np.all(joints(result["solutions"])[:, 2] >= 0.3048)
    assert len(result["rejected"]) >= 4
    negative = [e for e in result["rejected"] if e["joints"][2] < 0]
    assert len(negative) == 4
    for entry in negative:
        slide = next(v for v in entry["violations"] if v["joint"] == 2)
        assert slide == {"joint": 2, "value": pytest.approx(-0.8, abs=1e-12), "lower": 0.3048, "upper": 1.27}


def test_stanford_slide_is_never_wrapped_by_the_limits_endpoint(client):
    rows = [[0.5 - 2 * np.pi, 0, 0.8, 0, 0, 0], [0, 0, 0.5 + 2 * np.pi, 0, 0, 0], [0, 0, -0.5, 0, 0, 0]]
    results = client.post("/v1/robots/spong_ex3_5_stanford/limits", json={"joints": rows}).json()["results"]
    assert results[0]["equivalent"] == pytest.approx([0.5, 0, 0.8, 0, 0, 0])  # a revolute joint takes a turn
    assert results[1]["equivalent"] is None  # 0.5 + 2π − 2π would fit, but a slide has no turns
    assert results[2]["violations"] == [{"joint": 2, "value": -0.5, "lower": 0.3048, "upper": 1.27}]


# --- filter_limits: false ----------------------------------------------------------------------------------

def test_unfiltered_keeps_every_solution_flagged(client):
    q = np.array([0.4, 0.6, 0.8, 0.2, 0.9, 1.0])
    target = targets_of(client, "spong_ex3_5_stanford", q[None])[0]
    filtered = ik(client, "spong_ex3_5_stanford", target)
    unfiltered = ik(client, "spong_ex3_5_stanford", target, filter_limits=False)
    assert unfiltered["status"] == "ok" and unfiltered["rejected"] == []
    assert_same_vectors(joints(unfiltered["solutions"]),
                        np.vstack([joints(filtered["solutions"]), joints(filtered["rejected"])]))
    flagged = [s for s in unfiltered["solutions"] if not s["within_limits"]]
    assert len(flagged) == len(filtered["rejected"]) > 0
    assert all(s["violations"] for s in flagged)
    assert f"{len(flagged)} of the solutions violate a joint limit (filter_limits is false)" in unfiltered["detail"]


# --- The limits endpoints ----------------------------------------------------------------------------------

def test_limits_endpoint_in_radians_gives_the_nearest_equivalent(client):
    response = client.post("/v1/robots/ur5/limits", json={"joints": [[7.0, -7.0, 0, 0, 0, 0], [0.5] * 6]})
    assert response.status_code == 200, response.text
    first, second = response.json()["results"]
    assert first["within_limits"] is False
    assert first["violations"] == [
        {"joint": 0, "value": 7.0, "lower": pytest.approx(-2 * np.pi), "upper": pytest.approx(2 * np.pi)},
        {"joint": 1, "value": -7.0, "lower": pytest.approx(-2 * np.pi), "upper": pytest.approx(2 * np.pi)}]
    # 7 − 2π = 0.717 and 7 − 4π = −5.566 both fit: the nearest to 7 is returned
    assert first["equivalent"] == pytest.approx([7.0 - 2 * np.pi, -7.0 + 2 * np.pi, 0, 0, 0, 0])
    assert second == {"within_limits": True, "violations": [], "equivalent": None}


def test_limits_endpoint_in_degrees(client):
    rows = [[0, 90, -90, 0, 0, 300],   # q6 300° → −60° (±266°)
            [0, 90, -90, 200, 0, 0],   # q4 200° in [−110°, 170°]: −160° does not fit either
            [170, 90, -90, 0, 0, 0]]   # q1 170° in ±160°: −190° does not fit
    body = client.post("/v1/robots/puma560_standard/limits", json={"joints": rows, "angle_unit": "deg"}).json()
    first, second, third = body["results"]
    assert first["violations"] == [{"joint": 5, "value": 300.0, "lower": pytest.approx(-266),
                                    "upper": pytest.approx(266)}]
    assert first["equivalent"] == pytest.approx([0, 90, -90, 0, 0, -60])
    assert second["equivalent"] is None and [v["joint"] for v in second["violations"]] == [3]
    assert third["equivalent"] is None and third["violations"][0]["upper"] == pytest.approx(160)


@pytest.mark.parametrize("rows", [40, 3000])
def test_the_limits_answer_is_its_response_model(client, rows):
    """The answer is built field by field, not through LimitsResponse: it must be what the model says, with
    violations, equivalents and none, an override with an open bound, in degrees, for a small body (answered where
    it arrives) and a large one, catalogue and inline."""
    q = np.random.default_rng(rows).uniform(-500, 500, (rows, 6)).round(3)
    limits = [{"lower": -90, "upper": 90}, {"lower": None, "upper": 45}] + [None] * 4
    requests = [("/v1/robots/ur5/limits", {"joints": q.tolist(), "angle_unit": "deg"}),
                ("/v1/robots/puma560_standard/limits", {"joints": q.tolist(), "angle_unit": "deg", "limits": limits}),
                ("/v1/limits", {"robot": PLANAR, "joints": q[:, :2].tolist(), "angle_unit": "deg"})]
    kinds = set()
    for path, body in requests:
        response = client.post(path, json=body)
        assert response.status_code == 200, response.text
        answer = response.json()
        assert LimitsResponse.model_validate(answer).model_dump(mode="json") == answer
        assert len(answer["results"]) == rows
        kinds |= {(r["within_limits"], r["equivalent"] is None) for r in answer["results"]}
    assert kinds == {(True, True), (False, False), (False, True)}  # within; outside, with and without an equivalent


def test_limits_inline_with_an_override(client):
    body = {"robot": {**PLANAR, "angle_unit": "deg"}, "angle_unit": "deg", "joints": [[400, -30], [-10, 10]],
            "limits": [{"lower": -360, "upper": 360}, {"lower": 0, "upper": None}]}
    response = client.post("/v1/limits", json=body)
    assert response.status_code == 200, response.text
    first, second = response.json()["results"]
    assert first["equivalent"] == pytest.approx([40, 330])  # one-sided: the nearest turn above 0
    assert [v["joint"] for v in first["violations"]] == [0, 1]
    assert first["violations"][1] == {"joint": 1, "value": pytest.approx(-30.0), "lower": 0.0, "upper": None}
    assert second == {"within_limits": True, "violations": [], "equivalent": None}


# --- Every 422 -----------------------------------------------------------------------------------------------

UR5_TARGET = {"position": [0.4, 0.1, 0.3], "orientation": {"type": "quaternion", "wxyz": [0, 1, 0, 0]}}
ZERO = [0.0] * 6
SIX_LIMITS = [{"lower": -1, "upper": 1}] * 6
BAD_ORDER = SIX_LIMITS[:2] + [{"lower": 50, "upper": 10}] + SIX_LIMITS[3:]

INVALID = [
    ("/v1/robots/ur5/limits", {"joints": [ZERO], "limits": BAD_ORDER}, ["body", "limits", 2],
     "joint 2 (elbow): lower limit 50 is greater than upper limit 10"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "limits": BAD_ORDER}, ["body", "limits", 2], "joint 2 (elbow)"),
    ("/v1/robots/ur5/ik/batch", {"targets": [UR5_TARGET], "limits": BAD_ORDER}, ["body", "limits", 2],
     "joint 2 (elbow)"),
    ("/v1/robots/ur5/limits", {"joints": [ZERO], "limits": SIX_LIMITS[:5]}, ["body", "limits"],
     "expected limits for 6 joints"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "limits": SIX_LIMITS + [None]}, ["body", "limits"],
     "expected limits for 6 joints"),
    ("/v1/robots/ur5/limits", {"joints": [ZERO], "limits": [{"lower": math.nan, "upper": 1}] + SIX_LIMITS[1:]},
     ["body", "limits", 0, "lower"], "finite"),
    ("/v1/robots/ur5/limits", {"joints": [ZERO], "limits": [{"lower": -math.inf, "upper": 1}] + SIX_LIMITS[1:]},
     ["body", "limits", 0, "lower"], "finite"),
    ("/v1/robots/ur5/limits", {"joints": [ZERO], "limits": [{"lower": 0}] + SIX_LIMITS[1:]},
     ["body", "limits", 0, "upper"], "required"),
    ("/v1/robots/ur5/limits", {"joints": [[0, math.nan, 0, 0, 0, 0]]}, ["body", "joints", 0, 1], "finite"),
    ("/v1/robots/ur5/limits", {"joints": [ZERO, ZERO[:5]]}, ["body", "joints", 1], "row 1 has 5"),
    ("/v1/robots/ur5/limits", {"joints": []}, ["body", "joints"], "at least 1"),
    ("/v1/limits", {"joints": [[0]], "robot": {"convention": "standard", "joints": [
        {"a": 1, "limits": {"lower": 1, "upper": 0}}]}}, ["body", "robot"], "greater than upper limit"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO[:5]}, ["body", "reference"], "shape (6,)"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": [math.nan] + ZERO[1:]}, ["body", "reference", 0],
     "finite"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "max_solutions": 2}, ["body", "max_solutions"],
     "max_solutions needs a reference"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "max_joint_move": 0.5}, ["body", "max_joint_move"],
     "max_joint_move needs a reference"),
    ("/v1/robots/ur5/ik/batch", {"targets": [UR5_TARGET], "max_solutions": 1}, ["body", "max_solutions"],
     "needs a reference"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "ordering": {"weights": [1] * 6}}, ["body", "ordering", "weights"],
     "needs a reference"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "ordering": {"norm": "l2"}}, ["body", "ordering", "norm"],
     "needs a reference"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "ordering": {"weights": [1] * 5}},
     ["body", "ordering", "weights"], "expected 6 values of weights"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "ordering": {"weights": [1, -1, 1, 1, 1, 1]}},
     ["body", "ordering", "weights", 1], "greater than or equal to 0"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "ordering": {"weights": [math.nan] + [1] * 5}},
     ["body", "ordering", "weights", 0], "finite"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "ordering": {"norm": "l1"}},
     ["body", "ordering", "norm"], "'linf' or 'l2'"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "max_joint_move": [1] * 5},
     ["body", "max_joint_move"], "expected 6 values of max_joint_move"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "max_joint_move": -1},
     ["body", "max_joint_move"], "greater than or equal to 0"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "reference": ZERO, "max_solutions": -1}, ["body", "max_solutions"],
     "greater than or equal to 0"),
    ("/v1/robots/ur5/ik", {"target": UR5_TARGET, "max_equivalents": 0}, ["body", "max_equivalents"],
     "greater than or equal to 1"),
]


@pytest.mark.parametrize("path, body, loc, match", INVALID, ids=[f"{i}:{c[2][-1]}" for i, c in enumerate(INVALID)])
def test_invalid_requests_are_422_naming_the_field(client, path, body, loc, match):
    import json

    response = client.post(path, content=json.dumps(body), headers={"content-type": "application/json"})
    problem = assert_problem(response, 422, loc=loc)
    assert match in problem["detail"], problem["detail"]


# --- Catalogue ---------------------------------------------------------------------------------------------

PUBLISHED = {
    "puma560_standard": [(-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266)],
    "puma560_modified": [(-160, 160), (-225, 45), (-225, 45), (-110, 170), (-100, 100), (-266, 266)],
    "puma560_khalil": [(-160, 160), (-225, 45), (-225, 45), (-110, 170), (-100, 100), (-266, 266)],
    "ur5": [(-360, 360)] * 6,
    "spong_ex3_5_stanford": [(-170, 170), (-170, 170), (0.3048, 1.27), (-260, 80), (-90, 90), (-170, 170)],
}


def test_catalogue_states_where_every_limit_comes_from(client):
    robot_ids = [robot["id"] for robot in client.get("/v1/robots").json()["robots"]]
    assert set(PUBLISHED) <= set(robot_ids)
    for robot_id in robot_ids:
        description = client.get(f"/v1/robots/{robot_id}").json()
        assert description["limits_source"] and description["limits_source"].strip(), robot_id
        if description["format"] == "urdf":  # limits are the source file's: tests/robots/test_urdf.py
            continue
        served = [None if j["limits"] is None else (j["limits"]["lower"], j["limits"]["upper"])
                  for j in description["joints"]]
        if robot_id in PUBLISHED:
            assert served == PUBLISHED[robot_id], robot_id


def test_the_wire_words_every_note_of_the_core_with_the_same_fields():
    import string

    from service.api.boundary import WIRE_NOTES
    from service.kinematics.ik import NOTE_WORDING

    def fields(text):
        return {name for _, name, _, _ in string.Formatter().parse(text) if name}

    assert WIRE_NOTES.keys() == NOTE_WORDING.keys()
    assert all(fields(WIRE_NOTES[kind]) == fields(NOTE_WORDING[kind]) for kind in NOTE_WORDING)
