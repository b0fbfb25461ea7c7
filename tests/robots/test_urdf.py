"""URDF input: the catalogue's URDF arms against their source files, chain errors, hostile XML.

The source files are read from the installed packages of the ``test`` extra (example-robot-data, pybullet), and
their FK is computed here, independently of the service: parse with the standard library, walk the chain from
base_link to tip_link, and multiply origin (xyz, rpy) and joint motion (Rodrigues about the axis, or a slide along
it) in numpy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml

from service.config import BUILTIN_ROBOTS_DIR
from tests.arms import URDF_SOURCES, source_urdf
from tests.conftest import assert_problem
from tests.oracles.rotations import axis_angle, rpy


def _numbers(element, attribute: str, default: str) -> np.ndarray:
    text = default if element is None else element.get(attribute, default)
    return np.array([float(v) for v in text.split()])


def _source_chain(text: str, base: str, tip: str) -> list:
    joints = {j.find("child").get("link"): j for j in ET.fromstring(text).findall("joint")}
    chain, link = [], tip
    while link != base:
        chain.append(joints[link])
        link = joints[link].find("parent").get("link")
    return chain[::-1]


def _source_fk(chain: list, q: np.ndarray) -> np.ndarray:
    """base_T_tip of a URDF chain at q, straight from its joint origins (independent of service/robots/urdf.py)."""
    T, i = np.eye(4), 0
    for joint in chain:
        origin = joint.find("origin")
        roll, pitch, yaw = _numbers(origin, "rpy", "0 0 0")
        step = np.eye(4)
        step[:3, :3] = rpy(roll, pitch, yaw)
        step[:3, 3] = _numbers(origin, "xyz", "0 0 0")
        T = T @ step
        kind = joint.get("type")
        if kind == "fixed":
            continue
        axis = _numbers(joint.find("axis"), "xyz", "1 0 0")
        motion = np.eye(4)
        if kind == "prismatic":
            motion[:3, 3] = axis / np.linalg.norm(axis) * q[i]
        else:
            motion[:3, :3] = axis_angle(axis / np.linalg.norm(axis), q[i])
        T = T @ motion
        i += 1
    return T


@pytest.mark.parametrize("robot_id", sorted(URDF_SOURCES))
def test_catalogue_urdf_arms_match_their_source_files(client, robot_id):
    sidecar = yaml.safe_load((BUILTIN_ROBOTS_DIR / f"{robot_id}.urdf.yaml").read_text(encoding="utf-8"))
    assert sidecar["source"] and sidecar["licence"]
    chain = _source_chain(source_urdf(robot_id), sidecar["base_link"], sidecar["tip_link"])
    moving = [j for j in chain if j.get("type") != "fixed"]
    robot = client.get(f"/v1/robots/{robot_id}").json()
    summary = next(r for r in client.get("/v1/robots").json()["robots"] if r["id"] == robot_id)
    assert summary["joint_names"] == [j.get("name") for j in moving]
    assert summary["licence"] == sidecar["licence"] and robot["licence"] == sidecar["licence"]
    assert "<mesh" not in robot["urdf"] and "<visual" not in robot["urdf"]
    rng = np.random.default_rng(3)
    rows = rng.uniform(-math.pi, math.pi, (50, len(moving)))
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": rows.tolist()}).json()["poses"]
    for q, pose in zip(rows, poses):
        np.testing.assert_allclose(pose["matrix"], _source_fk(chain, q), atol=1e-12, rtol=0)
    # the vendor limits of the source file, continuous joints unlimited
    check = client.post(f"/v1/robots/{robot_id}/limits", json={"joints": rows.tolist()}).json()["results"]
    for q, result in zip(rows, check):
        outside = set()
        for index, joint in enumerate(moving):
            limit = joint.find("limit")
            if joint.get("type") != "continuous" and limit is not None:
                if not float(limit.get("lower")) - 1e-9 <= q[index] <= float(limit.get("upper")) + 1e-9:
                    outside.add(index)
        assert {v["joint"] for v in result["violations"]} == outside


def test_the_catalogue_has_the_arms_of_the_issue(client):
    ids = {r["id"] for r in client.get("/v1/robots").json()["robots"]}
    assert {"ur3e", "ur5e", "ur10e", "ur16e", "franka_panda", "kuka_iiwa14", "kinova_jaco2", "unitree_z1",
            "so101", "ufactory_xarm7", "kuka_kr6_r900_2", "kuka_kr210_r2700", "abb_irb120", "ufactory_xarm6",
            "ufactory_lite6", "fanuc_lrmate200id", "abb_irb6700"} <= ids
    for robot_id in ids:
        description = client.get(f"/v1/robots/{robot_id}").json()
        assert description["source"], robot_id


def test_posting_a_real_urdf_returns_every_ik_solution(client):
    """The README's example: the Jaco2 URDF inline (meshes and all), a pose from its own FK, all 8+ solutions."""
    text = source_urdf("kinova_jaco2")
    robot = {"format": "urdf", "urdf": text, "base_link": "j2s6s200_link_base", "tip_link": "j2s6s200_end_effector"}
    q = [0.4, 2.6, 1.2, -0.7, 1.4, 0.2]
    fk = client.post("/v1/fk", json={"robot": robot, "joints": q}).json()
    assert fk["joint_names"][0] == "j2s6s200_joint_1"
    answer = client.post("/v1/ik", json={"robot": robot, "target": {"matrix": fk["pose"]["matrix"]},
                                         "filter_limits": False}).json()
    assert answer["solver"]["method"] == "analytic" and answer["solver"]["complete"]
    assert any(np.allclose(s["joints"], q, atol=1e-8) for s in answer["solutions"])
    for solution in answer["solutions"]:
        assert solution["residual"]["position"] < 1e-9


