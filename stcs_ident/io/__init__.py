"""Reading and writing what users bring: campaign files and acceleration records.

Imports only :mod:`stcs_ident.core`.
"""
