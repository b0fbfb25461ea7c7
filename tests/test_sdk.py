"""A Python client generated from openapi/openapi.json, used against a live server.

openapi-python-client (the ``sdk`` extra, pinned; CI installs it) generates the client into a temporary
directory, offline. The client then talks to ``python -m service`` on a free loopback port that runs with an
API key, so the security scheme is exercised through the generated ``AuthenticatedClient`` as well.

Checked: clean generated names (one module per named schema, no ``*_type_0`` / ``*_item`` models); the robot
list; every catalogue robot parsed by the generated models (the ``d``-last guard of api.md: openapi-python-client
binds the incoming dict to a local ``d``); FK; IK with every orientation variant and with a matrix target;
limits; and a 404 and a 422 received as typed ``Problem`` models.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import BUILTIN_ROBOTS_DIR
from service.kinematics import forward_kinematics
from service.openapi import SPEC_PATH
from tests.doc_pages import section
from tests.live import serve

if importlib.util.find_spec("openapi_python_client") is None:
    pytest.skip("openapi-python-client is not installed: pip install -e '.[sdk]' (CI installs it)",
                allow_module_level=True)

PACKAGE = "kinematics_client"
API_KEY = "sdk-test-key"
CATALOGUE = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)


@pytest.fixture(scope="module")
def sdk(tmp_path_factory):
    """Generate the client package and import it."""
    root = tmp_path_factory.mktemp("sdk")
    config = root / "config.yaml"
    shared = (SPEC_PATH.parent / "client-config.yaml").read_text(encoding="utf-8")  # the README's settings
    config.write_text(shared + f"project_name_override: kinematics-client\npackage_name_override: {PACKAGE}\n"
                      "post_hooks: []\n")
    result = subprocess.run(
        [sys.executable, "-m", "openapi_python_client", "generate", "--path", str(SPEC_PATH), "--meta", "none",
         "--output-path", str(root / PACKAGE), "--config", str(config)],
        capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    # Warnings mean a schema the generator could not turn into a model: the spec must give none.
    assert "Warning" not in result.stdout + result.stderr, result.stdout + result.stderr
    sys.path.insert(0, str(root))
    try:
        yield importlib.import_module(PACKAGE)
    finally:
        sys.path.remove(str(root))
        for name in [name for name in sys.modules if name == PACKAGE or name.startswith(PACKAGE + ".")]:
            del sys.modules[name]


@pytest.fixture(scope="module")
def client(sdk):
    with serve(KIN_API_KEY=API_KEY) as base_url:
        with sdk.AuthenticatedClient(base_url=base_url, token=API_KEY, prefix="", auth_header_name="X-API-Key",
                                     raise_on_unexpected_status=True) as authenticated:
            yield authenticated


def _api(name: str):
    return importlib.import_module(f"{PACKAGE}.api.{name}")


def _models():
    return importlib.import_module(f"{PACKAGE}.models")


def test_generated_names_are_clean(sdk):
    root = Path(sdk.__file__).parent
    models = sorted(p.stem for p in (root / "models").glob("*.py") if p.stem != "__init__")
    assert not [m for m in models if "_type_" in m or m.endswith("_item") or m.startswith("body_")], models
    for expected in ("dh_robot", "khalil_robot", "urdf_robot", "screws_robot", "pose_target", "matrix_orientation",
                     "quaternion_orientation", "euler_zyz_orientation", "rpy_orientation", "ik_response", "problem", "angle_unit"):
        assert expected in models
    operations = sorted(p.stem for p in (root / "api").rglob("*.py") if p.stem != "__init__")
    assert {"list_robots", "get_robot", "forward_kinematics", "forward_kinematics_inline",
            "forward_kinematics_batch", "inverse_kinematics", "inverse_kinematics_inline",
            "inverse_kinematics_batch", "check_joint_limits", "check_joint_limits_inline", "liveness",
            "readiness"} <= set(operations)


def test_list_robots(client):
    listed = _api("robots.list_robots").sync(client=client)
    assert type(listed).__name__ == "RobotList"
    by_id = {robot.id: robot for robot in listed.robots}
    assert set(by_id) == {entry.description.id for entry in CATALOGUE.entries()}
    assert by_id["ur5"].dof == 6 and by_id["ur5"].convention.value == "standard"


def test_every_catalogue_robot_parses_with_its_d_values(client):
    """The d-last guard: a property named d would otherwise overwrite from_dict's local dict."""
    get_robot = _api("robots.get_robot")
    for entry in CATALOGUE.entries():
        robot = get_robot.sync(robot_id=entry.description.id, client=client)
        if entry.description.format == "urdf":
            assert type(robot).__name__ == "URDFRobot" and robot.urdf == entry.description.urdf
            continue
        assert type(robot).__name__ == ("KhalilRobot" if entry.description.convention == "khalil" else "DHRobot")
        assert [joint.d for joint in robot.joints] == [joint.d for joint in entry.description.joints]


