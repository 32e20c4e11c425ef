"""The package's floors, checked on its source: each module imports only from its own floor or the floors
below, no import circle (function-level imports count: one must not hide a circle), no private name taken
from another module, and no file read outside ``io/`` (the report writers aside).

The floors, bottom up (README, "Layout"): core, io, effects, forward, spectra, simulate, identify, diagnose,
track, report, cli; the package's face (``stcs_ident/__init__.py``) stands above them all.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import stcs_ident

PACKAGE = Path(stcs_ident.__file__).parent
FLOORS = ("core", "io", "effects", "forward", "spectra", "simulate", "identify", "diagnose", "track", "report", "cli")
#: Where a file may be read: the readers of io/, and the report writers (they read back what they wrote to
#: check it, and the fonts and styles matplotlib opens).
READERS = ("io",)
#: The one writer below report/: core/files.py puts every output in place whole (its ``open`` takes the
#: caller's write mode, and it opens the finished temporary read-only only to fsync it).
WRITERS = ("stcs_ident.core.files",)
#: Calls that read a file (by the callee's last name, or ``module.name``).
READ_CALLS = {"open", "read_text", "read_bytes", "File", "load", "loadtxt", "genfromtxt", "fromfile", "read_csv",
              "read_parquet", "read_table", "read_hdf", "read_json", "read_excel", "ParquetFile", "TdmsFile"}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _sources() -> dict[str, tuple[Path, ast.Module]]:
    return {_module_name(p): (p, ast.parse(p.read_text(encoding="utf-8"))) for p in sorted(PACKAGE.rglob("*.py"))}


SOURCES = _sources()
#: Compiled kernels (a C source beside the modules) are modules too.
EXTENSIONS = {_module_name(p.with_suffix(".py")) for p in PACKAGE.rglob("*.c")}


def _floor(module: str) -> int:
    """Index of a module's floor in :data:`FLOORS`; the face (the package itself) is above them all."""
    parts = module.split(".")
    if len(parts) == 1:
        return len(FLOORS)
    assert parts[1] in FLOORS, f"{module} is on no floor (the package root holds only its face)"
    return FLOORS.index(parts[1])


def _imports(module: str, path: Path, tree: ast.Module):
    """(line, imported module, imported names) of every import of the package anywhere in ``tree``."""
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "stcs_ident":
                    yield node.lineno, alias.name, ()
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "stcs_ident":
                continue
            names = []
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                if sub in SOURCES or sub in EXTENSIONS:
                    yield node.lineno, sub, ()
                else:
                    names.append(alias.name)
            if names:
                yield node.lineno, target, tuple(names)


EDGES = {m: [(line, t, names) for line, t, names in _imports(m, p, tree)] for m, (p, tree) in SOURCES.items()}


def test_every_module_stands_on_a_floor():
    for module in SOURCES:
        _floor(module)


@pytest.mark.parametrize("floor", FLOORS)
def test_a_floor_imports_only_from_itself_and_the_floors_below(floor):
    level = FLOORS.index(floor)
    upward = [f"{m}:{line} imports {t}" for m, edges in EDGES.items() if m.split(".")[1:2] == [floor]
              for line, t, _ in edges if t not in EXTENSIONS and _floor(t) > level]
    assert not upward, "\n".join(upward)


def test_no_import_circle():
    graph = {m: {t for _, t, _ in edges if t in SOURCES and t != m} for m, edges in EDGES.items()}
    # Tarjan's strongly connected components, iteratively.
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles = []
    for root in list(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    component = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        component.append(w)
                        if w == v:
                            break
                    if len(component) > 1:
                        circles.append(sorted(component))
    assert not circles, circles


def test_no_private_name_is_imported_from_another_module():
    private = [f"{m}:{line} imports {name} from {t}" for m, edges in EDGES.items()
               for line, t, names in edges for name in names if name.startswith("_") and name != "__version__"]
    assert not private, "\n".join(private)


def _callee(node: ast.Call) -> str:
    func = node.func
    if isinstance(func, ast.Attribute):
        return func.attr
    return func.id if isinstance(func, ast.Name) else ""


def test_no_file_is_read_outside_io():
    """Reading is io/'s job: a call that opens or loads a file elsewhere (``open`` in a mode that reads,
    ``h5py.File``, ``pandas.read_*``, ``numpy.load``, ``tomllib.load``, ``Path.read_text``...) is refused;
    writing goes through core/files.py's atomic writers and report/."""
    found = []
    for module, (path, tree) in SOURCES.items():
        floor = module.split(".")[1] if "." in module else ""
        if floor in READERS or floor == "report" or module in WRITERS:
            continue
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call) or _callee(node) not in READ_CALLS:
                continue
            if _callee(node) in ("open", "File") and _writes(node):
                continue
            found.append(f"{module}:{node.lineno} {ast.unparse(node.func)}(...)")
    assert not found, "\n".join(found)


def _writes(node: ast.Call) -> bool:
    """Whether an ``open``/``File`` call names a mode that writes (``"w"``, ``"a"``, ``"x"``, ``"wb"``...)."""
    modes = [a for a in node.args[1:2]] + [k.value for k in node.keywords if k.arg == "mode"]
    if isinstance(node.func, ast.Attribute) and node.func.attr == "open":  # path.open(mode)
        modes = [a for a in node.args[:1]] + [k.value for k in node.keywords if k.arg == "mode"]
    return any(isinstance(m, ast.Constant) and isinstance(m.value, str) and set(m.value) & set("wax")
               for m in modes)
