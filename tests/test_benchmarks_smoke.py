"""The benchmark scripts run end to end with tiny sizes, so that they cannot rot.

No timing is asserted: only that each script runs and prints its table. The anchor libraries (the ``bench``
extra) are usually not installed here, and the scripts must then say they skipped them; wrk may be missing too.
"""

from __future__ import annotations

import shutil

import pytest

from benchmarks import (anchors, collision, core, http_throughput, request_profile, single_pose_profile, slide_classes,
                        wrist_classes)


def test_core_benchmark_runs_with_tiny_sizes(capsys):
    assert core.main(["--quick", "--robots", "PUMA 560", "Stanford"]) == 0
    out = capsys.readouterr().out
    assert "| PUMA 560 | IK, single pose | core |" in out
    assert "| Stanford | FK, batch of 20 | core |" in out
    assert "peak traced memory for a 200-pose batch" in out
    for robot in ("PUMA 560", "UR5", "KUKA KR6"):  # what a request pays: the whole answer beside the solve alone
        for limits in ("limits ±π, no filter", "catalogue limits"):
            assert f"| {robot} | IK answer, {limits}, single pose | core |" in out
            assert f"| {robot} | IK answer, {limits}, batch of 20 | core, solve only (solve_ik_arrays) |" in out
            assert f"| {robot} | IK answer, {limits}, {core.FEW_TARGETS_A_CALL} targets a call | core |" in out
    for robot in ("UR5", "KUKA KR6"):  # and what a CAD-rounded description of the arm pays
        assert f"| {robot}, parallel axes 1e-5 rad off | IK answer, limits ±π, no filter, single pose | core |" in out
        assert (f"arm with parallel axes 1e-5 rad off / the exact arm, core ({robot}): " in out)
    for name in anchors.LIBRARIES:
        if not anchors.installed(name):
            assert f"{name}: not installed" in out


def test_the_cad_rounded_arms_leave_their_family_by_the_tilt_alone():
    """cad_rounded moves each twist of 0 or π by 1e-5 rad, alternately up and down, and nothing else: the UR5 and
    the KUKA KR6 so stated are answered by the refined closed form (IdealisedPlan), as a rounded URDF of them is,
    so the rounded rows time that path."""
    import numpy as np

    from service.config import Settings
    from service.kinematics.ik import cached_plan
    from service.kinematics.ik._idealised import IdealisedPlan
    from service.robots.catalogue import load_catalogue

    catalogue = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
    for label in core.ROUNDED_ROBOTS:
        exact = catalogue.get(core.ROBOTS[label]).robot
        rounded = core.cad_rounded(exact)
        moved = rounded.alpha - exact.alpha
        parallel = np.abs(np.sin(exact.alpha)) < 1e-9
        assert parallel.sum() >= 2
        np.testing.assert_allclose(moved[parallel], core.ROUNDING_TILT * (-1.0) ** np.arange(parallel.sum()),
                                   rtol=1e-6)
        assert not moved[~parallel].any()
        for name in ("a", "d", "theta", "world_T_base", "flange_T_tool"):
            assert np.array_equal(getattr(rounded, name), getattr(exact, name))
        assert isinstance(cached_plan(rounded, constrain_orientation=True, reference=None), IdealisedPlan)


def test_request_profile_runs_with_tiny_sizes(capsys):
    assert request_profile.main(["--requests", "3", "--batch", "20", "--batch-requests", "1"]) == 0
    out = capsys.readouterr().out
    for request in ("POST fk, one configuration", "POST ik, one pose",
                    "POST ik/batch, 20 targets as matrix rows, arrays form"):
        assert f"**{request}**" in out
    for stage in ("receive + parse (orjson)", "validate (IKRequest)", "validate (IKBatchRequest)",
                  "dependencies (catalogue robot)", "cost check (small or not, the cost model's caps)",
                  "core answer (answer_ik)", "encode (ik_objects, orjson)", "encode (ik_columns, orjson)",
                  "send (response object, ASGI messages)", "framework, the service's ASGI layer, routing (the rest)"):
        assert f"|   {stage} |" in out
    assert "|     of which the solve alone (solve_ik) |" in out
    assert out.count("| bare FastAPI: POST of this body, validated |") == 3
    assert "| bare FastAPI + the service's ASGI layer (RequestGate): POST of this body |" in out
    for request in ("fk", "ik"):
        assert f"| POST {request}, whole request, arguments found by FastAPI's dependency solver |" in out


def test_single_pose_profile_runs_with_tiny_sizes(capsys):
    assert single_pose_profile.main(["--quick", "--robots", "PUMA 560", "UR5"]) == 0
    out = capsys.readouterr().out
    for robot in ("PUMA 560", "UR5"):
        assert f"**{robot}**: " in out
    for stage in ("scalar solve (plan.solve_one)", "FK check (verify_one)",
                  "the rest: table, selection, targets, plan look-up, assembly, IKAnswer"):
        assert out.count(f"|   {stage} |") == 2
    for stage in ("FK of the candidates (the chain program on floats)", "table (one_pose_table)",
                  "selection (select), limits ±π, no filter"):
        assert out.count(f"|     {stage} |") == 2
    assert out.count("| whole answer (answer_ik), catalogue limits |") == 2
    assert out.count("- the floor (the scalar solve + the FK of its candidates): ") == 2


