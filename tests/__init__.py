"""The test suite of stcs_ident, a package so that its helpers are imported by name (``tests.diagnose_cases``)."""
