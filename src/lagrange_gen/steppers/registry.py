"""Registry of stepper methods and the glue each one emits into a generated module."""

METHODS = ()


def glue_source(method: str) -> str:
    raise KeyError(method)