def test_the_single_pose_profile_leaves_the_core_as_it_found_it():
    """The in-the-answer rows look stages up from tables while they run: afterwards the plan's solve, the FK check
    and the chain program are the core's own again, and answer a pose the profile never saw."""
    import numpy as np

    from service.config import Settings
    from service.kinematics import forward_kinematics
    from service.kinematics.ik import IKTargets, answer_ik, cached_plan
    from service.kinematics.ik import _closed_form, _goals
    from service.robots.catalogue import load_catalogue

    robot = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get(core.ROBOTS["UR5"]).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    before = (vars(type(plan)).get("solve_one"), _closed_form.verify_one, _goals.tool_columns_scalar_rows)
    single_pose_profile.profile_robot("UR5", robot, 3, 1)
    assert (vars(type(plan)).get("solve_one"), _closed_form.verify_one, _goals.tool_columns_scalar_rows) == before
    q = np.array([0.3, -1.1, 1.4, -0.2, 0.9, 2.5])
    answer = answer_ik(robot, IKTargets.poses(forward_kinematics(robot, q)[None]))
    assert np.abs(answer.solutions.joints - q).max(axis=1).min() < 1e-9


def test_wrist_classes_benchmark_runs_with_tiny_sizes(capsys):
    assert wrist_classes.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "- KUKA KR 6 R900-2: offset_shoulder_parallel_elbow+spherical_wrist" in out
    assert "| random skew axes | IK, batch of 20 | core |" in out
    assert "| random wrist at the base | IK, single pose | core |" in out


def test_collision_benchmark_runs_with_tiny_sizes(capsys):
    assert collision.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "12 pairs: 5 box-capsule, 7 capsule-capsule" in out
    for row in ("link_frames, 200 configurations", "distances, 200 configurations",
                "check (margin 0.01), 200 configurations", "distances, 1 configuration (per call)",
                "distances, 16 configurations (per call)", "collision_model (compiling the 12 pairs, per call)"):
        assert f"| {row} |" in out
    assert "| 100 targets, arrays form |" in out and "| 100 targets, objects form |" in out


def test_slide_classes_benchmark_runs_with_tiny_sizes(capsys):
    assert slide_classes.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "- random PRR + wrist: skew_axes_with_slide+spherical_wrist" in out
    assert "| random RPR | IK, batch of 20 | core |" in out


@pytest.mark.skipif(shutil.which("wrk") is None, reason="wrk (Debian package) is not installed")
def test_http_benchmark_runs_with_tiny_sizes(capsys):
    assert http_throughput.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "| GET /healthz (framework ceiling) |" in out
    assert "single IK on the PUMA or UR5 / GET /healthz" in out
    for row in ("POST ik, one pose, kuka_kr6_r900_2", "POST /v1/ik, one pose, inline puma560_standard",
                "POST ik, one pose, puma560_standard, 2 workers", http_throughput.WAYPOINTS_ROW):
        assert f"| {row} |" in out
    assert "targets, format arrays, catalogue limits |" in out
    for row in ("GET /healthz", "POST fk, one configuration", "POST ik, one pose, puma560_standard"):
        assert f"| {row}, KIN_LOG_LEVEL=info (the default) |" in out
    assert "- the access line of the default log level, per request" in out
    assert f"- {http_throughput.WAYPOINTS} waypoints in one batch / one pose a request, poses/s" in out


def test_http_benchmark_says_when_wrk_is_missing(capsys, monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert http_throughput.main(["--quick"]) == 0
    assert "wrk is not installed" in capsys.readouterr().out


def test_redundant_benchmark_runs_with_tiny_sizes(capsys):
    from benchmarks import redundant

    assert redundant.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "| iiwa 14 | full pose, q7 sampled 32× |" in out
    assert "| SO-101-like | position + direction, roll axis z |" in out


def test_general_6r_benchmark_runs_with_tiny_sizes(capsys):
    from benchmarks import general_6r

    assert general_6r.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "| random general 6R (seed 2026) | core |" in out
    assert "| Manocha-Canny 16-solution arm | core |" in out


def test_three_parallel_benchmark_runs_with_tiny_sizes(capsys):
    from benchmarks import three_parallel

    assert three_parallel.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "| 4∥5∥6 | IK, batch of 20 | core |" in out
    assert "core on 1∥2∥3: family three_parallel_at_base" in out


def test_general_6r_singular_count_runs_with_tiny_sizes(capsys):
    from benchmarks import general_6r_singular

    assert general_6r_singular.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "| ufactory_xarm6 | 10 |" in out
    assert out.strip().splitlines()[-1].endswith("| 0 |")  # no broken promise
