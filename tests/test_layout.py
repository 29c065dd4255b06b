"""The package's layout: every module imports on its own, the physics knows no case file, the
material points know no drape, imports sit at module top, the command line lives in drape.cli
alone, the wheel's package list is the source tree's, and the ``drape`` command reaches every
tool."""
import ast
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


@pytest.mark.slow
def test_every_module_imports_on_its_own():
    """Each module imported alone, in a fresh interpreter state (minutes: every module loads
    what it imports anew). The fast tier has the import graph's cycles
    (:func:`test_the_import_graph_has_no_cycle`) and imports every module once, collecting
    the doctests."""
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


#: Function-level imports of a project module that stay, with the reason each cannot be at the
#: top: (module, imported module) -> why.
FUNCTION_LEVEL_IMPORTS = {
    ("drape.models.plate", "constitutive.material"):
        "the material package reads material files (pydantic), which the physics must not load",
}
#: The command-line tools: ``drape COMMAND`` -> its ``python -m`` module.
COMMANDS = {"run": "drape.run", "sweep": "drape.sweep", "report": "drape.report",
            "validate": "drape.validate", "predict": "drape.predict", "inspect": "drape.inspect", "measure": "drape.measure",
            "identify": "drape.identify", "fit": "constitutive.fit",
            "datasets": "constitutive.datasets"}
VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]


def source_files(*prefixes, root=ROOT):
    """{dotted name: path} of every ``.py`` file of the project under ``prefixes`` (all of it
    without), ``__main__`` files included."""
    found = {}
    for pkg in PACKAGES:
        for f in sorted((root / pkg).rglob("*.py")):
            parts = list(f.relative_to(root).with_suffix("").parts)
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            if not prefixes or under(name, *prefixes):
                found[name] = f
    return found


def under(module: str, *prefixes) -> bool:
    """Whether ``module`` is one of ``prefixes`` or inside one."""
    return any(module == p or module.startswith(p + ".") for p in prefixes)


def _is_main_guard(node) -> bool:
    """``if __name__ == "__main__":``"""
    test = node.test if isinstance(node, ast.If) else None
    return (isinstance(test, ast.Compare) and isinstance(test.left, ast.Name)
            and test.left.id == "__name__" and len(test.comparators) == 1
            and isinstance(test.comparators[0], ast.Constant)
            and test.comparators[0].value == "__main__")


def imports(path, package: str):
    """(imported module, inside a function, under the ``__main__`` guard) of every import
    statement of ``path``, a module of ``package`` (``from x import y`` counts as ``x``; a
    relative import is resolved)."""
    found = []

    def visit(node, in_function, in_guard):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.Import):
                found.extend((a.name, in_function, in_guard) for a in child.names)
            elif isinstance(child, ast.ImportFrom):
                parts = package.split(".")[:len(package.split(".")) + 1 - child.level]
                module = child.module if not child.level else ".".join(
                    parts + ([child.module] if child.module else []))
                found.append((module, in_function, in_guard))
            visit(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef,
                                                           ast.Lambda)),
                  in_guard or _is_main_guard(child))

    visit(ast.parse(path.read_text()), False, False)
    return found


def project_imports():
    """{dotted name: imports(path)} of every file of the project."""
    return {name: imports(path, ".".join(path.relative_to(ROOT).parts[:-1]))
            for name, path in source_files().items()}


def test_the_import_reader_sees_every_kind_of_import(tmp_path):
    path = tmp_path / "mod.py"
    path.write_text("import argparse\nfrom . import sibling\nfrom ..up import x\n"
                    "def f():\n    from drape.case import case\n"
                    "if __name__ == '__main__':\n    import drape.cli\n")
    assert imports(path, "pkg.sub") == [("argparse", False, False), ("pkg.sub", False, False),
                                         ("pkg.up", False, False), ("drape.case", True, False),
                                         ("drape.cli", False, True)]


def _is_type_checking(node) -> bool:
    """``if TYPE_CHECKING:``: imports for annotations only, never run."""
    return isinstance(node, ast.If) and ast.unparse(node.test) in ("TYPE_CHECKING",
                                                                   "typing.TYPE_CHECKING")


def import_graph(root=ROOT) -> dict[str, set[str]]:
    """{module: the project modules its import imports} for every module of the project under
    ``root`` (``__main__`` files left out: they are run, never imported). An edge is an import
    that runs when the module is imported: outside functions, ``if TYPE_CHECKING:`` and the
    ``__main__`` guard; ``from p import name`` leads to ``p.name`` when that is a module, else to
    ``p``. Importing ``a.b.c`` first runs the ``__init__`` of ``a`` and ``a.b``, so an import
    also leads to each package the imported module lies in that does not hold the importer."""
    files = {name: path for name, path in source_files(root=root).items()
             if not name.endswith("__main__")}
    graph = {}
    for name, path in files.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        imported = set()

        def visit(node):
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                    continue
                if _is_main_guard(child) or _is_type_checking(child):
                    for statement in child.orelse:
                        visit(ast.Module([statement], []))
                elif isinstance(child, ast.Import):
                    imported.update(alias.name for alias in child.names)
                elif isinstance(child, ast.ImportFrom):
                    parts = package.split(".")[:len(package.split(".")) + 1 - child.level]
                    base = child.module if not child.level else ".".join(
                        parts + ([child.module] if child.module else []))
                    imported.update(f"{base}.{a.name}" if f"{base}.{a.name}" in files else base
                                    for a in child.names)
                else:
                    visit(child)

        visit(ast.parse(path.read_text()))
        edges = set()
        for module in imported:
            if module.split(".")[0] in PACKAGES:
                parts = module.split(".")
                edges.update(".".join(parts[:i]) for i in range(1, len(parts) + 1))
        graph[name] = {m for m in edges if m != name and not under(name, m)}
    return graph


