"""The ground floor: errors, notes, formatting, files, the cable model, records, settings and parameter kinds.

Imports nothing else of the package; every other floor builds on it.
"""