def test_descriptions_in_other_forms_parse_and_work_inline(client):
    """?form=screws and ?form=urdf come back as typed models, and those models work as inline robots."""
    models = _models()
    get_robot = _api("robots.get_robot")
    screws = get_robot.sync(robot_id="ur5", client=client, form=models.DescriptionForm.SCREWS)
    urdf = get_robot.sync(robot_id="ur5", client=client, form=models.DescriptionForm.URDF)
    assert type(screws).__name__ == "ScrewsRobot" and type(urdf).__name__ == "URDFRobot"
    q = [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]
    expected = forward_kinematics(CATALOGUE.get("ur5").robot, np.array(q))
    fk_inline = _api("forward_kinematics.forward_kinematics_inline")
    for robot in (screws, urdf):
        pose = fk_inline.sync(client=client, body=models.FKInlineRequest(joints=q, robot=robot)).pose
        assert np.allclose(pose.matrix, expected, atol=1e-12)
    refused = get_robot.sync_detailed(robot_id="franka_panda", client=client, form=models.DescriptionForm.DH)
    assert refused.status_code == 422 and isinstance(refused.parsed, models.Problem)


def test_per_request_tool(client):
    models = _models()
    tool = np.eye(4)
    tool[:3, 3] = [0.0, 0.0, 0.15]
    q = [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]
    response = _api("forward_kinematics.forward_kinematics").sync(
        robot_id="ur5", client=client, body=models.FKRequest(joints=q, tool=tool.tolist()))
    assert np.allclose(response.pose.matrix, forward_kinematics(CATALOGUE.get("ur5").robot, np.array(q)) @ tool,
                       atol=1e-12)
    assert response.joint_names == CATALOGUE.get("ur5").robot.joint_names


def test_forward_kinematics(client):
    models = _models()
    response = _api("forward_kinematics.forward_kinematics").sync(
        robot_id="spong_ex3_1_planar_rr", client=client, body=models.FKRequest(joints=[0.5, -0.7]))
    assert response.pose.position == pytest.approx([1.367616, 0.380091, 0.0], abs=1e-6)
    inline = models.FKInlineRequest(
        joints=[0.3, 0.2],
        robot=models.DHRobot(convention=models.DHRobotConvention.STANDARD,
                             joints=[models.DHJoint(a=1.0, d=0.0), models.DHJoint(a=0.5, d=0.25)]))
    pose = _api("forward_kinematics.forward_kinematics_inline").sync(client=client, body=inline).pose
    assert pose.position == pytest.approx([np.cos(0.3) + 0.5 * np.cos(0.5), np.sin(0.3) + 0.5 * np.sin(0.5), 0.25])


def _targets(models, T: np.ndarray):
    from service.kinematics import quaternions_from_matrices, rpy_from_matrix
    from service.kinematics._rotations import euler_zyz_from_matrix

    R, p = T[:3, :3], T[:3, 3].tolist()
    return {
        "matrix target": models.PoseTarget(matrix=T.tolist()),
        "matrix": models.PoseTarget(position=p, orientation=models.MatrixOrientation(type_="matrix",
                                                                                      matrix=R.tolist())),
        "quaternion": models.PoseTarget(position=p, orientation=models.QuaternionOrientation(
            type_="quaternion", wxyz=quaternions_from_matrices(R[None])[0].tolist())),
        "euler_zyz": models.PoseTarget(position=p, orientation=models.EulerZYZOrientation(
            type_="euler_zyz", angles=euler_zyz_from_matrix(R)[0].tolist())),
        "rpy": models.PoseTarget(position=p, orientation=models.RPYOrientation(
            type_="rpy", angles=rpy_from_matrix(R)[0].tolist())),
    }


