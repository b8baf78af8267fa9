"""The ``ballistic-limit`` command."""
