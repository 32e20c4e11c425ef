"""The package's version (also ``stcs_ident.__version__``), on the ground floor so that any floor may say it."""

__version__ = "0.1.0"
