"""Acceleration records in the formats data loggers write, one module per format."""
