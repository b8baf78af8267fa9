"""The ``perforate`` command."""
