"""The import graph of fegear, read from the source (every ``import`` statement, including the
function-local ones): no cycle between packages, none between modules, and the case-file layer
``fegear.io`` reads and validates without reaching into the model layers or the pipeline above
them. The modules of the result model, the pipeline, the writers and the API stay short."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "fegear"

#: What ``fegear.io`` must not import: the model layers and everything above it.
IO_FORBIDDEN = {"ltca", "tca", "scenes", "mesh", "pipeline", "output", "sweep", "api", "cli"}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _node(module: str) -> str | None:
    """The graph node of a module: its sub-package or top-level module below ``fegear``
    (``fegear.ltca.grid`` → ``ltca``, ``fegear.api`` → ``api``); None for the package root
    (``from fegear import __version__``: the root imports nothing eagerly)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


@functools.cache
def _tree(path: Path) -> ast.Module:
    """The parsed source of one file, parsed once per session: every test reads the same
    sources, and parsing the whole package took ~1 s per test (no test changes a tree)."""
    return ast.parse(path.read_text(encoding="utf-8"))


def _imports(path: Path) -> list[tuple[str, int]]:
    """``[(imported fegear module, line)]`` of one source file, relative imports resolved."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names if a.name.startswith("fegear")]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "fegear":  # from fegear import x: x may be a sub-package
                out += [(f"fegear.{a.name}", node.lineno) for a in node.names]
            elif target.startswith("fegear."):
                out.append((target, node.lineno))
    return out


@functools.cache
def _graph() -> dict[str, dict[str, list[str]]]:
    """``{node: {imported node: ["module:line", ...]}}`` over every source file (built once per
    session, read by several tests: none changes it)."""
    graph: dict[str, dict[str, list[str]]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        src = _node(_module_name(path))
        if src is None:
            continue
        for target, line in _imports(path):
            dst = _node(target)
            if (
                dst is None
                or dst == src
                or not (PACKAGE / dst).exists()
                and not (PACKAGE / f"{dst}.py").exists()
            ):
                continue
            where = f"{path.relative_to(PACKAGE.parent)}:{line}"
            graph.setdefault(src, {}).setdefault(dst, []).append(where)
    return graph


def _cycles(graph: dict[str, dict[str, list[str]]]) -> list[list[str]]:
    """Strongly connected components with more than one node (Tarjan, 1972)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _runtime_imports(path: Path) -> list[tuple[str, int]]:
    """``[(imported fegear module, line)]`` of one source file as Python runs it: imports under
    ``if TYPE_CHECKING:`` left out (annotations only), ``from package import name`` resolved to
    the module ``package.name`` where ``name`` is one."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    tree = _tree(path)
    typing_only = {
        id(n)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for stmt in node.body
        for n in ast.walk(stmt)
    }
    out = []
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names if a.name.startswith("fegear")]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "fegear" or target.startswith("fegear."):
                out += [(f"{target}.{a.name}", node.lineno) for a in node.names]
    return out


@functools.cache
def _module_graph() -> dict[str, dict[str, list[str]]]:
    """``{module: {imported module: ["path:line", ...]}}`` over every source file (an import of
    a name resolves to the deepest module that holds it: ``fegear.ltca.grid.pair_cells`` →
    ``fegear.ltca.grid``; built once per session, read by several tests: none changes it)."""
    modules = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}
    graph: dict[str, dict[str, list[str]]] = {}
    for src, path in modules.items():
        for target, line in _runtime_imports(path):
            dst = target
            while dst and dst not in modules:
                dst = dst.rpartition(".")[0]
            if dst in ("", "fegear", src):
                continue
            where = f"{path.relative_to(PACKAGE.parent)}:{line}"
            graph.setdefault(src, {}).setdefault(dst, []).append(where)
    return graph


def _local_imports(path: Path) -> list[ast.ImportFrom | ast.Import]:
    """The imports of fegear modules inside the functions of one source file."""
    out: list[ast.ImportFrom | ast.Import] = []

    def visit(node: ast.AST, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if in_function and isinstance(child, ast.Import):
                if any(a.name.startswith("fegear") for a in child.names):
                    out.append(child)
            elif in_function and isinstance(child, ast.ImportFrom):
                if child.level or (child.module or "").startswith("fegear"):
                    out.append(child)
            visit(child, in_function or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef))

    visit(_tree(path), False)
    return out


def _has_reason(lines: list[str], node: ast.stmt, import_lines: set[int]) -> bool:
    """A ``# local:`` comment on the import or in the comments and imports right above it."""
    if any("# local:" in lines[i - 1] for i in range(node.lineno, node.end_lineno + 1)):
        return True
    i = node.lineno - 1
    while i >= 1 and (i in import_lines or lines[i - 1].strip().startswith("#")):
        if "# local:" in lines[i - 1]:
            return True
        i -= 1
    return False


