"""Ctrl-C that lands while Python runs a finaliser or a weakref callback prints no traceback: the command's one
line says it was interrupted (the Ctrl-C test of tests/test_outputs.py once saw "Exception ignored in:
<function WeakValueDictionary...remove> Traceback ... KeyboardInterrupt" under load)."""

import gc
import importlib
import signal
import sys

cli_main = importlib.import_module("stcs_ident.cli.main")  # the module (the package's face binds the function)


class _Finalised:
    def __init__(self, error):
        self.error = error

    def __del__(self):
        raise self.error  # as SIGINT's handler does, had the signal landed in this finaliser


def test_an_interrupt_in_a_finaliser_is_not_printed_other_errors_are(monkeypatch):
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", lambda info: seen.append(info.exc_type))
    monkeypatch.setattr(signal, "getsignal", lambda _: signal.default_int_handler)  # as in a plain process
    monkeypatch.setattr(signal, "signal", lambda *_: None)  # the test's own handler stays
    with cli_main._ctrl_c():
        for error in (KeyboardInterrupt, ValueError):
            obj = _Finalised(error)
            del obj
            gc.collect()
    assert seen == [ValueError]  # the interrupt swallowed (main() says it once), anything else reported