def cycle(graph) -> list[str]:
    """One cycle of ``graph`` as the modules along it (the first again at the end), or []."""
    state, path = {}, []

    def visit(node):
        state[node] = "open"
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return path[path.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        state[node] = "done"
        path.pop()
        return []

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return []


def test_the_import_graph_has_no_cycle():
    """A cycle of module-level imports breaks the import of whichever of its modules comes
    first (a partly initialised module); a package's ``__init__`` counts as the package."""
    graph = import_graph()
    assert set(graph) == set(modules())
    assert "drape.models.shell" in graph["drape.case.build"]
    assert "drape.solvers.newmark" not in graph["drape.solvers.step_control"]   # TYPE_CHECKING
    assert cycle(graph) == []


def test_the_import_graph_finds_a_cycle_through_a_package_init(tmp_path):
    pkg = tmp_path / "meshes"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from meshes.a import A\n")
    (pkg / "a.py").write_text("from . import b\nA = 1\n")
    (pkg / "b.py").write_text("import numpy\nfrom typing import TYPE_CHECKING\n"
                              "if TYPE_CHECKING:\n    from meshes.a import A\n"
                              "def f():\n    from meshes import a\n")
    (pkg / "c.py").write_text("from meshes.sub.d import D\n")
    (pkg / "sub").mkdir()
    (pkg / "sub" / "__init__.py").write_text("from .d import D\n")
    (pkg / "sub" / "d.py").write_text("D = 1\n")
    graph = import_graph(tmp_path)
    assert graph == {"meshes": {"meshes.a"}, "meshes.a": {"meshes.b"}, "meshes.b": set(),
                     "meshes.c": {"meshes.sub", "meshes.sub.d"}, "meshes.sub": {"meshes.sub.d"},
                     "meshes.sub.d": set()}
    assert cycle(graph) == []
    (pkg / "sub" / "d.py").write_text("from meshes.c import C\nD = 1\n")   # c -> sub -> d -> c
    assert cycle(import_graph(tmp_path)) == ["meshes.c", "meshes.sub", "meshes.sub.d", "meshes.c"]
    (pkg / "sub" / "d.py").write_text("import meshes.a\nD = 1\n")
    (pkg / "a.py").write_text("from meshes.sub import d\nA = 1\n")
    # a -> sub.d (and the package sub, whose __init__ imports d) -> a
    assert cycle(import_graph(tmp_path)) == ["meshes.a", "meshes.sub", "meshes.sub.d", "meshes.a"]


def test_no_argparse_outside_the_command_line():
    """Options are read in one place, drape.cli; the layers below take plain arguments."""
    found = project_imports()
    assert "drape.cli.run" in found and any(m == "argparse" for m, _, _ in found["drape.cli.run"])
    bad = [name for name, names in found.items() if not under(name, "drape.cli")
           and any(under(m, "argparse") for m, _, _ in names)]
    assert not bad, f"argparse outside drape.cli: {bad}"


def test_imports_of_project_modules_are_at_module_top():
    """An import inside a function hides a dependency (and an import cycle): only the listed
    ones, each with its reason, stay there."""
    found = {(name, m) for name, names in project_imports().items()
             for m, in_function, _ in names if in_function and under(m, *PACKAGES)}
    assert all(FUNCTION_LEVEL_IMPORTS.values())
    assert found == set(FUNCTION_LEVEL_IMPORTS), (
        f"not listed: {sorted(found - set(FUNCTION_LEVEL_IMPORTS))}; "
        f"listed but gone: {sorted(set(FUNCTION_LEVEL_IMPORTS) - found)}")


def test_material_points_know_no_drape():
    """constitutive lies below drape. Its ``__main__`` modules are exempt: they are the entry
    points ``python -m constitutive.fit`` and ``python -m constitutive.datasets``, which hand
    the command line to drape.cli, where every tool's options are read."""
    found = {name: names for name, names in project_imports().items()
             if under(name, "constitutive") and not name.endswith(".__main__")}
    assert len(found) > 20
    bad = sorted({(name, m) for name, names in found.items() for m, _, _ in names
                  if under(m, "drape")})
    assert not bad


def test_only_entry_points_import_the_command_line():
    """drape.cli is the top layer: nothing below imports it but the entry points (a
    ``__main__`` module, or code under ``if __name__ == "__main__":``)."""
    bad = sorted({(name, m) for name, names in project_imports().items()
                  if not under(name, "drape.cli") and not name.endswith("__main__")
                  for m, _, guarded in names if under(m, "drape.cli") and not guarded})
    assert not bad


def test_entry_points_only_hand_over_to_the_command_line():
    """``python -m drape.<tool>`` and the ``__main__`` modules hold no logic: each imports its
    tool's ``main`` from drape.cli and exits with what it returns."""
    shims = {"drape.__main__": "drape.cli", "drape.run.__main__": "drape.cli.run",
             "constitutive.fit.__main__": "drape.cli.fit",
             "constitutive.datasets.__main__": "drape.cli.datasets",
             **{f"drape.{tool}": f"drape.cli.{tool}"
                for tool in ("sweep", "measure", "validate", "report", "inspect", "identify")}}
    files, found = source_files(), project_imports()
    for name, cli in shims.items():
        assert {m for m, _, _ in found[name]} == {"sys", cli}, name
        calls = [ast.unparse(n) for n in ast.walk(ast.parse(files[name].read_text()))
                 if isinstance(n, ast.Call)]
        assert calls[0] == "sys.exit(main())" and len(calls) == 2, name


def test_the_source_trees_version_is_the_distributions():
    import drape

    assert drape.__version__ == VERSION


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_drape_command_delegates_to_the_tool(command, capsys):
    from drape.cli import main

    with pytest.raises(SystemExit) as stop:
        main([command, "--help"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: python -m {COMMANDS[command]} ")


def test_drape_lists_every_command():
    from drape.cli import COMMANDS as listed

    assert set(listed) == set(COMMANDS)


@pytest.mark.parametrize("argv, code, out, err", [
    (["--help"], 0, "usage: drape COMMAND [ARGS...]\n", ""),
    (["-h"], 0, "usage: drape COMMAND [ARGS...]\n", ""),
    (["--version"], 0, f"drape {VERSION}\n", ""),
    (["nonsense"], 2, "", "error: unknown command 'nonsense' (see drape --help)\n"),
    ([], 2, "", "usage: drape COMMAND [ARGS...]\n"),
])
def test_drape_alone_answers_help_version_and_errors(argv, code, out, err, capsys):
    from drape.cli import main

    assert main(argv) == code
    printed = capsys.readouterr()
    assert printed.out.startswith(out) and printed.err.startswith(err)
    assert bool(printed.out) == bool(out) and bool(printed.err) == bool(err)


def test_drape_help_loads_no_tool():
    """``drape --help`` answers at once: no tool's module, no solver, no Dask."""
    code = ("import json, sys; from drape.cli import main; main(['--help']); "
            "print(json.dumps(sorted(sys.modules)), file=sys.stderr)")
    out = run_python(code)
    assert out.returncode == 0, out.stderr
    loaded = json.loads(out.stderr)
    assert not [m for m in loaded if under(m, "drape.run", "drape.cli.run", "distributed", "scipy")]


# ``python -m MODULE --help`` of each entry point, one interpreter for all (runpy is what -m runs)
_HELP_OF_EACH = """
import contextlib, io, json, runpy, sys, warnings
warnings.simplefilter("ignore", RuntimeWarning)     # a module run again as __main__
answers = {}
for module in sys.argv[1:]:
    sys.argv, out = [module, "--help"], io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            runpy.run_module(module, run_name="__main__", alter_sys=True)
    except SystemExit as stop:
        answers[module] = [stop.code, out.getvalue()]
print(json.dumps(answers))
"""


def test_python_m_entry_points():
    modules = ["drape", *COMMANDS.values()]
    out = run_python(_HELP_OF_EACH, *modules)
    assert out.returncode == 0, out.stderr
    answers = json.loads(out.stdout.splitlines()[-1])
    assert {m: code for m, (code, _) in answers.items()} == dict.fromkeys(modules, 0)
    assert all(text.startswith("usage:") for _, text in answers.values())


def test_the_api_reference_lists_every_identification_module():
    """``drape.identification`` exports no names of its own, so docs/api/index.rst lists its
    modules one by one; a new module must join the list to be documented."""
    listed = (ROOT / "docs" / "api" / "index.rst").read_text().split()
    assert set(modules("drape.identification")) <= set(listed)


def test_no_test_loads_a_benchmark_script():
    """What a test needs lives in the package; ``benchmarks/`` holds thin command lines over it.
    A test that names the folder in code (a path built from ``"benchmarks"``, a file under it,
    a module loaded from a file) is refused."""
    offenders = []
    for path in sorted((ROOT / "tests").rglob("*.py")):
        if path == Path(__file__).resolve():
            continue            # this rule names what it looks for
        for node in ast.walk(ast.parse(path.read_text())):
            text = node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else ""
            name = node.attr if isinstance(node, ast.Attribute) else ""
            if (text == "benchmarks" or (text.startswith("benchmarks/") and text.endswith(".py"))
                    or name in ("spec_from_file_location", "run_path")):
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert offenders == []
