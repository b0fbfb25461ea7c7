"""The committed OpenAPI document is the app's, and keeps the contract's names."""

import json

from service.openapi import SPEC_PATH, current_spec

CONTRACT_OPERATIONS = {
    ("get", "/v1/robots"): "list_robots",
    ("get", "/v1/robots/{robot_id}"): "get_robot",
    ("post", "/v1/robots/{robot_id}/fk"): "forward_kinematics",
    ("post", "/v1/fk"): "forward_kinematics_inline",
    ("post", "/v1/robots/{robot_id}/fk/batch"): "forward_kinematics_batch",
    ("post", "/v1/robots/{robot_id}/ik"): "inverse_kinematics",
    ("post", "/v1/ik"): "inverse_kinematics_inline",
    ("post", "/v1/robots/{robot_id}/ik/batch"): "inverse_kinematics_batch",
    ("post", "/v1/robots/{robot_id}/limits"): "check_joint_limits",
    ("post", "/v1/limits"): "check_joint_limits_inline",
    ("post", "/v1/robots/{robot_id}/ik/trajectory"): "inverse_kinematics_trajectory",
    ("post", "/v1/ik/trajectory"): "inverse_kinematics_trajectory_inline",
    ("get", "/healthz"): "liveness",
    ("get", "/readyz"): "readiness",
}


def test_committed_spec_matches_the_app():
    committed = json.loads(SPEC_PATH.read_text(encoding="utf-8"))
    current = current_spec()
    assert committed == current, "openapi/openapi.json is stale: run `python -m service.openapi`"
    # the paths in the document's order (health, catalogue, FK, IK, limits, trajectories), whatever order the app
    # matches its routers in; dict equality above does not compare the order
    assert list(committed["paths"]) == list(current["paths"])
    assert list(current["paths"])[:4] == ["/healthz", "/readyz", "/v1/robots", "/v1/robots/{robot_id}"]


def test_contract_paths_and_operation_ids():
    paths = current_spec()["paths"]
    for (method, path), operation_id in CONTRACT_OPERATIONS.items():
        assert paths[path][method]["operationId"] == operation_id


def test_dh_schemas_declare_d_last():
    """Generated Python clients break unless `d` is the last property (api.md)."""
    schemas = current_spec()["components"]["schemas"]
    for name in ("DHJoint", "KhalilJoint"):
        assert list(schemas[name]["properties"])[-1] == "d"
        assert schemas[name]["additionalProperties"] is False


def test_orientation_variants_are_named_and_tagged():
    schemas = current_spec()["components"]["schemas"]
    for name, tag in [("MatrixOrientation", "matrix"), ("QuaternionOrientation", "quaternion"),
                      ("EulerZYZOrientation", "euler_zyz"), ("RPYOrientation", "rpy")]:
        assert schemas[name]["properties"]["type"]["const"] == tag


def test_trajectory_field_names_of_the_contract():
    """api.md, Trajectory IK: the request and per-sample response fields clients depend on."""
    schemas = current_spec()["components"]["schemas"]
    assert {"samples", "branch", "reference"} <= set(schemas["TrajectoryRequest"]["properties"])
    assert {"time", "pose", "twist", "acceleration"} <= set(schemas["TrajectorySample"]["properties"])
    assert set(schemas["Twist"]["properties"]) == {"linear", "angular"}
    assert set(schemas["Acceleration"]["properties"]) == {"linear", "angular"}
    assert {"time", "joints", "velocities", "accelerations", "branch", "branch_changed", "singularities"} <= set(
        schemas["TrajectorySampleResult"]["properties"])
    assert {"samples", "summary"} <= set(schemas["TrajectoryResponse"]["properties"])
