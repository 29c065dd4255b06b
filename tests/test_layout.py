"""The package's layout: every module imports on its own, the physics knows no case file, the
wheel's package list is the source tree's, and the ``drape`` command reaches every tool."""
import json
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("constitutive", "drape", "meshes")

#: Layers below the case file: they take numbers, arrays and functions of time.
PHYSICS = ("drape.fem", "drape.models", "drape.solvers", "drape.contact", "constitutive.law", "constitutive.friction",
           "constitutive.sheet", "constitutive.sheet_friction", "constitutive.derived",
           "constitutive.conventions", "constitutive.kes")
#: What the physics must not load: the schema library and the layers above it.
FORBIDDEN = ("pydantic", "drape.case", "drape.run", "drape.batch", "drape.analyses")


def modules(*prefixes):
    """Dotted names of the project's modules under ``prefixes`` (``__main__`` files left out)."""
    names = []
    for pkg in PACKAGES:
        for f in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(f.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__main__":
                continue
            if parts[-1] == "__init__":
                parts = parts[:-1]
            name = ".".join(parts)
            if not prefixes or any(name == p or name.startswith(p + ".") for p in prefixes):
                names.append(name)
    return names


def run_python(code, *args):
    return subprocess.run([sys.executable, "-c", code, *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)


# Each module is imported with every project module dropped from sys.modules first, so an
# import cycle shows up as the ImportError of a partly initialised module whichever module is
# imported first; third-party libraries stay loaded, which keeps this to one interpreter.
_EACH_ALONE = """
import importlib, json, sys, traceback
failed = {}
for name in sys.argv[1:]:
    for loaded in [m for m in sys.modules if m.split(".")[0] in ("constitutive", "drape", "meshes")]:
        del sys.modules[loaded]
    try:
        importlib.import_module(name)
    except Exception:
        failed[name] = traceback.format_exc(limit=-3)
print(json.dumps(failed))
"""


def test_every_module_imports_on_its_own():
    names = modules()
    assert len(names) > 80
    out = run_python(_EACH_ALONE, *names)
    assert out.returncode == 0, out.stderr
    failed = json.loads(out.stdout)
    assert not failed, "\n".join(f"{k}:\n{v}" for k, v in failed.items())


def test_no_module_over_500_lines():
    """One concept per module: a module that grows past 500 lines holds more than one."""
    lengths = {f.relative_to(ROOT).as_posix(): len(f.read_text().splitlines())
               for pkg in ("constitutive", "drape") for f in (ROOT / pkg).rglob("*.py")}
    assert not {f: n for f, n in lengths.items() if n > 500}


def test_physics_loads_no_schema_and_no_case_layer():
    names = modules(*PHYSICS)
    assert "drape.models.shell" in names and "drape.solvers.newmark" in names
    code = ("import importlib, json, sys\n"
            "for name in sys.argv[1:]: importlib.import_module(name)\n"
            "print(json.dumps(sorted(sys.modules)))")
    out = run_python(code, *names)
    assert out.returncode == 0, out.stderr
    loaded = json.loads(out.stdout)
    bad = [m for m in loaded if any(m == f or m.startswith(f + ".") for f in FORBIDDEN)]
    assert not bad, f"the physics loads {bad}"


def test_wheel_package_list_is_the_source_tree():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    tree = {".".join(p.parent.relative_to(ROOT).parts) for pkg in PACKAGES
            for p in (ROOT / pkg).rglob("__init__.py")}
    assert set(config["packages"]) == tree | {"fabric_drape_cases"}
    assert config["package-dir"]["fabric_drape_cases"] == "cases"


def test_bundled_cases_found():
    from constitutive.bundled import cases_dir
    from constitutive.material import available_materials

    assert {"fabric1", "fabric2", "kes_example"} <= set(available_materials())
    assert (cases_dir("cantilever.toml")).is_file()
    assert sorted(p.name for p in cases_dir("validation").glob("*.toml"))


@pytest.mark.parametrize("command", ["run", "sweep", "report", "validate", "inspect", "measure", "fit"])
def test_drape_command_delegates_to_the_tool(command, capsys):
    from drape.commands import main

    with pytest.raises(SystemExit) as stop:
        main([command, "--help"])
    assert stop.value.code == 0
    assert "usage:" in capsys.readouterr().out


@pytest.mark.parametrize("module", ["drape.run", "drape.sweep", "constitutive.fit", "drape"])
def test_python_m_entry_points(module):
    out = subprocess.run([sys.executable, "-m", module, "--help"], cwd=ROOT, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "usage:" in out.stdout
