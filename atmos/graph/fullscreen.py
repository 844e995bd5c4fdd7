"""FullscreenPass: a pass that draws one fullscreen-triangle program (the shape of most effects)."""
from __future__ import annotations

from atmos.graph.passes import PassBuilder, PluginPass


class FullscreenPass(PluginPass):
    """Subclass with ``name``, ``phase``, ``fragment`` (a shader file; ``vertex`` is the fullscreen
    triangle), ``reads`` and ``writes``
    (resource names) and, if needed, :meth:`defines`; ``execute`` binds a target and calls
    ``frame.fullscreen(self.program)``. ``plugin`` is the plugin that made the pass (its settings).

    ``program`` comes from the GPU context's program cache each time it is asked for, with the
    current :meth:`defines`, so a setting that changes a define takes effect on the next frame.
    A pass that blends onto ``color`` lists it in ``reads`` and ``writes``.
    """
    fragment: str = ""
    vertex: str = "lib/fullscreen.vert"
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ("color",)

    def setup(self, builder: PassBuilder) -> None:
        for name in self.reads:
            builder.read(name)
        for name in self.writes:
            builder.write(name)

    @property
    def program(self):
        return self.gpu.program(vertex_shader=self.vertex, fragment_shader=self.fragment,
                                defines=self.defines())
