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


def test_the_ur5_solution_counts_the_readme_states(client):
    """Inclusive bounds: a joint at exactly 0 within ±360° fits three ways, so the counts are not all 512."""
    import numpy as np

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    paragraph = readme.split("Bounds are inclusive, so a joint at", 1)[1].split("\n\n", 1)[0]
    stated = [int(n) for n in re.findall(r"\*\*(\d+)\*\*", paragraph)]
    configurations = [[0.1, -1.2, 1.0, 0.3, 1.5, 0.2], [0.1, -1.2, 1.0, 0.3, 1.5, 0.0],
                      [0.0, -1.2, 1.0, 0.3, 1.5, 0.2], [0.0] * 6]
    counted = []
    for q in configurations:
        matrix = client.post("/v1/robots/ur5/fk", json={"joints": q}).json()["pose"]["matrix"]
        answer = client.post("/v1/robots/ur5/ik", json={"target": {"matrix": matrix}}).json()
        assert answer["status"] == "ok" and not answer["truncated"]
        counted.append(len(answer["solutions"]))
        # independent count: the distinct branches (angles wrapped to (-π, π]), times, per joint, the number of
        # v + 2kπ inside the inclusive [-2π, 2π]
        branches: list[np.ndarray] = []
        for joints in np.array([s["joints"] for s in answer["solutions"]]):
            if not any(np.all(np.abs(np.angle(np.exp(1j * (joints - b)))) < 1e-6) for b in branches):
                branches.append(joints)
        branches = np.array(branches)
        fits = [sum(abs(v + 2 * k * np.pi) <= 2 * np.pi + 1e-9 for k in range(-2, 3)) for v in branches.ravel()]
        assert len(answer["solutions"]) == int(np.prod(np.reshape(fits, branches.shape), axis=1).sum())
    assert stated == counted


def test_the_core_library_example_runs():
    """"Use the core from Python" runs as written (the other Python blocks talk to a server): its asserts are the
    README's claims."""
    import contextlib
    import io

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("### Use the core from Python", 1)[1].split("\n### ", 1)[0]
    blocks = re.findall(r"```python\n(.+?)```", section, re.S)
    assert blocks, "the README shows the core's Python API"
    for block in blocks:
        with contextlib.redirect_stdout(io.StringIO()):
            exec(compile(block, "README.md", "exec"), {"__name__": "readme_example"})