#: the packages the gear-agnostic mechanics may stand on
GEAR_AGNOSTIC = {"errors", "fem", "linalg", "store"}


def test_graph_reader_sees_the_known_edges():
    """The reader is not blind: edges that must exist are found (a broken reader that returns
    nothing would pass the two tests below)."""
    g = _graph()
    assert "ltca" in g["pipeline"]  # the pipeline runs the loaded cycle
    assert "io" in g["pipeline"]  # ... of a case read by io
    assert "mechanics" in g["ltca"]  # the LTCA solves with the contact solver
    assert "pipeline" in g["output"]  # the writers read a GearRun


def test_module_graph_reader_sees_the_known_edges():
    g = _module_graph()
    assert "fegear.ltca.position" in g["fegear.ltca.fidelity"]  # FE solves a position
    assert "fegear.linalg._mkl_pardiso" in g["fegear.linalg.schur"]  # from package import module
    assert "fegear.results.build" in g["fegear.output.gear_output"]  # the writers read the model
    # annotations only: analysis's types in fidelity are no import at run time
    assert "fegear.ltca.analysis" not in g["fegear.ltca.fidelity"]


def test_module_graph_has_no_cycles():
    """No module imports, directly or through others, a module that imports it (function-local
    imports included: they hide a circle, they do not remove it)."""
    g = _module_graph()
    cycles = _cycles(g)
    detail = [
        f"{a} -> {b}: {', '.join(g[a][b])}"
        for comp in cycles
        for a in comp
        for b in comp
        if b in g.get(a, {})
    ]
    assert not cycles, "module cycles:\n" + "\n".join(detail)


#: The modules whose length is capped (lines): the result model, the pipeline, the writers, the
#: Python API. A module of one concept fits; two concepts in one module are split.
SHORT_MODULES = ("results", "pipeline", "output", "api")
MAX_LINES = 600


