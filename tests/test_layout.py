"""The package layout's promises: only the simulator modules load pybullet, and imports go one way.

Modules are discovered with pkgutil.walk_packages, so a new module is covered without editing this file.
"""
from __future__ import annotations

import ast
import json
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("symlearn", "search", "pddl_export")
# The modules that import pybullet on purpose (the simulator and the two that run it).
SIMULATOR_MODULES = {"symlearn.sim.simulator", "symlearn.sim.collect", "symlearn.sim.scenarios"}

# Python source run before anything else: makes `import pybullet` fail as if it were not installed.
BLOCK_PYBULLET = """
import sys
class _NoPybullet:
    def find_spec(self, name, path=None, target=None):
        if name == "pybullet" or name.startswith("pybullet."):
            raise ImportError("pybullet is blocked for this test")
        return None
sys.meta_path.insert(0, _NoPybullet())
"""


def _env() -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


def all_modules() -> list[str]:
    """Every module of the three packages, found by walking their folders (nothing is imported)."""
    names = []
    for pkg in PACKAGES:
        names.append(pkg)
        names += [m.name for m in pkgutil.walk_packages([str(ROOT / pkg)], prefix=f"{pkg}.")]
    return sorted(names)


def test_module_discovery_finds_the_layout():
    mods = set(all_modules())
    assert SIMULATOR_MODULES <= mods
    assert {"symlearn.world", "symlearn.cli.main", "search.astar", "pddl_export.symbolic"} <= mods


# In one fresh interpreter, import every module but the simulator's, each noting whether pybullet got loaded by
# it. Importing is monotone (a module that loads pybullet alone also loads it among others), so a clean run
# shows that each module alone stays clean; the first offender is named, with the import chain that reached it.
_PROBE = """
import importlib, json, sys, traceback
names = json.loads(sys.argv[1])
offenders = []
class _Spy:
    current = None
    def find_spec(self, name, path=None, target=None):
        if name == "pybullet" and not offenders:
            stack = [f"{f.filename}:{f.lineno}" for f in traceback.extract_stack()
                     if "importlib" not in f.filename and "<frozen" not in f.filename]
            offenders.append({"module": _Spy.current, "stack": stack[-6:]})
        return None
sys.meta_path.insert(0, _Spy())
for n in names:
    _Spy.current = n
    importlib.import_module(n)
print(json.dumps({"offenders": offenders, "pybullet_loaded": "pybullet" in sys.modules,
                  "ray_loaded": "ray" in sys.modules}))
"""


def test_no_module_but_the_simulator_imports_pybullet():
    names = [m for m in all_modules() if m not in SIMULATOR_MODULES]
    r = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(names)], cwd=ROOT, env=_env(), capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert out["offenders"] == [] and not out["pybullet_loaded"], out
    assert not out["ray_loaded"], "importing a module loaded Ray: the optional extra must be imported lazily"


def test_ray_is_imported_only_inside_the_engine_module():
    """Ray is an optional extra: one module imports it, and only inside its functions, so the package works without it."""
    importers = {pkg: _imported_packages(ROOT / pkg, pkg).get("ray", set()) for pkg in PACKAGES}
    assert importers == {"symlearn": {"symlearn.cluster"}, "search": set(), "pddl_export": set()}, importers
    tree = ast.parse((ROOT / "symlearn" / "cluster.py").read_text())
    def imports_ray(node) -> bool:
        if isinstance(node, ast.Import):
            return any(a.name.split(".")[0] == "ray" for a in node.names)
        return isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "ray"

    assert not any(imports_ray(n) for n in tree.body)  # nothing at module level
    inner = [n for n in ast.walk(tree) if isinstance(n, ast.Import) and any(a.name == "ray" for a in n.names)]
    assert len(inner) == 1  # the check is not vacuous: the engine does import Ray, inside import_ray


def test_the_probe_catches_a_module_that_imports_pybullet():
    """The check above is not vacuous: the simulator module itself is reported."""
    r = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(["symlearn.world", "symlearn.sim.simulator"])],
                       cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert [o["module"] for o in out["offenders"]] == ["symlearn.sim.simulator"] and out["pybullet_loaded"]


def test_search_and_pddl_tests_pass_without_pybullet(tmp_path):
    files = ["tests/test_search.py", "tests/test_pddl_export.py", "tests/test_sas_planners.py"]
    code = BLOCK_PYBULLET + (
        "try:\n    import pybullet\nexcept ImportError:\n    pass\nelse:\n    sys.exit('pybullet was not blocked')\n"
        "import pytest\n"
        f"sys.exit(pytest.main({files!r} + ['-q', '-p', 'no:cacheprovider', '-p', 'no:warnings', "
        f"'--basetemp', {str(tmp_path / 'bt')!r}]))\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (r.stdout[-3000:], r.stderr[-2000:])
    summary = r.stdout.strip().splitlines()[-1]
    assert " passed" in summary and "failed" not in summary and "error" not in summary, summary


# ------------------------------------------------------------------------------- one-way import graph


def _imported_packages(path: Path, package: str) -> dict[str, set[str]]:
    """Top-level package name -> the modules of `package` (under path) that import it, from their source."""
    out: dict[str, set[str]] = {}
    for f in sorted(path.rglob("*.py")):
        rel = ".".join(f.relative_to(path.parent).with_suffix("").parts)
        for node in ast.walk(ast.parse(f.read_text(), str(f))):
            if isinstance(node, ast.Import):
                tops = [a.name.split(".")[0] for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                tops = [package] if node.level else [(node.module or "").split(".")[0]]
            else:
                continue
            for t in tops:
                out.setdefault(t, set()).add(rel)
    return out


@pytest.mark.parametrize("package, forbidden", [("pddl_export", {"search", "symlearn", "pybullet"}),
                                                ("search", {"symlearn", "pybullet"})])
def test_import_graph_is_one_way(package, forbidden):
    imports = _imported_packages(ROOT / package, package)
    bad = {t: sorted(imports[t]) for t in forbidden if t in imports}
    assert not bad, f"{package} must not import {sorted(bad)}: {bad}"


def test_import_graph_parser_sees_real_imports():
    """The parser is not vacuous: symlearn imports both lower packages, search imports pddl_export."""
    sym = _imported_packages(ROOT / "symlearn", "symlearn")
    assert {"search", "pddl_export", "pybullet", "numpy"} <= set(sym)
    assert "symlearn.sim.simulator" in sym["pybullet"]
    assert "pddl_export" in _imported_packages(ROOT / "search", "search")