@pytest.mark.parametrize("variant", ["matrix target", "matrix", "quaternion", "euler_zyz", "rpy"])
def test_inverse_kinematics_with_every_orientation_variant(client, variant):
    models = _models()
    robot = CATALOGUE.get("puma560_modified").robot
    q = np.radians([20.0, -40.0, 70.0, 10.0, 35.0, -15.0])
    target = _targets(models, forward_kinematics(robot, q))[variant]
    response = _api("inverse_kinematics.inverse_kinematics").sync(
        robot_id="puma560_modified", client=client,
        body=models.IKRequest(target=target, reference=q.tolist(), filter_limits=False))
    assert type(response).__name__ == "IKResponse"
    assert response.status == models.IKStatus.OK
    assert response.solver.method == models.SolverMethod.ANALYTIC and response.solver.complete
    assert len(response.solutions) == 8  # the PUMA's eight branches at a regular pose
    nearest = response.solutions[0]
    assert np.allclose(nearest.joints, q, atol=1e-9)  # ordered nearest to the reference first
    assert nearest.residual.position < 1e-9
    assert nearest.branch.shoulder is not None and nearest.branch.elbow is not None


def test_inverse_kinematics_batch(client):
    models = _models()
    robot = CATALOGUE.get("ur5").robot
    q = np.array([0.1, -1.2, 1.0, 0.3, 1.5, 0.2])
    targets = list(_targets(models, forward_kinematics(robot, q)).values())
    response = _api("inverse_kinematics.inverse_kinematics_batch").sync(
        robot_id="ur5", client=client, body=models.IKBatchRequest(targets=targets, reference=q.tolist()))
    assert [result.status for result in response.results] == [models.IKStatus.OK] * 5
    for result in response.results:
        assert np.allclose(result.solutions[0].joints, q, atol=1e-9)


def test_render_returns_the_svg_text(client):
    models = _models()
    picture = _api("pictures.render").sync(
        robot_id="ur5", client=client,
        body=models.RenderRequest(joints=[[0.0] * 6, [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]]))
    assert isinstance(picture, str) and picture.startswith("<svg")
    assert picture.count('class="configuration') == 2


def test_check_joint_limits(client):
    models = _models()
    response = _api("joint_limits.check_joint_limits").sync(
        robot_id="ur5", client=client, body=models.LimitsRequest(joints=[[7.0, 0, 0, 0, 0, 0], [0.5] * 6]))
    outside, inside = response.results
    assert not outside.within_limits and inside.within_limits
    violation = outside.violations[0]
    assert (violation.joint, violation.value) == (0, 7.0)
    assert violation.upper == pytest.approx(2 * np.pi)
    assert outside.equivalent == pytest.approx([7.0 - 2 * np.pi, 0, 0, 0, 0, 0])


def test_unknown_robot_is_a_typed_404(client):
    models = _models()
    detailed = _api("forward_kinematics.forward_kinematics").sync_detailed(
        robot_id="no_such_robot", client=client, body=models.FKRequest(joints=[0.0]))
    assert detailed.status_code == 404
    assert isinstance(detailed.parsed, models.Problem)
    assert detailed.parsed.status == 404 and "no_such_robot" in detailed.parsed.detail


def test_wrong_joint_count_is_a_typed_422_naming_the_field(client):
    models = _models()
    detailed = _api("forward_kinematics.forward_kinematics").sync_detailed(
        robot_id="ur5", client=client, body=models.FKRequest(joints=[0.0, 0.0]))
    assert detailed.status_code == 422
    problem = detailed.parsed
    assert isinstance(problem, models.Problem)
    assert isinstance(problem.errors[0], models.FieldError)
    assert problem.errors[0].loc == ["body", "joints"]


