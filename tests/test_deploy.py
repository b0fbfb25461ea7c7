"""The deployment examples: the Kubernetes manifest's autoscaler and probes, and the reachability-study client
run against a live server with two workers. The manifests are validated offline: deploy/kubernetes.yaml against
the Kubernetes API schemas that kubernetes-validate bundles (every version it has, strict: an unknown field fails),
deploy/compose.yaml against the Compose specification's JSON schema (tests/data/compose-spec.json, compose-go's,
the one `docker compose config` applies) plus the references `docker compose` resolves, and deploy/nginx.conf with
crossplane, nginx's own parser, in the http context compose.yaml mounts it into."""

from __future__ import annotations

import copy
import importlib.util
import io
import json
import re
from collections import Counter
from pathlib import Path

import crossplane
import jsonschema
import kubernetes_validate
import pytest
import yaml
from kubernetes_validate.utils import all_versions

from service.config import Settings
from tests.live import serve

DEPLOY = Path(__file__).resolve().parent.parent / "deploy"
COMPOSE_SCHEMA = Path(__file__).resolve().parent / "data" / "compose-spec.json"


def _study_module():
    spec = importlib.util.spec_from_file_location("reachability_study", DEPLOY / "reachability_study.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_autoscaler_scales_the_deployment_on_cpu_and_the_probes_are_wired():
    documents = {doc["kind"]: doc for doc in yaml.safe_load_all((DEPLOY / "kubernetes.yaml").read_text())}
    deployment, autoscaler = documents["Deployment"], documents["HorizontalPodAutoscaler"]
    assert autoscaler["spec"]["scaleTargetRef"] == {"apiVersion": "apps/v1", "kind": "Deployment",
                                                    "name": deployment["metadata"]["name"]}
    assert 1 <= autoscaler["spec"]["minReplicas"] <= autoscaler["spec"]["maxReplicas"]
    (container,) = deployment["spec"]["template"]["spec"]["containers"]
    assert container["resources"]["requests"]["cpu"]  # utilisation is a share of the request: it must be set
    assert container["readinessProbe"]["httpGet"]["path"] == "/readyz"  # can serve (load is shed per request)
    assert container["livenessProbe"]["httpGet"]["path"] == "/healthz"
    fields = set(Settings.model_fields)
    for variable in container["env"]:  # every setting the example sets exists
        assert variable["name"].removeprefix("KIN_").lower() in fields, variable["name"]


def test_the_reachability_study_client_loses_no_pose_across_two_workers(client):
    """216 poses in batches of 50 over 3 connections to 2 workers, against a server whose batch cap (40) makes
    every batch a 413 the client must split: the counts equal one in-process batch of the same targets."""
    study = _study_module()
    targets = study.grid_targets(6, 0.8, 0.3, [3.141592653589793, 0.0, 0.0])
    expected = client.post("/v1/robots/puma560_standard/ik/batch",
                           json={"targets": targets, "format": "arrays", "max_equivalents": 1}).json()
    expected = Counter(expected["targets"]["status"])
    assert expected["ok"] and expected["unreachable"]  # the grid reaches out of the workspace and into it
    with serve(KIN_WORKERS="2", KIN_MAX_BATCH="40") as url:
        progress = io.StringIO()
        summary = study.run_study(url, "puma560_standard", targets, batch=50, connections=3, progress=progress)
    assert summary["poses"] == len(targets) == 216
    assert summary["status"] == dict(sorted(expected.items()))
    assert "5/5 batches, 216 poses" in progress.getvalue()


# --------------------------------------------------------------------------- the manifests, validated offline


def _kubernetes_documents() -> list[dict]:
    return list(yaml.safe_load_all((DEPLOY / "kubernetes.yaml").read_text()))


def _kubernetes_versions() -> list[str]:
    return sorted(set(all_versions()), key=lambda version: tuple(int(part) for part in version.split(".")))


def test_the_kubernetes_manifest_is_valid_against_every_bundled_api_schema():
    """Strict: an unknown or misplaced field fails too, not only a wrong type or a missing required field."""
    versions = _kubernetes_versions()
    assert len(versions) >= 5, versions  # 1.25 … 1.37 in kubernetes-validate 1.37.0
    documents = _kubernetes_documents()
    assert {doc["kind"] for doc in documents} == {"ConfigMap", "Deployment", "Service", "HorizontalPodAutoscaler"}
    for version in versions:
        for document in documents:
            kubernetes_validate.validate(document, version, strict=True)


def test_the_kubernetes_check_catches_a_misspelt_field():
    documents = {doc["kind"]: doc for doc in _kubernetes_documents()}
    deployment = copy.deepcopy(documents["Deployment"])
    deployment["spec"]["template"]["spec"]["containers"][0]["readinessProbe"]["httpGet"]["paht"] = "/readyz"
    with pytest.raises(kubernetes_validate.ValidationError, match="paht"):
        kubernetes_validate.validate(deployment, _kubernetes_versions()[-1], strict=True)


def test_the_kubernetes_manifest_s_references_resolve():
    """What the schemas cannot see and the API server or the controllers would: selectors, port names, volumes."""
    documents = {doc["kind"]: doc for doc in _kubernetes_documents()}
    deployment, service, config_map = documents["Deployment"], documents["Service"], documents["ConfigMap"]
    pod = deployment["spec"]["template"]
    labels = pod["metadata"]["labels"]
    assert deployment["spec"]["selector"]["matchLabels"].items() <= labels.items()  # else the API refuses it
    assert service["spec"]["selector"].items() <= labels.items()  # else the Service has no endpoints
    (container,) = pod["spec"]["containers"]
    port_names = {port["name"] for port in container["ports"]}
    assert {port["targetPort"] for port in service["spec"]["ports"]} <= port_names
    for probe in ("readinessProbe", "livenessProbe"):
        assert container[probe]["httpGet"]["port"] in port_names
    volumes = {volume["name"]: volume for volume in pod["spec"]["volumes"]}
    assert {mount["name"] for mount in container["volumeMounts"]} <= volumes.keys()
    assert volumes["extra-robots"]["configMap"]["name"] == config_map["metadata"]["name"]
    robots_dir = next(v["value"] for v in container["env"] if v["name"] == "KIN_ROBOTS_DIR")
    assert robots_dir in {mount["mountPath"] for mount in container["volumeMounts"]}
    for key, text in config_map["data"].items():  # each key a robot file named after its id
        assert yaml.safe_load(text)["id"] == Path(key).stem


def _compose() -> dict:
    return yaml.safe_load((DEPLOY / "compose.yaml").read_text())


def _compose_errors(document: dict) -> list[str]:
    schema = json.loads(COMPOSE_SCHEMA.read_text())
    validator_class = jsonschema.validators.validator_for(schema)
    validator_class.check_schema(schema)
    validator = validator_class(schema, format_checker=validator_class.FORMAT_CHECKER)
    return [f"{'/'.join(map(str, error.absolute_path))}: {error.message}" for error in validator.iter_errors(document)]


def test_the_compose_file_is_valid_against_the_compose_specification_schema():
    assert _compose_errors(_compose()) == []
    misspelt = _compose()
    misspelt["services"]["api"]["healthcheck"]["intervl"] = "10s"
    assert any("intervl" in error for error in _compose_errors(misspelt))


def test_the_compose_file_resolves_as_docker_compose_config_would():
    """The checks `docker compose config` (and `up`) make beyond the schema, without Docker: nothing left to
    interpolate, dependencies on defined services with a health check, the build context and bind mounts present."""
    text = (DEPLOY / "compose.yaml").read_text()
    assert not re.search(r"\$\{?[A-Za-z_]", text)  # no variable: the file means the same in every shell
    services = _compose()["services"]
    for name, service in services.items():
        for dependency, condition in service.get("depends_on", {}).items():
            assert dependency in services, (name, dependency)
            if condition.get("condition") == "service_healthy":
                assert "healthcheck" in services[dependency], dependency
        if "build" in service:
            assert (DEPLOY / service["build"]["context"] / "Dockerfile").is_file()
        for volume in service.get("volumes", []):
            source = volume.split(":")[0]
            if source.startswith("."):
                assert (DEPLOY / source).exists(), (name, source)
    api = services["api"]
    fields = set(Settings.model_fields)
    for variable in api["environment"]:
        assert variable.removeprefix("KIN_").lower() in fields, variable
    assert "/readyz" in " ".join(api["healthcheck"]["test"])


def _size_bytes(value: str) -> int:
    number, unit = re.fullmatch(r"(\d+)([kKmMgG]?)", value).groups()
    return int(number) * {"": 1, "k": 1024, "m": 1024 ** 2, "g": 1024 ** 3}[unit.lower()]


def _seconds(value: str) -> float:
    number, unit = re.fullmatch(r"(\d+)(ms|s|m)?", value).groups()
    return int(number) * {"ms": 0.001, "s": 1, "m": 60, None: 1}[unit]


def _nginx(tmp_path: Path, conf: Path) -> dict:
    """crossplane's parse of ``conf`` included in the http block, where compose.yaml mounts it (conf.d)."""
    main = tmp_path / "nginx.conf"
    main.write_text(f"events {{}}\nhttp {{\n    include {conf.resolve()};\n}}\n")
    return crossplane.parse(str(main), strict=True, check_ctx=True, check_args=True)


def test_the_nginx_example_parses_and_agrees_with_the_service_and_compose(tmp_path):
    parsed = _nginx(tmp_path, DEPLOY / "nginx.conf")
    assert parsed["status"] == "ok", parsed["errors"]
    (conf,) = [entry["parsed"] for entry in parsed["config"] if entry["file"] == str((DEPLOY / "nginx.conf").resolve())]
    blocks = {(d["directive"], *d["args"]): d.get("block", []) for d in conf}
    (upstream,) = [block for key, block in blocks.items() if key[0] == "upstream"]
    (server,) = [block for key, block in blocks.items() if key[0] == "server"]

    def directive(block: list[dict], name: str) -> list[str]:
        (found,) = [d["args"] for d in block if d["directive"] == name]
        return found

    services = _compose()["services"]
    host, port = directive(upstream, "server")[0].split(":")
    assert host in services and port in services[host]["expose"]  # nginx resolves the api replicas by name
    assert f"{directive(server, 'listen')[0]}" in [p.split(":")[-1] for p in services["lb"]["ports"]]
    settings = Settings(_env_file=None)
    assert _size_bytes(directive(server, "client_max_body_size")[0]) >= settings.max_body_bytes  # the 413 is ours
    (location,) = [d["block"] for d in server if d["directive"] == "location"]
    assert _seconds(directive(location, "proxy_read_timeout")[0]) > settings.request_timeout_ms / 1000
    broken = tmp_path / "broken.conf"
    broken.write_text((DEPLOY / "nginx.conf").read_text().replace("proxy_read_timeout", "proxy_read_timout"))
    assert _nginx(tmp_path, broken)["status"] == "failed"
