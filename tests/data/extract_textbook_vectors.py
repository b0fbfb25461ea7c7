"""Regenerate textbook_fk_vectors.json from section 8 of the shared textbook.

Usage, from the repository root::

    python tests/data/extract_textbook_vectors.py            # rewrite the JSON
    python tests/data/extract_textbook_vectors.py --check    # exit 1 if it is stale
    python tests/data/extract_textbook_vectors.py --textbook PATH

By default the textbook is ``../shared/textbook.md`` relative to the repository
root (the layout of the project checkout and of CI).

What the script does:

* reads every ``#### <name>`` block of "## 8. FK test vectors": a line
  ``q = (...)`` followed by a fenced 4x4 matrix, three per robot;
* maps the textbook's names to catalogue robot ids (``TEXTBOOK_NAME_TO_IDS``;
  an unknown name is an error, so a new robot in the textbook is not dropped
  silently). ``craig_puma560_modified_DH`` feeds both ``puma560_modified`` and
  ``puma560_khalil``, whose frames and joint angles are the same;
* converts joint vectors to the catalogue's joint variables. Only the Assur
  SCARA needs it: §8 gives (theta1, theta2_paper, l3), and the catalogue's DH
  variable is q2 = -theta2_paper (textbook.md §4.1);
* replaces a printed joint value by the exact angle it stands for when it is
  within 1e-9 of one of pi/2, pi/4, -pi/3, pi/6, -pi/4 (the §8 text says the
  third vector of each robot uses these exact values).

The matrix entries are kept exactly as printed (6 significant digits), so a
consumer must compare with a tolerance: 5e-6 absolute for robots in metres,
5e-6 * max(1, |value|) for the Assur SCARA in millimetres.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_TEXTBOOK = REPO_ROOT.parent / "shared" / "textbook.md"
OUTPUT = Path(__file__).resolve().with_name("textbook_fk_vectors.json")

#: §8 heading -> catalogue robot ids that take its vectors.
TEXTBOOK_NAME_TO_IDS: dict[str, tuple[str, ...]] = {
    "spong_ex3_1_planar_RR": ("spong_ex3_1_planar_rr",),
    "spong_ex3_2_cylindrical_RPP": ("spong_ex3_2_cylindrical_rpp",),
    "spong_ex3_3_spherical_wrist_RRR": ("spong_ex3_3_spherical_wrist_rrr",),
    "spong_ex3_4_cylindrical_with_wrist": ("spong_ex3_4_cylindrical_with_wrist",),
    "spong_ex3_5_stanford_RRPRRR": ("spong_ex3_5_stanford",),
    "spong_ex3_6_scara_RRPR": ("spong_ex3_6_scara_rrpr",),
    "spong_ex4_3_elbow_with_wrist_RRRRRR": ("spong_ex4_3_elbow_with_wrist",),
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": (
        "spong_sec4_3_elbow_shoulder_offset_with_wrist",
    ),
    "spong_sec4_3_spherical_arm_RRP": ("spong_sec4_3_spherical_arm_rrp",),
    "spong_sec4_3_spherical_arm_table3_4_frames": (
        "spong_sec4_3_spherical_arm_table3_4_frames",
    ),
    "ex004_1_PRP": ("ex004_1_prp",),
    "ex004_2_polar_RRP": ("ex004_2_polar_rrp",),
    "ex004_3_spherical_RRPR": ("ex004_3_spherical_rrpr",),
    "ex004_4_polar_offset_RRP": ("ex004_4_polar_offset_rrp",),
    "craig_puma560_modified_DH": ("puma560_modified", "puma560_khalil"),
    "assur001_scara_RRP": ("assur001_scara_rrp",),
}

#: Catalogue id -> function mapping the textbook's joint vector to the catalogue's.
JOINT_CONVERSIONS = {
    # q2_DH = -theta2_paper (textbook.md §4.1).
    "assur001_scara_rrp": lambda q: [q[0], -q[1], q[2]],
}

EXACT_ANGLES = (math.pi / 2, math.pi / 4, -math.pi / 3, math.pi / 6, -math.pi / 4)
SNAP_TOLERANCE = 1e-9

_SECTION = re.compile(r"^## 8\..*?$(.*?)^## 9\.", re.S | re.M)
_BLOCK = re.compile(r"^#### (\S+)\s*$(.*?)(?=^#### |\Z)", re.S | re.M)
_VECTOR = re.compile(r"^q = \(([^)]*)\)\s*```\s*(.*?)```", re.S | re.M)
_ROW = re.compile(r"\[([^\]]*)\]")


def _snap(value: float) -> float:
    """Return the exact angle a printed joint value stands for, or the value itself."""
    for exact in EXACT_ANGLES:
        if abs(value - exact) < SNAP_TOLERANCE:
            return exact
    return value


def _normalise_zero(value: float) -> float:
    """Turn a printed -0 into 0 so the JSON reads cleanly."""
    return 0.0 if value == 0 else value


def parse_section8(markdown: str) -> dict[str, list[dict]]:
    """Parse §8 of the textbook into {textbook name: [{"joints", "matrix"}, ...]}.

    joints: list of floats (rad or length), matrix: 4x4 list of floats as printed.
    Raises ValueError when the section or a block does not have the expected shape.
    """
    section = _SECTION.search(markdown)
    if section is None:
        raise ValueError("section '## 8.' ... '## 9.' not found in the textbook")
    parsed: dict[str, list[dict]] = {}
    for name, body in _BLOCK.findall(section.group(1)):
        vectors = []
        for joints_text, matrix_text in _VECTOR.findall(body):
            joints = [_snap(float(x)) for x in joints_text.split(",")]
            rows = [
                [_normalise_zero(float(x)) for x in row.split(",")]
                for row in _ROW.findall(matrix_text)
            ]
            if len(rows) != 4 or any(len(row) != 4 for row in rows):
                raise ValueError(f"{name}: a matrix is not 4x4: {matrix_text!r}")
            if rows[3] != [0.0, 0.0, 0.0, 1.0]:
                raise ValueError(f"{name}: last matrix row is not (0, 0, 0, 1)")
            vectors.append({"joints": joints, "matrix": rows})
        if len(vectors) != 3:
            raise ValueError(f"{name}: expected 3 vectors, found {len(vectors)}")
        parsed[name] = vectors
    return parsed


def catalogue_vectors(markdown: str) -> dict[str, list[dict]]:
    """Return {catalogue robot id: [{"joints", "matrix"}, ...]} from the textbook text."""
    parsed = parse_section8(markdown)
    unknown = sorted(set(parsed) - set(TEXTBOOK_NAME_TO_IDS))
    missing = sorted(set(TEXTBOOK_NAME_TO_IDS) - set(parsed))
    if unknown or missing:
        raise ValueError(f"§8 names not mapped: {unknown}; mapped names not in §8: {missing}")
    result: dict[str, list[dict]] = {}
    for name, vectors in parsed.items():
        for robot_id in TEXTBOOK_NAME_TO_IDS[name]:
            convert = JOINT_CONVERSIONS.get(robot_id, list)
            result[robot_id] = [
                {"joints": convert(v["joints"]), "matrix": v["matrix"]} for v in vectors
            ]
    return dict(sorted(result.items()))


def to_json(vectors: dict[str, list[dict]]) -> str:
    """Serialise with one matrix row per line, so diffs stay readable."""
    lines = ["{"]
    robot_ids = list(vectors)
    for i, robot_id in enumerate(robot_ids):
        lines.append(f"  {json.dumps(robot_id)}: [")
        entries = vectors[robot_id]
        for j, entry in enumerate(entries):
            rows = ",\n".join(f"      {json.dumps(row)}" for row in entry["matrix"])
            lines.append("    {")
            lines.append(f'     "joints": {json.dumps(entry["joints"])},')
            lines.append('     "matrix": [')
            lines.append(rows)
            lines.append("     ]")
            lines.append("    }" + ("," if j < len(entries) - 1 else ""))
        lines.append("  ]" + ("," if i < len(robot_ids) - 1 else ""))
    lines.append("}")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--textbook", type=Path, default=DEFAULT_TEXTBOOK)
    parser.add_argument("--output", type=Path, default=OUTPUT)
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    args = parser.parse_args(argv)

    text = to_json(catalogue_vectors(args.textbook.read_text(encoding="utf-8")))
    if args.check:
        current = args.output.read_text(encoding="utf-8") if args.output.exists() else ""
        if current != text:
            print(f"{args.output} is out of date; rerun without --check", file=sys.stderr)
            return 1
        print(f"{args.output} is up to date")
        return 0
    args.output.write_text(text, encoding="utf-8")
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
