"""The ``coefficients`` command."""