@pytest.mark.parametrize("part", SHORT_MODULES)
def test_result_pipeline_output_and_api_modules_are_short(part):
    root = PACKAGE / part
    paths = sorted(root.rglob("*.py")) if root.is_dir() else [PACKAGE / f"{part}.py"]
    assert paths and all(p.exists() for p in paths), part
    long = {
        str(p.relative_to(PACKAGE.parent)): n
        for p in paths
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_package_graph_has_no_cycles():
    g = _graph()
    cycles = _cycles(g)
    detail = [
        f"{a} -> {b}: {', '.join(g[a][b])}"
        for comp in cycles
        for a in comp
        for b in comp
        if b in g.get(a, {})
    ]
    assert not cycles, "package cycles:\n" + "\n".join(detail)


@pytest.mark.parametrize("layer", sorted(IO_FORBIDDEN))
def test_io_does_not_import_upwards(layer):
    """``fegear.io`` reads case files: it imports nothing from the model layers or above."""
    edges = _graph().get("io", {})
    assert layer not in edges, f"fegear.io imports fegear.{layer}: {edges.get(layer)}"


def test_contact_solver_knows_nothing_about_gears():
    """The contact solver and the linear algebra under it import no gear code."""
    g = _graph()
    for low in ("linalg", "store", "errors"):
        assert set(g.get(low, {})) <= {"errors"}, f"fegear.{low} imports {g.get(low)}"
    # the mechanics (contact solver, compliance operators) stands on the FE body, the linear
    # algebra and the cache, none of which knows a gear
    assert set(g.get("mechanics", {})) <= GEAR_AGNOSTIC, (
        f"fegear.mechanics imports {g['mechanics']}"
    )
    assert set(g.get("fem", {})) <= {"errors"}, f"fegear.fem imports {g.get('fem')}"


def test_the_case_file_fidelities_are_the_registered_ones():
    """A fidelity is registered once (:data:`fegear.ltca.fidelity.FIDELITIES`); the case-file
    choices are those plus the unloaded TCA, and every registered fidelity has the protocol."""
    from fegear.io.gear_case import FIDELITIES as CHOICES
    from fegear.io.gear_case import UNLOADED
    from fegear.ltca.fidelity import FIDELITIES, Fidelity

    assert set(CHOICES) == set(FIDELITIES) | {UNLOADED}
    for name, fid in FIDELITIES.items():
        assert fid.name == name
        for member in Fidelity.__annotations__:
            assert hasattr(fid, member), f"{name} lacks {member}"
        for method in ("layer_depth", "max_cells", "compliance", "solve_position"):
            assert callable(getattr(fid, method)), f"{name}.{method}"


def test_the_gear_families_are_the_case_kinds():
    """A gear family is registered once (:data:`fegear.pipeline.pair.FAMILIES`) for each
    ``[case] kind`` the schema accepts."""
    from fegear.io.gear_case import GEAR_KINDS
    from fegear.pipeline.pair import FAMILIES

    assert set(FAMILIES) == set(GEAR_KINDS)
    for kind, fam in FAMILIES.items():
        assert fam.kind == kind


#: The imports of fegear modules that stay inside functions. Every other import is at module
#: level: a function-local import hides a dependency from the reader (a circle stays a circle,
#: see above) and is paid on every call. These stay because the command line starts light:
#: ``fegear/cli.py`` and the CalculiX exporter (``fegear/export/__init__.py``,
#: ``fegear/export/command.py``: the command builds its parser from them) import the API, the
#: LTCA, the flank views, the sweeps and the scenes, which pull scipy and scikit-fem (~2 s),
#: only in the subcommand that uses them, so that ``fegear --help`` and ``fegear cache`` do not.
#: ``fegear/export/settings.py`` (``fegear settings``) and ``fegear accept`` likewise import
#: the API. Each carries a ``# local:`` comment with its reason. Lower this number when one goes.
MAX_LOCAL_IMPORTS = 19


def test_function_local_imports_are_few_and_say_why():
    found = {p: _local_imports(p) for p in sorted(PACKAGE.rglob("*.py")) if _local_imports(p)}
    listing = [
        f"{p.relative_to(PACKAGE.parent)}:{n.lineno}: {ast.unparse(n)}"
        for p, nodes in found.items()
        for n in nodes
    ]
    assert len(listing) <= MAX_LOCAL_IMPORTS, (
        f"{len(listing)} function-local imports of fegear modules (at most "
        f"{MAX_LOCAL_IMPORTS}): import at module level\n" + "\n".join(listing)
    )
    silent = []
    for p, nodes in found.items():
        lines = p.read_text(encoding="utf-8").splitlines()
        import_lines = {i for n in nodes for i in range(n.lineno, n.end_lineno + 1)}
        silent += [
            f"{p.relative_to(PACKAGE.parent)}:{n.lineno}"
            for n in nodes
            if not _has_reason(lines, n, import_lines)
        ]
    assert not silent, "function-local imports without a '# local:' reason: " + ", ".join(silent)


def test_the_local_import_reader_sees_them():
    """The reader is not blind: the command line's imports of the API are found."""
    names = [ast.unparse(n) for n in _local_imports(PACKAGE / "cli.py")]
    assert "from fegear.api import run" in names


def test_the_mechanics_is_a_package_of_its_own_and_knows_no_gear():
    """The gear-agnostic mechanics: its modules are in the module graph (the LTCA solves with
    its contact solver), none of them is in a cycle, and they import only the gear-agnostic
    layers (:data:`GEAR_AGNOSTIC`)."""
    g = _module_graph()
    assert "fegear.mechanics.contact" in g["fegear.ltca.position"]
    mechanics = [m for m in g if m.startswith("fegear.mechanics.")]
    assert mechanics, "the reader sees no module of fegear.mechanics"
    for m in mechanics:
        outside = {d for d in g[m] if not d.startswith("fegear.mechanics.")}
        assert {d.split(".")[1] for d in outside} <= GEAR_AGNOSTIC, f"{m} imports {sorted(g[m])}"
    in_cycles = {m for comp in _cycles(g) for m in comp}
    assert not {m for m in in_cycles if m.startswith("fegear.mechanics")}