def test_without_the_key_the_client_gets_a_typed_401(sdk, client):
    models = _models()
    with sdk.Client(base_url=str(client._base_url)) as anonymous:
        detailed = _api("robots.list_robots").sync_detailed(client=anonymous)
    assert detailed.status_code == 401 and isinstance(detailed.parsed, models.Problem)


# --------------------------------------------------------------------------- a plain Client, and the README script


@pytest.fixture(scope="module")
def open_server(sdk):
    """A live server without KIN_API_KEY, as most deployments on a cell network run."""
    with serve() as base_url:
        yield base_url


def test_every_v1_operation_takes_a_plain_client(sdk):
    """The key is optional in the spec, so no operation demands an AuthenticatedClient."""
    import inspect
    import typing

    root = Path(sdk.__file__).parent
    modules = sorted(p for p in (root / "api").rglob("*.py") if p.stem != "__init__")
    assert len(modules) >= 14
    for path in modules:
        module = importlib.import_module(f"{PACKAGE}.api.{path.parent.name}.{path.stem}")
        annotation = inspect.signature(module.sync_detailed).parameters["client"].annotation
        accepted = typing.get_args(annotation) or (annotation,)
        assert sdk.Client in accepted, (path.stem, annotation)


def test_the_security_scheme_names_the_header():
    import json

    spec = json.loads(SPEC_PATH.read_text(encoding="utf-8"))
    scheme = spec["components"]["securitySchemes"]["ApiKeyHeader"]
    assert (scheme["type"], scheme["in"], scheme["name"]) == ("apiKey", "header", "X-API-Key")
    assert spec["security"] == [{"ApiKeyHeader": []}, {}]  # optional: a plain client is enough without a key
    assert spec["paths"]["/healthz"]["get"]["security"] == []


def test_a_plain_client_works_without_a_key(sdk, open_server):
    models = _models()
    with sdk.Client(base_url=open_server, raise_on_unexpected_status=True) as plain:
        listed = _api("robots.list_robots").sync(client=plain)
        assert "ur5" in {robot.id for robot in listed.robots}
        q = [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]
        pose = _api("forward_kinematics.forward_kinematics").sync(
            robot_id="ur5", client=plain, body=models.FKRequest(joints=q)).pose
        # the FK pose as it stands is an IK target
        answer = _api("inverse_kinematics.inverse_kinematics").sync(
            robot_id="ur5", client=plain,
            body=models.IKRequest(target=models.PoseTarget.from_dict(pose.to_dict()), reference=q))
    assert answer.status == models.IKStatus.OK
    assert np.allclose(answer.solutions[0].joints, q, atol=1e-9)


def test_a_plain_client_with_the_header_works_with_a_key(sdk, client):
    with sdk.Client(base_url=str(client._base_url), headers={"X-API-Key": API_KEY},
                    raise_on_unexpected_status=True) as keyed:
        listed = _api("robots.list_robots").sync(client=keyed)
    assert len(listed.robots) == len(CATALOGUE)


def _readme_sdk_section() -> str:
    """The "Python SDK" section of docs/python-library.md (tests/test_readme.py leaves its script to this file)."""
    return section("python-library.md", "## Python SDK")


def test_the_readme_sdk_script_runs_and_prints_what_the_readme_says(sdk, open_server):
    import os
    import re

    section = _readme_sdk_section()
    script = re.search(r"```python\n(.+?)\n```", section, re.S).group(1)
    shown = re.search(r"It prints `(.+?)`", section).group(1)
    root = Path(sdk.__file__).parent.parent
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                            env={**os.environ, "KIN_URL": open_server,
                                 "PYTHONPATH": os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")])})
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == shown


def test_the_readme_generate_command_is_the_one_this_test_runs():
    command = re.search(r"```sh\n(openapi-python-client generate .+?)\n```", _readme_sdk_section()).group(1)
    assert command.split()[:4] == ["openapi-python-client", "generate", "--path", "openapi/openapi.json"]
    assert "--meta none" in command and "--config openapi/client-config.yaml" in command
