"""Shared by the benchmark scripts: which stcs_ident they time, and the timing helpers.

The benchmarks time the INSTALLED package (``import stcs_ident`` as the
running Python resolves it), not this checkout's source tree: a plain
checkout has no compiled kernel, so it would silently time the numpy
fallback of the forward solver. Every script prints :func:`print_header`
first: the package version, where it was imported from, and which code
path of the forward solver runs (compiled kernel or numpy fallback, and
why).

Timing an installed copy of this checkout::

    python3 -m venv /tmp/bench-venv && /tmp/bench-venv/bin/pip install .
    /tmp/bench-venv/bin/python benchmarks/forward.py
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[1]  # the checkout these scripts belong to
INSTALL_HINT = "python3 -m venv /tmp/bench-venv && /tmp/bench-venv/bin/pip install ."

try:
    import stcs_ident
except ImportError as exc:
    sys.exit(f"stcs_ident is not importable by {sys.executable} ({exc}).\n"
             f"The benchmarks time the installed package; install it first, e.g. from {CHECKOUT}:\n"
             f"    {INSTALL_HINT}\n"
             f"    /tmp/bench-venv/bin/python benchmarks/{Path(sys.argv[0]).name}")

from stcs_ident.forward import roots


def _editable_of(tree: Path) -> bool:
    """Whether this Python's stcs-ident distribution is an editable install of ``tree``."""
    from importlib.metadata import PackageNotFoundError, distribution
    from urllib.parse import unquote, urlparse

    try:
        text = distribution("stcs-ident").read_text("direct_url.json")
    except PackageNotFoundError:
        return False
    if not text:
        return False
    info = json.loads(text)
    if not info.get("dir_info", {}).get("editable", False):
        return False
    url = urlparse(info.get("url", ""))
    return url.scheme == "file" and Path(unquote(url.path)).resolve() == tree


def package_location() -> tuple[Path, str]:
    """Directory stcs_ident was imported from, and what it is."""
    pkg = Path(stcs_ident.__file__).resolve().parent
    if pkg.is_relative_to(CHECKOUT):
        how = "an editable install" if _editable_of(CHECKOUT) else "on sys.path (PYTHONPATH?), not installed"
        return pkg, f"the source tree of this checkout: {how}"
    if {"site-packages", "dist-packages"} & set(pkg.parts):
        return pkg, "site-packages: an installed copy"
    return pkg, "neither this checkout nor site-packages (another source tree?)"


def code_path() -> tuple[str, str | None]:
    """The forward solver's code path, and a warning when the kernel is missing (or may be stale)."""
    directory = Path(roots.__file__).resolve().parent
    built = sorted(p for p in directory.glob("_dsm_kernel*") if p.suffix in (".so", ".pyd"))
    forced = roots.FORCE_NUMPY
    if roots.use_kernel():
        # in a source tree (not an install's copy) the source or a header it includes may be newer
        sources = [directory / "_dsm_kernel.c", *directory.glob("_*.h")]
        newest = max(sources, key=lambda p: p.stat().st_mtime if p.exists() else 0.0)
        if (directory.is_relative_to(CHECKOUT) and newest.exists() and built
                and built[0].stat().st_mtime < newest.stat().st_mtime):
            return (f"compiled kernel ({built[0].name})",
                    (f"WARNING: {built[0].name} is older than {newest.name} beside it: it may be stale "
                    f"(rebuild it by reinstalling: pip install [-e] .)"))
        return f"compiled kernel ({built[0].name if built else roots._dsm_kernel.__file__})", None
    if roots._dsm_kernel is not None:  # built and importable, switched off
        return f"numpy fallback (STCS_IDENT_NUMPY={os.environ.get('STCS_IDENT_NUMPY')} set; kernel available)", None
    if built:
        short = "does not import"
        why = f"compiled kernel {built[0].name} is present but does not import"
        try:
            from stcs_ident.forward import _dsm_kernel  # noqa: F401
        except ImportError as exc:
            why += f": {exc}"
    else:
        short = "is not built"
        why = f"compiled kernel not built: no _dsm_kernel*.so in {directory}"
    if forced:
        why += "; STCS_IDENT_NUMPY set too"
    warning = (f"WARNING: these timings are of the NUMPY path: the compiled kernel {short} in the package imported. "
               f"To time the kernel, install the package in a fresh venv ({INSTALL_HINT}; needs a C compiler) "
               f"and run this script with /tmp/bench-venv/bin/python.")
    return f"numpy fallback ({why})", warning


def spectra_path() -> str:
    """Which code fits the spectra's bands: the compiled kernel (spectra/_whittle_kernel.c) or the numpy path."""
    from stcs_ident.spectra import whittle

    if getattr(whittle, "_whittle_kernel", None) is None:
        return "numpy (no compiled kernel in this install)" if hasattr(whittle, "_whittle_kernel") else "numpy"
    if whittle.FORCE_NUMPY:
        return "numpy (STCS_IDENT_NUMPY set; kernel available)"
    return f"compiled kernel ({os.path.basename(whittle._whittle_kernel.__file__)})"


def print_header() -> None:
    """What is being timed: package version and origin, Python, forward-solver code path."""
    pkg, where = package_location()
    path, warning = code_path()
    print(f"stcs_ident {stcs_ident.__version__} imported from {pkg}")
    print(f"  location: {where}")
    print(f"  python: {sys.executable} ({platform.python_version()})")
    print(f"  forward solver: {path}")
    print(f"  spectra fits: {spectra_path()}")
    if warning:
        print(warning)
    print(flush=True)


def wall_times(func, repeat: int) -> list[float]:
    """Wall time (s) of each of ``repeat`` calls of ``func`` (no warm-up)."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        func()
        times.append(time.perf_counter() - t)
    return times


def timed(func, repeat: int):
    """Median wall time (s) of ``repeat`` calls of ``func`` after one warm-up call, and the last call's value."""
    value = [func()]

    def call():
        value[0] = func()

    return statistics.median(wall_times(call, repeat)), value[0]


def run_cli(*args) -> float:
    """Wall time (s) of ``stcs-ident ARGS`` run with this Python's package in a child process (stdout dropped;
    a failure raises)."""
    command = [sys.executable, "-c", "import sys; from stcs_ident.cli.main import main; sys.exit(main(sys.argv[1:]))",
               *map(str, args)]
    started = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - started
