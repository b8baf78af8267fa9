"""The case layer's section schemas (pydantic), one module per model package: a case file's
section -> frozen dataclasses of SI values for the models (ARCHITECTURE.md)."""
