# SPDX-License-Identifier: GPL-2.0-or-later
"""The package's shape: no import circles, one home per idea, no module too long to read."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("stickslip", "pyref")


def module_name(path):
    rel = path.relative_to(ROOT).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def imports(path, name, modules):
    """Modules of our packages that `path` imports, at module level or inside functions
    (a lazy import hides a circle, it does not remove it). `from P import M` of a
    submodule M counts as importing P.M only (P is already being imported)."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    got = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            got |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            subs = {f"{base}.{a.name}" for a in node.names} & modules
            got |= subs or {base}
    return {m for m in got if m.split(".")[0] in PACKAGES}


def graph():
    files = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")]
    names = {module_name(p): p for p in files}
    return {n: {m for m in imports(p, n, set(names)) if m in names and m != n} for n, p in names.items()}


def find_cycle(g):
    state, stack = {}, []

    def visit(n):
        state[n] = "open"
        stack.append(n)
        for m in sorted(g[n]):
            if state.get(m) == "open":
                return stack[stack.index(m):] + [m]
            if m not in state and (c := visit(m)):
                return c
        state[n] = "done"
        stack.pop()
        return None

    for n in sorted(g):
        if n not in state and (c := visit(n)):
            return c
    return None


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_circles():
    g = graph()
    # the graph holds imports made inside functions too (cli imports runner in cmd_run)
    assert len(g) > 20 and "stickslip.runner" in g["stickslip.cli"]
    assert find_cycle(g) is None, " -> ".join(find_cycle(g))


def test_pyref_knows_nothing_of_the_engines_or_the_package():
    g = graph()
    for name, deps in g.items():
        if name.startswith("pyref"):
            assert all(d.startswith("pyref") for d in deps), (name, deps)


def test_case_kinds_are_only_named_in_their_modules():
    """Report, precision, analysis and the runner loop over kinds: no kind is named there."""
    for module in ("report", "studies/precision", "analysis", "runner", "studies/report_plan"):
        text = (ROOT / "stickslip" / f"{module}.py").read_text()
        code = "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))
        for kind in ("kinds.drag", "kinds.tray", "kinds.tilt", '"grain_x"', '"plate_angle"', "grain1"):
            assert kind not in code, (module, kind)


def test_adapters_know_only_their_engine_and_the_time_series_columns():
    """stickslip/adapters/ holds the adapters and their dump readers: no case kind, study,
    benchmark, report or runner is known there (the runner calls them, not the reverse).
    stickslip.shipped (where the engines' files are, in a checkout or a wheel) knows nothing;
    stickslip.law_options (the law's options and each engine's words for them) pyref's only."""
    g = graph()
    adapters = [n for n in g if n.startswith("stickslip.adapters")]
    assert len(adapters) >= 6 and not g["stickslip.shipped"] and g["stickslip.law_options"] == {"pyref.laws"}
    for name in adapters:
        for dep in g[name]:
            assert dep.startswith(("stickslip.adapters", "pyref")) or dep in (
                "stickslip.columns", "stickslip.shipped", "stickslip.law_options"), (name, dep)


def test_benchmarks_and_studies_are_leaves():
    """Benchmarks are reached from the command line only; studies from the command line and
    the report. Nothing they do is needed to run a scene."""
    g = graph()
    for name, deps in g.items():
        for dep in deps:
            if dep.startswith("stickslip.bench") and not name.startswith("stickslip.bench"):
                assert name == "stickslip.cli", (name, dep)
            if dep.startswith("stickslip.studies") and not name.startswith(("stickslip.studies", "stickslip.bench")):
                assert name in ("stickslip.cli", "stickslip.report"), (name, dep)



def test_the_contract_is_reached_from_tests_and_tools_only():
    """stickslip/contract/ holds the law's contract and the drivers that hold each engine to it
    (they use the adapters): nothing a run needs, so no module outside it imports it."""
    g = graph()
    assert "stickslip.contract.runners" in g and "stickslip.adapters.lammps" in g["stickslip.contract.lammps"]
    for name, deps in g.items():
        if not name.startswith("stickslip.contract"):
            assert not [d for d in deps if d.startswith("stickslip.contract")], (name, deps)

# --- module size and the tools' imports -------------------------------------------------------
MAX_LINES = 600  # a module longer than this holds more than one idea: split it along them
CODE_FOLDERS = ("stickslip", "pyref", "yade_law", "tools", "deme_model")


def long_modules(root=ROOT, folders=CODE_FOLDERS, limit=MAX_LINES):
    """(path, lines) of every Python module under root/folders longer than `limit` lines."""
    out = []
    for folder in folders:
        for path in sorted((root / folder).rglob("*.py")):
            n = len(path.read_text().splitlines())
            if n > limit:
                out.append((path.relative_to(root).as_posix(), n))
    return out


def test_the_size_check_sees_a_long_module(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "short.py").write_text("x = 1\n" * 600)
    (tmp_path / "pkg" / "long.py").write_text("x = 1\n" * 601)
    assert long_modules(tmp_path, ("pkg",)) == [("pkg/long.py", 601)]


def test_no_module_is_over_600_lines():
    assert long_modules() == []


def tools_graph(folder=ROOT / "tools"):
    """{tool module: the tool modules it imports}: the scripts in tools/ import each other by
    their file names (the folder is on sys.path), at module level or inside functions."""
    names = {p.stem: p for p in folder.glob("*.py")}
    graph = {}
    for name, path in names.items():
        got = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                got |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                got.add(node.module.split(".")[0])
        graph[name] = {m for m in got if m in names and m != name}
    return graph


def test_the_tools_graph_finds_a_circle(tmp_path):
    (tmp_path / "a.py").write_text("def f():\n    import b\n")
    (tmp_path / "b.py").write_text("from a import f\n")
    (tmp_path / "c.py").write_text("import a\nimport numpy\n")
    g = tools_graph(tmp_path)
    assert g == {"a": {"b"}, "b": {"a"}, "c": {"a"}} and find_cycle(g) == ["a", "b", "a"]


def test_no_import_circles_in_tools():
    g = tools_graph()
    assert "deme_plane_emulation" in g["deme_gpu_check"]  # (an import inside a function counts)
    assert find_cycle(g) is None, " -> ".join(find_cycle(g))
