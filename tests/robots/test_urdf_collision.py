"""URDF ``<collision>`` elements on the real URDFs of example-robot-data and pybullet: every modelled shape lands
where the URDF puts it, checked against pybullet's own link frames.

The service turns each element into a shape on a core frame (the frame i of the body its link is fixed to). The
check here does not use that code: pybullet loads the same URDF and gives each link's frame at random joint values;
the element's ``<origin>``, read here with the standard library, places it on that frame; and the base frame of the
chain is taken out. The service's shape, carried by ``link_frames`` of its robot at the same joint values, must
be there to 1e-6 (pybullet answers link
frames in single precision). Mesh elements are replaced by boxes in the text both sides load (the service models no mesh),
so that every element of every link is checked, not only the URDFs' few primitives.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from importlib.metadata import distribution
from pathlib import Path

import numpy as np
import pytest

from service.kinematics import link_frames
from service.kinematics.collision import Box, Capsule, Sphere
from service.robots.build import robot_from_description, urdf_geometry_shown
from service.robots.schemas import URDFRobot

pybullet = pytest.importorskip("pybullet")

_ERD = "cmeel.prefix/share/example-robot-data/robots/"
#: name -> (distribution, path, base_link, tip_link)
URDFS = {
    "ur3": ("example-robot-data", _ERD + "ur_description/urdf/ur3_robot.urdf", "base_link", "tool0"),
    "ur5": ("example-robot-data", _ERD + "ur_description/urdf/ur5_robot.urdf", "base_link", "tool0"),
    "ur10": ("example-robot-data", _ERD + "ur_description/urdf/ur10_robot.urdf", "base_link", "tool0"),
    "ur5_gripper": ("example-robot-data", _ERD + "ur_description/urdf/ur5_gripper.urdf", "base_link", "tool0"),
    "panda": ("example-robot-data", _ERD + "panda_description/urdf/panda.urdf", "panda_link0", "panda_link8"),
    "panda_collision": ("example-robot-data", _ERD + "panda_description/urdf/panda_collision.urdf", "panda_link0",
                        "panda_link8"),
    "kinova_jaco2": ("example-robot-data", _ERD + "kinova_description/robots/kinova.urdf", "j2s6s200_link_base",
                     "j2s6s200_end_effector"),
    "xarm7": ("example-robot-data", _ERD + "xarm_description/urdf/xarm7.urdf", "link_base", "link_eef"),
    "z1": ("example-robot-data", _ERD + "z1_description/urdf/z1.urdf", "link00", "link06"),
    "so100": ("example-robot-data", _ERD + "so_arm_description/urdf/so100.urdf", "base", "gripper"),
    "so101": ("example-robot-data", _ERD + "so_arm_description/urdf/so101.urdf", "base_link", "gripper_frame_link"),
    "iiwa14": ("pybullet", "pybullet_data/kuka_iiwa/model.urdf", "lbr_iiwa_link_0", "lbr_iiwa_link_7"),
}
#: pybullet answers link frames to single precision (errors up to 2.3e-7 seen); a shape on a wrong frame or link is
#: off by millimetres at least.
TOLERANCE = 1e-6
MESH_AS_BOX = '<box size="0.011 0.023 0.037"/>'


def _text(name: str) -> str:
    dist, path, _, _ = URDFS[name]
    return Path(distribution(dist).locate_file(path)).read_text(encoding="utf-8")


def _without_meshes(text: str) -> str:
    """The URDF with its visuals dropped and every collision mesh a small box (same origin)."""
    text = re.sub(r"<visual\b.*?</visual>", "", text, flags=re.S)
    return re.sub(r"<mesh\b[^>]*/>", MESH_AS_BOX, text)


def _rpy(values: list[float]) -> np.ndarray:
    r, p, y = values
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def _pose(position, quaternion_xyzw) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = np.array(pybullet.getMatrixFromQuaternion(quaternion_xyzw)).reshape(3, 3)
    T[:3, 3] = position
    return T


class _Bullet:
    """pybullet's view of a URDF: link frames (the URDF's own, not the inertial ones) at given joint values."""

    def __init__(self, path: Path):
        self.client = pybullet.connect(pybullet.DIRECT)
        self.body = pybullet.loadURDF(str(path), useFixedBase=True, physicsClientId=self.client)
        self.joints, self.link_index = {}, {}
        for j in range(pybullet.getNumJoints(self.body, physicsClientId=self.client)):
            info = pybullet.getJointInfo(self.body, j, physicsClientId=self.client)
            self.joints[info[1].decode()] = (j, info[2])
            self.link_index[info[12].decode()] = j
        self.root = pybullet.getBodyInfo(self.body, physicsClientId=self.client)[0].decode()

    def set(self, values: dict[str, float]) -> None:
        for name, (index, kind) in self.joints.items():
            if kind != pybullet.JOINT_FIXED:
                pybullet.resetJointState(self.body, index, values.get(name, 0.0), physicsClientId=self.client)

    def world_T_link(self, link: str) -> np.ndarray:
        if link == self.root:
            position, orientation = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
            inertial = pybullet.getDynamicsInfo(self.body, -1, physicsClientId=self.client)
            world_T_com = _pose(position, orientation)
            link_T_com = _pose(inertial[3], inertial[4])
            return world_T_com @ np.linalg.inv(link_T_com)
        state = pybullet.getLinkState(self.body, self.link_index[link], computeForwardKinematics=True,
                                      physicsClientId=self.client)
        return _pose(state[4], state[5])

    def close(self) -> None:
        pybullet.disconnect(self.client)


def _elements(text: str) -> list[tuple[str, np.ndarray, ET.Element]]:
    """(link, link_T_element, geometry) of every collision element, in document order."""
    found = []
    for link in ET.fromstring(text).findall("link"):
        for element in link.findall("collision"):
            origin = element.find("origin")
            T = np.eye(4)
            if origin is not None:
                T[:3, 3] = [float(v) for v in origin.get("xyz", "0 0 0").split()]
                T[:3, :3] = _rpy([float(v) for v in origin.get("rpy", "0 0 0").split()])
            found.append((link.get("name"), T, element.find("geometry")[0]))
    return found


@pytest.mark.parametrize("name", sorted(URDFS))
def test_urdf_collision_shapes_land_where_pybullet_puts_the_urdf_elements(name, tmp_path):
    _, _, base, tip = URDFS[name]
    text = _without_meshes(_text(name))
    path = tmp_path / f"{name}.urdf"
    path.write_text(text, encoding="utf-8")
    robot = robot_from_description(URDFRobot(format="urdf", urdf=text, base_link=base, tip_link=tip), max_joints=32)
    bullet = _Bullet(path)
    try:
        chain = robot.joint_names
        # Which links the chain carries: those that stay put in the base frame when every joint off the chain moves.
        rng = np.random.default_rng(11)
        elements = _elements(text)
        bullet.set({})
        still = {link: np.linalg.inv(bullet.world_T_link(base)) @ bullet.world_T_link(link)
                 for link, _, _ in elements}
        bullet.set({joint: rng.uniform(-0.5, 0.5) for joint in bullet.joints if joint not in chain})
        carried = [(link, T, geometry) for link, T, geometry in elements
                   if np.allclose(np.linalg.inv(bullet.world_T_link(base)) @ bullet.world_T_link(link), still[link],
                                  atol=1e-12)]
        assert len(robot.collision) == len(carried) > 0
        assert [shape.name for shape in robot.collision] == [link for link, _, _ in carried]
        for _ in range(5):
            q = rng.uniform(-math.pi, math.pi, robot.dof)
            bullet.set(dict(zip(chain, q)))
            base_T_world = np.linalg.inv(bullet.world_T_link(base))
            frames = link_frames(robot.with_frames(np.eye(4), np.eye(4)), q)
            for shape, (link, link_T_element, geometry) in zip(robot.collision, carried):
                expected = base_T_world @ bullet.world_T_link(link) @ link_T_element  # the element's own frame
                frame = frames[shape.link]
                if geometry.tag == "cylinder":  # its bounding capsule: the axis segment, the radius
                    half = float(geometry.get("length")) / 2
                    assert isinstance(shape.shape, Capsule)
                    for end, sign in ((shape.shape.start, -1), (shape.shape.end, 1)):
                        np.testing.assert_allclose(frame[:3, :3] @ end + frame[:3, 3],
                                                   expected[:3, 3] + sign * half * expected[:3, 2], atol=TOLERANCE)
                    assert shape.shape.radius == float(geometry.get("radius"))
                    continue
                assert isinstance(shape.shape, Box if geometry.tag == "box" else Sphere), geometry.tag
                np.testing.assert_allclose(frame[:3, :3] @ shape.shape.center + frame[:3, 3], expected[:3, 3],
                                           atol=TOLERANCE)
                if geometry.tag == "box":
                    np.testing.assert_allclose(frame[:3, :3] @ shape.shape.rotation, expected[:3, :3],
                                               atol=TOLERANCE)
                    np.testing.assert_allclose(shape.shape.size, [float(v) for v in geometry.get("size").split()])
    finally:
        bullet.close()


def test_meshes_and_links_off_the_chain_are_named_in_the_notes():
    shown = urdf_geometry_shown(URDFRobot(format="urdf", urdf=_text("panda"), base_link="panda_link0",
                                          tip_link="panda_link8", notes="Franka's arm."))
    assert shown.notes.startswith("Franka's arm. Collision meshes are not modelled: panda_link0 (")
    assert "link1.stl" in shown.notes and "panda_leftfinger, panda_rightfinger" in shown.notes
    assert shown.collision == []  # its only primitives are the fingers' boxes
    shown = urdf_geometry_shown(URDFRobot(format="urdf", urdf=_text("z1"), base_link="link00", tip_link="link06"))
    assert [entry.link for entry in shown.collision] == ["link00", "link02", "link02", "link02", "link03", "link03",
                                                         "link04", "link06"]
    assert "gripperStator" in shown.notes and "gripperMover" in shown.notes