def _urdf(joints: str, links: str = "") -> str:
    names = links or "".join(f'<link name="l{i}"/>' for i in range(4))
    return f'<robot name="t">{names}{joints}</robot>'


def _joint(name: str, parent: str, child: str, kind: str = "revolute", extra: str = "") -> str:
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>{extra}</joint>')


def _post_fk(client, urdf: str, joints=None, **robot):
    body = {"robot": {"format": "urdf", "urdf": urdf, **robot}, "joints": joints if joints is not None else [0, 0, 0]}
    return client.post("/v1/fk", json=body)


CHAIN_JOINTS = _joint("j1", "l0", "l1") + _joint("j2", "l1", "l2", "prismatic", '<limit lower="0" upper="0.5"/>') \
    + _joint("j3", "l2", "l3", "continuous")
CHAIN = _urdf(CHAIN_JOINTS)


def test_a_single_chain_needs_no_base_or_tip_and_fixed_joints_fold(client):
    response = _post_fk(client, CHAIN, [0.5, 0.2, 0.1])
    assert response.status_code == 200, response.text
    assert response.json()["pose"]["position"] == pytest.approx([0, 0, 0.5])
    folded = CHAIN.replace(_joint("j3", "l2", "l3", "continuous"), _joint("f", "l2", "l3", "fixed"))
    assert _post_fk(client, folded, [0.5, 0.2]).json()["joint_names"] == ["j1", "j2"]
    limits = client.post("/v1/limits", json={"robot": {"format": "urdf", "urdf": CHAIN}, "joints": [[9, 0.6, 99]]})
    assert [v["joint"] for v in limits.json()["results"][0]["violations"]] == [1]  # j1 unlimited (no <limit>)


@pytest.mark.parametrize("urdf, robot, loc, match", [
    (CHAIN.replace('type="continuous">', 'type="continuous"><mimic joint="j1"/>'), {}, ["urdf", "joint", "j3"],
     "mimic"),
    (CHAIN.replace('type="continuous"', 'type="floating"'), {}, ["urdf", "joint", "j3"], "floating"),
    (CHAIN.replace('child link="l3"', 'child link="nowhere"'), {}, ["urdf", "joint", "j3"], "'nowhere'"),
    (CHAIN, {"tip_link": "l9"}, ["tip_link"], "'l9'"),
    (CHAIN, {"base_link": "l2", "tip_link": "l1"}, ["tip_link"], "does not connect"),
    (_urdf(CHAIN_JOINTS + _joint("j4", "l2", "l1")), {}, ["urdf", "joint", "j4"], "two parent joints"),
    (_urdf(_joint("j1", "l0", "l1") + _joint("j2", "l0", "l2"), '<link name="l0"/><link name="l1"/><link name="l2"/>'),
     {}, ["tip_link"], "leaves"),
    (_urdf(_joint("j1", "l0", "l1") + _joint("j2", "l2", "l3")), {}, ["urdf"], "separate trees"),
    ('<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x"><xacro:macro name="m"/></robot>', {}, ["urdf"],
     "xacro is out of scope"),
    ("<robot name='t'><link name='a'>", {}, ["urdf"], "not well-formed"),
    ("<sdf version='1.6'/>", {}, ["urdf"], "<robot>"),
])
def test_chain_errors_are_422_naming_the_joint_or_link(client, urdf, robot, loc, match):
    body = assert_problem(_post_fk(client, urdf, **robot), 422, loc=["body", "robot", *loc])
    assert match in body["detail"], body["detail"]


