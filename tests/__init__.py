"""The test suite of stcs_ident, a package so that its helpers are imported by name (``tests.diagnose_cases``).

Two tiers. ``pytest`` runs the fast one (``-m 'not slow'`` in pyproject's addopts): every unit, contract and
refusal test and one end-to-end case per capability. The tests marked ``slow`` are the statistical sets and
the big end-to-end ones (coverage, acceptance, hidden-effect diagnoses, FE references); the whole suite is
``pytest -m "slow or not slow" -n auto`` (pytest-xdist: a test's numbers are the same on any worker, in any
order; a statistic over many records stays one test).
"""
