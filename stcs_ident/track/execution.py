"""Where ``track``'s batches run: local worker processes or a Dask cluster, stopped cleanly either way.

- **Ctrl-C** (``KeyboardInterrupt``) cancels what is queued, stops the
  workers and is raised again for the caller (the command line says it in
  one line): every part of the table written before stays, and the next run
  skips its records. The workers ignore ``SIGINT`` themselves, so one
  Ctrl-C reaches the parent only and is handled once.
- **Workers never outlive the parent**: each local worker dies when its
  parent does, however the parent ends (``kill -9`` included): on Linux
  the system kills it (``PR_SET_PDEATHSIG``), and everywhere a watcher
  thread ends it within :data:`WATCH_INTERVAL` of the parent's end.
- **A scheduler address** is checked at once (:func:`check_scheduler`: a
  malformed one is refused before any work), and the service behind it
  must answer as a Dask scheduler within :data:`CONNECT_TIMEOUT` seconds
  (:func:`probe_scheduler`): an unreachable address or a service that is
  not Dask is refused within the timeout, never a hang.
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterable

from ..core.errors import InputError

__all__ = ["CONNECT_TIMEOUT", "WATCH_INTERVAL", "check_scheduler", "probe_scheduler", "run_dask", "run_local"]

#: Seconds to reach a Dask scheduler and read its greeting.
CONNECT_TIMEOUT = 10.0
#: Seconds between a worker's checks that its parent is alive.
WATCH_INTERVAL = 0.5

_SCHEMES = ("tcp", "tls", "ucx", "ws", "wss")
_ADDRESS = re.compile(r"(?:(?P<scheme>[a-z]+)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(?P<port>\d{1,5})")


def check_scheduler(address) -> tuple[str, str, int]:
    """``address`` as (scheme, host, port): ``[tcp|tls|ucx|ws|wss://]host:port`` with a port 1 … 65535 (or
    ``inproc://...``, a cluster in this process), else an :class:`~stcs_ident.core.errors.InputError`
    naming ``--scheduler`` (before any work)."""
    if isinstance(address, str) and address.startswith("inproc://") and len(address) > len("inproc://"):
        return "inproc", address[len("inproc://"):], 0  # a cluster in this process (a library caller's)
    m = _ADDRESS.fullmatch(address) if isinstance(address, str) else None
    scheme = (m["scheme"] or "tcp") if m else None
    if m is None or scheme not in _SCHEMES or not 1 <= int(m["port"]) <= 65535:
        raise InputError(f"is not a Dask scheduler address: {address!r} (expected [tcp://]host:port, such as "
                         "tcp://10.0.0.5:8786)", field="--scheduler")
    return scheme, m["host"].strip("[]"), int(m["port"])


def probe_scheduler(address: str, timeout: float | None = None) -> None:
    """Refuse, within ``timeout`` seconds, a ``tcp://`` address where no Dask scheduler answers: nothing
    listening, no route, or a service that does not greet as Dask does (a scheduler sends its handshake,
    which names its ``pickle-protocol``, as soon as it accepts). For ``tls://``, ``ws://`` and ``wss://``
    only whether something listens is checked (the greeting is wrapped), the rest is left to Dask's own
    timeout; ``ucx://`` and ``inproc://`` are not probed. ``timeout`` defaults to :data:`CONNECT_TIMEOUT`."""
    timeout = CONNECT_TIMEOUT if timeout is None else timeout
    scheme, host, port = check_scheduler(address)
    if scheme in ("ucx", "inproc"):
        return
    deadline = time.monotonic() + timeout
    try:
        with socket.create_connection((host, port), timeout=timeout) as conn:
            if scheme != "tcp":  # TLS or a websocket: only whether something listens (its greeting is wrapped)
                return
            greeting = b""
            while b"pickle-protocol" not in greeting and len(greeting) < 65536:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError
                conn.settimeout(left)
                chunk = conn.recv(4096)
                if not chunk:
                    break
                greeting += chunk
    except TimeoutError:
        raise InputError(f"no Dask scheduler answered at {address} within {timeout:g} s (is it a Dask "
                         "scheduler's address?)", field="--scheduler") from None
    except OSError as err:
        raise InputError(f"cannot reach the scheduler at {address}: {err.strerror or err}",
                         field="--scheduler") from None
    if b"pickle-protocol" not in greeting:
        raise InputError(f"the service at {address} is not a Dask scheduler (it did not greet as one)",
                         field="--scheduler")


def _take(iterator, n: int) -> list:
    out = []
    for item in iterator:
        out.append(item)
        if len(out) >= n:
            break
    return out


def run_local(batches: Iterable[tuple], workers: int, work: Callable, done: Callable[[list], None]) -> None:
    """``work(*batch)`` for every batch on ``workers`` local processes, ``done(rows)`` in this process as each
    finishes (at most ``2 * workers`` batches queued). Ctrl-C or any failure stops the workers at once and is
    raised again; what ``done`` wrote stays."""
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
    queue = iter(batches)
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_worker_start, initargs=(os.getpid(),))
    try:
        running = {pool.submit(work, *job) for job in _take(queue, 2 * workers)}
        while running:
            finished, running = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                done(future.result())
            running |= {pool.submit(work, *job) for job in _take(queue, len(finished))}
    except BaseException:
        _stop(pool)
        raise
    pool.shutdown()


def _stop(pool) -> None:
    """Cancel the queued batches and end the workers now (their running batch is lost, never half-written)."""
    pool.shutdown(wait=False, cancel_futures=True)
    processes = list((getattr(pool, "_processes", None) or {}).values())  # the executor has no public handle
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(timeout=5)


def _worker_start(parent: int) -> None:
    """In each worker: Ctrl-C is the parent's to handle, and the worker ends with its parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG: killed by the system when the parent ends
        except (OSError, AttributeError):  # no prctl: the watcher below is enough
            pass
    if os.getppid() != parent:  # the parent ended before prctl took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True, name="stcs-parent-watch").start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(WATCH_INTERVAL)
    os._exit(1)  # orphaned: nobody will read what this worker would write


def run_dask(batches: Iterable[tuple], scheduler: str, work: Callable, done: Callable[[list], None],
             timeout: float | None = None) -> None:
    """``work(*batch)`` for every batch on the Dask cluster at ``scheduler``, ``done(rows)`` here as each
    finishes (twice the cluster's threads queued). The address is checked and the scheduler probed first
    (:func:`probe_scheduler`); Ctrl-C or any failure cancels what the cluster still holds and is raised
    again; what ``done`` wrote stays."""
    check_scheduler(scheduler)
    timeout = CONNECT_TIMEOUT if timeout is None else timeout
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise InputError("needs Dask distributed: pip install 'dask[distributed]'", field="--scheduler") from None
    probe_scheduler(scheduler, timeout)
    try:
        client = Client(scheduler, timeout=f"{timeout:g}s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as err:
        raise InputError(f"cannot reach the scheduler at {scheduler}: {err}", field="--scheduler") from None
    submitted = []
    try:
        queue = iter(batches)
        n = max(2, 2 * sum(client.nthreads().values()))
        submitted = [client.submit(work, *job, pure=False) for job in _take(queue, n)]
        futures = as_completed(submitted, loop=client.loop)
        for future in futures:
            done(future.result())
            for job in _take(queue, 1):
                submitted.append(client.submit(work, *job, pure=False))
                futures.add(submitted[-1])
    except BaseException:
        with contextlib.suppress(Exception):  # stopping: the cluster may be gone already; the original error matters
            client.cancel([f for f in submitted if not f.done()], force=True)
        raise
    finally:
        client.close(timeout=timeout)
