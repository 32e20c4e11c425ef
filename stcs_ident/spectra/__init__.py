"""Spectra: acceleration records and modal frequency picking (the simulator is :mod:`stcs_ident.simulate`)."""
