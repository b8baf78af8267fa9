"""The ``nanostrength`` command."""