BILLION_LAUGHS = ('<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
                  + "".join(f'<!ENTITY lol{i} "{("&lol" + (str(i - 1) if i > 1 else "") + ";") * 10}">'
                            for i in range(1, 10))
                  + ']><robot name="&lol9;"><link name="a"/></robot>')
EXTERNAL_ENTITY = ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
                   '<robot name="&x;"><link name="a"/></robot>')
EXTERNAL_DTD = '<?xml version="1.0"?><!DOCTYPE robot SYSTEM "http://example.invalid/robot.dtd"><robot name="r"/>'
PLAIN_DTD = '<?xml version="1.0"?><!DOCTYPE robot [<!ELEMENT robot ANY>]><robot name="r"/>'
PARAMETER_ENTITY = ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY % p SYSTEM "file:///etc/passwd"> %p;]>'
                    '<robot name="r"/>')


@pytest.mark.parametrize("urdf", [BILLION_LAUGHS, EXTERNAL_ENTITY, EXTERNAL_DTD, PLAIN_DTD, PARAMETER_ENTITY],
                         ids=["billion-laughs", "external-entity", "external-dtd", "dtd", "parameter-entity"])
def test_hostile_xml_is_refused_and_the_server_stays_up(client, urdf):
    body = assert_problem(_post_fk(client, urdf), 422, loc=["body", "robot", "urdf"])
    assert "refused" in body["detail"] or "well-formed" in body["detail"], body["detail"]
    assert "root:" not in body["detail"]  # nothing of /etc/passwd comes back
    assert client.get("/healthz").status_code == 200
    assert client.post("/v1/robots/ur5/fk", json={"joints": [0] * 6}).status_code == 200


def test_huge_and_deeply_nested_documents_get_a_4xx(client):
    huge = _urdf(CHAIN_JOINTS + "<!--" + "x" * 1_100_000 + "-->")
    response = _post_fk(client, huge)
    assert 400 <= response.status_code < 500 and response.status_code in (413, 422), response.status_code
    deep = '<robot name="d">' + "<a>" * 200_000 + "</a>" * 200_000 + "</robot>"
    response = _post_fk(client, deep)
    assert 400 <= response.status_code < 500, response.status_code
    assert client.post("/v1/robots/ur5/fk", json={"joints": [0] * 6}).status_code == 200


def test_catalogue_urdf_needs_a_sidecar_with_source_and_licence(tmp_path):
    from service.robots.catalogue import CatalogueError, load_catalogue

    (tmp_path / "arm.urdf").write_text(CHAIN, encoding="utf-8")
    with pytest.raises(CatalogueError, match="sidecar"):
        load_catalogue([tmp_path], max_joints=32)
    (tmp_path / "arm.urdf.yaml").write_text("source: a test\n", encoding="utf-8")
    with pytest.raises(CatalogueError, match="licence"):
        load_catalogue([tmp_path], max_joints=32)
    (tmp_path / "arm.urdf.yaml").write_text("source: a test\nlicence: CC0-1.0\ntip_link: l3\n", encoding="utf-8")
    entry = load_catalogue([tmp_path], max_joints=32).get("arm")
    assert entry.robot.joint_names == ["j1", "j2", "j3"] and entry.description.licence == "CC0-1.0"
    (tmp_path / "arm.urdf").write_text(BILLION_LAUGHS, encoding="utf-8")
    with pytest.raises(CatalogueError, match="refused"):
        load_catalogue([tmp_path], max_joints=32)


def test_a_live_server_survives_hostile_urdfs():
    """Over real HTTP: every hostile document is a 4xx, and the same process answers /healthz and FK after them."""
    import httpx

    from tests.live import serve

    hostile = [BILLION_LAUGHS, EXTERNAL_ENTITY, PARAMETER_ENTITY,
               '<robot name="d">' + "<a>" * 200_000 + "</a>" * 200_000 + "</robot>"]
    with serve() as base_url, httpx.Client(base_url=base_url, timeout=30) as http:
        for urdf in hostile:
            response = http.post("/v1/fk", json={"robot": {"format": "urdf", "urdf": urdf}, "joints": [0]})
            assert 400 <= response.status_code < 500, response.text[:200]
        assert http.get("/healthz").status_code == 200
        assert http.post("/v1/robots/ur5e/fk", json={"joints": [0] * 6}).status_code == 200
