"""The command layer: one folder per command (argument parsing, pipeline, evaluation, studies,
report) over the model packages, which import none of it (ARCHITECTURE.md)."""
