"""Benchmarks of stcs_ident, run as scripts; a package so that the tests import the recipes they share
(``benchmarks.calibrate_spectra``, ``benchmarks.calibrate_damping``) by name."""
