"""The README's quick-start commands are the ones CI runs."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _quick_start_commands() -> list[str]:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```sh\n(.+?)\n```", section)


def test_quick_start_has_exactly_two_commands():
    commands = _quick_start_commands()
    assert len(commands) == 2, commands
    assert commands[0].endswith("python -m service")
    assert commands[1].endswith("python -m pytest")


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert _quick_start_commands()[1] in ci.splitlines()


def test_trajectories_example_answers_what_the_readme_shows(client):
    """The curl body of "### Trajectories" gives the second sample and summary printed below it (6 decimals)."""
    import json

    import numpy as np

    section = (ROOT / "README.md").read_text(encoding="utf-8").split("### Trajectories", 1)[1].split("\n### ", 1)[0]
    body = json.loads(re.search(r"-d '(\{.*?\})'\n```", section, re.S).group(1))
    shown = json.loads(re.search(r"```json\n(.+?)\n```", section, re.S).group(1))
    answer = client.post("/v1/robots/assur001_scara_rrp/ik/trajectory", json=body).json()
    sample, expected = answer["samples"][1], shown["samples"][0]
    for part in ("joints", "velocities", "accelerations"):
        np.testing.assert_allclose(sample[part], expected[part], atol=1e-6)
        np.testing.assert_allclose(sample["paper"][part], expected["paper"][part], atol=1e-6)
    assert sample["branch"] == expected["branch"] and sample["singularities"] == expected["singularities"]
    assert abs(sample["distance_to_singularity"] - expected["distance_to_singularity"]) < 1e-6
    np.testing.assert_allclose(answer["summary"]["largest_joint_step"]["values"],
                               shown["summary"]["largest_joint_step"]["values"], atol=1e-6)
    assert answer["solver"] == shown["solver"]
