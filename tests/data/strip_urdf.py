"""Write a catalogue URDF (robots/<id>.urdf): the kinematic tree of a source URDF, without meshes or visuals.

Kept: every ``<link name>`` and every ``<joint>`` with its ``parent``, ``child``, ``origin``, ``axis``, ``limit``
and ``mimic``, attribute values as the source states them. Dropped: visuals, collisions, inertias, transmissions,
gazebo blocks, materials and comments. A header comment names the source file and its licence; the sidecar
(robots/<id>.urdf.yaml) is written by hand.

    python tests/data/strip_urdf.py SOURCE.urdf robots/ID.urdf --source "..." --licence "..."
"""

from __future__ import annotations

import argparse
import xml.etree.ElementTree as ET
from pathlib import Path

_JOINT_CHILDREN = ("parent", "child", "origin", "axis", "limit", "mimic")


def stripped(source_text: str, header: str) -> str:
    root = ET.fromstring(source_text)
    lines = ['<?xml version="1.0"?>', f"<!-- {header} -->", f'<robot name="{root.get("name", "")}">']
    for link in root.findall("link"):
        lines.append(f'  <link name="{link.get("name")}"/>')
    for joint in root.findall("joint"):
        lines.append(f'  <joint name="{joint.get("name")}" type="{joint.get("type")}">')
        for tag in _JOINT_CHILDREN:
            element = joint.find(tag)
            if element is not None:
                attributes = " ".join(f'{key}="{value}"' for key, value in element.attrib.items())
                lines.append(f"    <{tag} {attributes}/>")
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source", type=Path)
    parser.add_argument("target", type=Path)
    parser.add_argument("--source-name", required=True, help="where the source file comes from")
    parser.add_argument("--licence", required=True)
    args = parser.parse_args()
    header = (f"Kinematics only (links, joints, origins, axes, limits) of {args.source_name}; licence "
              f"{args.licence}. Meshes, visuals, collisions and inertias removed by tests/data/strip_urdf.py.")
    args.target.write_text(stripped(args.source.read_text(encoding="utf-8"), header.replace("--", "-")),
                           encoding="utf-8")


if __name__ == "__main__":
    main()
