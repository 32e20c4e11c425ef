"""The ``stcs-ident`` command line: one module per command, listed in :mod:`stcs_ident.cli.commands`."""

from .commands import register_command, unregister_command
from .main import main

__all__ = ["main", "register_command", "unregister_command"]
