"""The solver core imports numpy and the standard library only: no web framework, no Pydantic."""

import ast
import sys
from pathlib import Path

CORE = Path(__file__).resolve().parents[2] / "service" / "kinematics"
ALLOWED = set(sys.stdlib_module_names) | {"numpy"}


def _imported_top_level_modules(path: Path) -> set[str]:
    modules = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            modules.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            modules.add(node.module.split(".")[0])
    return modules


def test_core_modules_import_only_numpy_and_the_standard_library():
    files = sorted(CORE.rglob("*.py"))
    assert len(files) > 20
    offenders = {str(path.relative_to(CORE)): sorted(_imported_top_level_modules(path) - ALLOWED)
                 for path in files if _imported_top_level_modules(path) - ALLOWED}
    assert offenders == {}


def test_the_check_sees_a_forbidden_import(tmp_path):
    module = tmp_path / "bad.py"
    module.write_text("from fastapi import APIRouter\nimport numpy as np\nfrom . import sibling\n")
    assert _imported_top_level_modules(module) - ALLOWED == {"fastapi"}
