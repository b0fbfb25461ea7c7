"""The deployment examples: the Kubernetes manifest's autoscaler and probes, and the reachability-study client
run against a live server with two workers."""

from __future__ import annotations

import importlib.util
import io
from collections import Counter
from pathlib import Path

import yaml

from service.config import Settings
from tests.live import serve

DEPLOY = Path(__file__).resolve().parent.parent / "deploy"


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
