"""Spectra: acceleration records, a record simulator and modal frequency picking."""
