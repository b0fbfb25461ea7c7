"""The README and the docs/ pages stay true: the quick-start commands are the ones CI runs, every page is linked,
every Python block runs, every curl request is answered as its comment says, every JSON and YAML example is valid."""

import contextlib
import io
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.doc_pages import DOCS, README, ROOT, Block, blocks, pages, section, text
from tests.ik_helpers import angle_gap


def _quick_start_commands() -> list[str]:
    return re.findall(r"```sh\n(.+?)\n```", section(README, "## Quick start"))


def test_quick_start_has_exactly_two_commands():
    commands = _quick_start_commands()
    assert len(commands) == 2, commands
    assert commands[0].endswith("python -m service")
    assert commands[1].endswith("python -m pytest")


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert _quick_start_commands()[1] in ci.splitlines()


def test_the_readme_is_a_front_door_that_links_every_docs_page():
    readme = text(README)
    assert readme.count("\n") < 300
    for page in sorted(DOCS.glob("*.md")):
        assert f"](docs/{page.name})" in readme, f"docs/{page.name} is not linked from the README"


def _anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    without_code = re.sub(r"^```.*?^```", "", text(page), flags=re.M | re.S)
    return {_anchor(h) for h in re.findall(r"^#+ (.+)$", without_code, re.M)}


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.name)
def test_every_relative_link_leads_to_a_file_and_heading_that_exist(page):
    for target in re.findall(r"\]\(([^)\s]+)\)", text(page)):
        if re.match(r"[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        linked = (page.parent / path).resolve() if path else page
        assert linked.exists(), f"{page.name} links {target}, which does not exist"
        if anchor:
            assert anchor in _anchors(linked), f"{page.name} links {target}, a heading that does not exist"


# --------------------------------------------------------------------------------------------- Python blocks

def _sdk_script() -> str:
    """The SDK script, which tests/test_sdk.py runs against a live server with a generated client."""
    return re.search(r"```python\n(.+?)\n```", section("python-library.md", "## Python SDK"), re.S).group(1)


@pytest.mark.parametrize("block", blocks("python"), ids=lambda b: b.where)
def test_every_python_example_runs(block: Block, client, monkeypatch):
    """Each block runs as written; its HTTP calls (httpx to localhost:8000) go to the application in process.
    The generated-SDK script needs the generator and a live server: tests/test_sdk.py runs that one."""
    if "kinematics_client" in block.body:
        assert block.body.strip() == _sdk_script().strip()
        return
    import httpx

    monkeypatch.setattr(httpx, "post", lambda url, **kwargs: client.post(url, **kwargs))
    monkeypatch.setattr(httpx, "get", lambda url, **kwargs: client.get(url, **kwargs))
    namespace = {"__name__": "docs_example"}
    with contextlib.redirect_stdout(io.StringIO()):
        exec(compile(block.body, block.where, "exec"), namespace)
    if "ik = httpx.post" in block.body:  # the URDF example: what its comment says of the answer
        solved = namespace["ik"]
        assert solved["status"] == "ok" and solved["solver"]["structure"] == "three_parallel"
        assert solved["solver"]["complete"] and len(solved["solutions"]) == 256
        np.testing.assert_allclose(namespace["pose"]["position"], [0.5631, 0.319656, 0.329824], atol=5e-7)


def test_the_core_library_page_shows_the_core():
    assert re.findall(r"```python\n(.+?)```", section("python-library.md", "## Use the core from Python"), re.S)


# ----------------------------------------------------------------------------------------------- curl blocks

CURL_BLOCKS = [b for b in blocks("sh") if re.search(r"^curl ", b.body, re.M)]


def _calls_of(block: Block, tmp_path: Path) -> list[list[str]]:
    """The argument lists of the block's curl commands, as bash expands them (curl replaced by a recorder; the
    block runs in a scratch directory that sees the repository's tests/, so redirections land there)."""
    log = tmp_path / "curl.log"
    (tmp_path / "tests").symlink_to(ROOT / "tests")
    recorder = (f'curl() {{ "{sys.executable}" -c "import json, sys; print(json.dumps(sys.argv[1:]))" "$@" '
                f'>> "{log}"; }}\nset -euo pipefail\n')
    subprocess.run(["bash", "-c", recorder + block.body], cwd=tmp_path, check=True, timeout=60)
    return [json.loads(line) for line in log.read_text(encoding="utf-8").splitlines()]


def _comments_of(block: Block) -> list[str]:
    """For each curl command in the block, the comment lines after it (joined), the claims about its answer."""
    claims: list[str] = []
    for line in block.body.splitlines():
        if line.startswith("curl "):
            claims.append("")
        elif line.startswith("#") and claims:
            claims[-1] += " " + line.lstrip("#").strip().lstrip("→").strip()
    return claims


def _request(arguments: list[str]) -> tuple[str, str, dict, str | None]:
    """method, path and query, headers and body of a curl argument list (the flags these pages use)."""
    headers, data, url, rest = {}, None, None, iter(arguments)
    for argument in rest:
        if argument == "-H":
            name, _, value = next(rest).partition(":")
            headers[name.strip()] = value.strip()
        elif argument == "-d":
            data = next(rest)
        elif argument in ("-s", "-sS"):
            continue
        else:
            assert not argument.startswith("-"), f"unexpected curl flag {argument}"
            url = argument
    assert url and url.startswith("localhost:8000/"), url
    return ("POST" if data is not None else "GET"), url[len("localhost:8000"):], headers, data


#: Keys whose documented values the answers must have (the first occurrence in the answer, depth first).
CLAIMED_KEYS = ("status", "method", "structure", "complete", "free_joints", "trimmed", "position",
                "quaternion_wxyz", "equivalent", "within_limits", "detail", "clearance")


def _first(answer, key):
    if isinstance(answer, dict):
        if key in answer:
            return answer[key]
        children = answer.values()
    elif isinstance(answer, list):
        children = answer
    else:
        return None
    for child in children:
        found = _first(child, key)
        if found is not None:
            return found
    return None


def _same_as_shown(actual, shown_text: str) -> bool:
    """The answer's value equals the documented one, numbers to the decimals shown."""
    shown = json.loads(shown_text)
    if isinstance(shown, (bool, str)) or shown is None:
        return actual == shown
    numbers = re.findall(r"-?\d+(?:\.(\d+))?", shown_text)
    flat = np.ravel(np.asarray(actual, dtype=float))
    if flat.size != len(numbers):
        return False
    tolerance = np.array([0.5 * 10.0 ** -len(decimals) + 1e-12 for decimals in numbers])
    return bool(np.all(np.abs(flat - np.ravel(np.asarray(shown, dtype=float))) <= tolerance))


def _check_claims(answer: dict, claims: str, where: str) -> None:
    """What the comment after a request shows of its answer; an IK answer is "ok" unless the comment says else."""
    if '"status"' not in claims:
        statuses = [answer.get("status")] if "solutions" in answer and "status" in answer else \
            [result["status"] for result in answer.get("results", []) if "solutions" in result]
        assert set(statuses) <= {"ok"}, f"{where}: status {statuses}"
    value = r'("[^"]*"|true|false|null|-?\d+(?:\.\d+)?(?![\d.eE])|\[[^\[\]]*\])'
    for key, shown in re.findall(rf'"?({"|".join(CLAIMED_KEYS)})"?:? {value}', claims):
        actual = _first(answer, key)
        assert _same_as_shown(actual, shown), f"{where}: {key} is {actual!r}, the page shows {shown}"
    kept = re.search(r"(\d+) solutions", claims)
    if kept:
        assert len(answer["solutions"]) == int(kept.group(1)), f"{where}: {len(answer['solutions'])} solutions"
    rejected = re.search(r'(\d+) (?:more )?in "rejected"', claims)
    if rejected:
        assert len(answer["rejected"]) == int(rejected.group(1)), f"{where}: {len(answer['rejected'])} rejected"


@pytest.mark.parametrize("block", CURL_BLOCKS, ids=lambda b: b.where)
def test_every_curl_example_is_answered_as_its_page_says(block: Block, client, tmp_path):
    calls, claims = _calls_of(block, tmp_path), _comments_of(block)
    assert len(calls) == len(claims), "every curl line of the block ran once"
    for arguments, claim in zip(calls, claims):
        method, path, headers, data = _request(arguments)
        response = client.request(method, path, headers=headers, content=data)
        where = f"{block.where} {method} {path}"
        assert response.status_code == 200, f"{where}: {response.status_code} {response.text[:500]}"
        if response.headers["content-type"].startswith("application/json"):
            _check_claims(response.json(), claim, where)


def test_the_curl_examples_cover_every_operation_kind_the_pages_describe():
    sent = " ".join(b.body for b in CURL_BLOCKS)
    for route in ("/fk", "/fk/batch", "/ik", "/ik/batch", "/ik/trajectory", "/limits", "/render", "?form="):
        assert route in sent, route


# ------------------------------------------------------------------------------------------ JSON, YAML blocks

def _elided(example: str) -> str:
    """A JSON example with its elisions (``[...]``) as empty lists."""
    return example.replace("[...]", "[]")


def _spec_schema_for(document: dict) -> dict:
    """The spec's response schema whose properties hold every top-level key of ``document`` and all its required
    ones (the IK and trajectory answers)."""
    from service.openapi import current_spec

    spec = current_spec()
    candidates = [
        name for name, schema in spec["components"]["schemas"].items()
        if name.endswith("Response") and set(document) <= set(schema.get("properties", {}))
        and set(schema.get("required", [])) <= set(document)
    ]
    assert len(candidates) == 1, candidates
    return {"$ref": f"#/components/schemas/{candidates[0]}", "components": spec["components"]}


@pytest.mark.parametrize("block", blocks("json"), ids=lambda b: b.where)
def test_every_json_example_is_valid(block: Block, client):
    """A ``"collision": [...]`` fragment is sent as part of an inline robot; an answer is validated against the
    spec's schema of that answer."""
    import jsonschema

    if block.body.lstrip().startswith('"collision"'):
        fragment = json.loads("{" + block.body + "}")
        robot = _catalogue_description("puma560_standard")
        answer = client.post("/v1/fk", json={"robot": {**robot, **fragment}, "joints": [0.0] * 6,
                                             "collisions": {"margin": 0.0}})
        assert answer.status_code == 200, answer.text
        assert answer.json()["clearance"] is not None
        return
    document = json.loads(_elided(block.body))
    jsonschema.validate(document, _spec_schema_for(document))
    described = client.get(f"/v1/robots/{document['robot_id']}").json()
    assert document["joint_names"] == [joint["name"] for joint in described["joints"]]


def _catalogue_description(robot_id: str) -> dict:
    import yaml

    description = yaml.safe_load((ROOT / "robots" / f"{robot_id}.yaml").read_text(encoding="utf-8"))
    return {key: value for key, value in description.items() if key != "collision"}


@pytest.mark.parametrize("block", blocks("yaml"), ids=lambda b: b.where)
def test_every_robot_file_example_loads(block: Block, tmp_path):
    """The robot file shown loads as a robot file: two revolute joints, the second limited to ±150°."""
    import yaml

    from service.robots.catalogue import load_robot_file

    shown = yaml.safe_load(block.body)
    path = tmp_path / f"{shown['id']}.yaml"
    path.write_text(block.body, encoding="utf-8")
    loaded = load_robot_file(path, max_joints=32)
    bounds = [(joint.lower, joint.upper) for joint in loaded.robot.joints]
    assert bounds[0] == (-np.inf, np.inf) and np.allclose(bounds[1], np.radians([-150, 150]))


# ------------------------------------------------------------------------------------ the pages' stated numbers

def test_trajectories_example_answers_what_the_page_shows(client):
    """The curl body of docs/trajectories.md gives the second sample and summary printed below it (6 decimals)."""
    page = text("trajectories.md")
    body = json.loads(re.search(r"-d '(\{.*?\})'\n```", page, re.S).group(1))
    shown = json.loads(re.search(r"```json\n(.+?)\n```", page, re.S).group(1))
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


def test_the_ur5_solution_counts_the_page_states(client):
    """Inclusive bounds: a joint at exactly 0 within ±360° fits three ways, so the counts are not all 512."""
    paragraph = text("api-guide.md").split("Bounds are inclusive, so a joint at", 1)[1].split("\n\n", 1)[0]
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
            if not any(np.all(angle_gap(joints, b) < 1e-6) for b in branches):
                branches.append(joints)
        branches = np.array(branches)
        fits = [sum(abs(v + 2 * k * np.pi) <= 2 * np.pi + 1e-9 for k in range(-2, 3)) for v in branches.ravel()]
        assert len(answer["solutions"]) == int(np.prod(np.reshape(fits, branches.shape), axis=1).sum())
    assert stated == counted


# ------------------------------------------------------------------------------ the commands the pages name

#: ``python -m module`` or ``python script.py`` with its flags, in a block or in inline code.
_COMMAND = re.compile(r"(?:\.venv/bin/)?python3? (?:-m ([\w.]+)|([\w/]+\.py))"
                      r"((?: --?[\w-]+(?: [^\s`|&#-][^\s`|&#]*)?)*)")


def _project_commands() -> list[tuple[str, str, list[str]]]:
    """(page, module or script, flags) of every command that runs this repository's code."""
    found = []
    for page in pages():
        for module, script, flags in _COMMAND.findall(text(page)):
            if (module or script).split(".")[0].split("/")[0] in ("service", "benchmarks"):
                found.append((page.name, module or script, re.findall(r"--[\w-]+", flags)))
    return found


def _help_of(target: str) -> str:
    """The ``--help`` text of a script or module; for one whose imports need an extra this environment lacks (the
    load test's locust), its source, where argparse names every flag."""
    import importlib.util

    argv = [sys.executable, target] if target.endswith(".py") else [sys.executable, "-m", target]
    run = subprocess.run([*argv, "--help"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    if run.returncode == 0:
        return run.stdout
    missing = re.search(r"No module named '([\w.]+)'", run.stderr)
    assert missing and importlib.util.find_spec(missing.group(1).split(".")[0]) is None, run.stderr
    path = ROOT / target if target.endswith(".py") else Path(importlib.util.find_spec(target).origin)
    return path.read_text(encoding="utf-8")


def test_the_commands_the_pages_name_exist_with_their_flags():
    import importlib.util

    commands = _project_commands()
    assert any(target == "benchmarks.core" for _, target, _ in commands)
    helps: dict[str, str] = {}
    for page, target, flags in commands:
        if target.endswith(".py"):
            assert (ROOT / target).is_file(), f"{page}: {target} does not exist"
        else:
            assert importlib.util.find_spec(target) is not None, f"{page}: no module {target}"
        if flags:
            if target not in helps:
                helps[target] = _help_of(target)
            for flag in flags:
                assert re.search(re.escape(flag) + r"(?![\w-])", helps[target]), f"{page}: {target} has no {flag}"


def test_the_extras_the_pages_install_exist():
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"]
    named = {name for page in pages() for group in re.findall(r"-e '\.\[([\w,]+)\]'", text(page))
             for name in group.split(",")}
    assert named and named <= set(extras), named - set(extras)
