"""The ``cavity`` command."""
