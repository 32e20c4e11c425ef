"""stcs-ident: cable force and bending stiffness from vibration records."""

__version__ = "0.1.0"
