"""pushctl's version (``pushctl.__version__``, pyproject.toml's), named in every provenance
line: a module of its own among the shared basics, so that no module imports the package's
top and importing it loads nothing."""

VERSION = "0.1.0"
