"""The render graph's error type."""


class GraphError(RuntimeError):
    """A render graph that cannot be compiled or run; the message names the passes and resources involved."""
