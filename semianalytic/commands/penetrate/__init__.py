"""The ``penetrate`` command."""
