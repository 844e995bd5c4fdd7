"""ComputePass: a pass that runs one compute program over the frame (the shape of per-pixel and
per-froxel work: on GPUs that run graphics on a few units, compute is many times faster than a
fullscreen fragment pass doing the same arithmetic)."""
from __future__ import annotations

from atmos.graph.passes import PassBuilder, PluginPass


def work_groups(size, local) -> tuple[int, ...]:
    """Work groups that cover ``size`` (w[, h[, d]]) with groups of ``local`` (the shader's local_size)."""
    groups = []
    try:
        for n, k in zip(size, local, strict=True):
            groups += (-(-int(n) // int(k)),)
    except ValueError:
        if len(groups) == min(len(size), len(local)):     # zip's: the ranks differ
            raise ValueError(f"work_groups: size {tuple(size)} and local size {tuple(local)} differ in rank") from None
        raise
    return tuple(groups)


class ComputePass(PluginPass):
    """Subclass with ``name``, ``phase``, ``compute`` (a ``.comp`` shader file), ``reads`` (names it samples)
    and ``writes`` (names it writes as images: read-modify-write ones are listed in both and are read
    as images too) and, if needed, :meth:`defines`; ``execute`` binds and dispatches with
    :meth:`PassContext.dispatch`. ``plugin`` is the plugin that made the pass (its settings).

    ``program`` comes from the GPU context's program cache with the current :meth:`defines`, so a
    setting that changes a define takes effect on the next frame. Barriers before the pass come from
    its declarations (:mod:`atmos.gpu.hazards`): no pass issues one itself.
    """
    compute: str = ""
    local_size: tuple[int, ...] = (8, 8)
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()

    def setup(self, builder: PassBuilder) -> None:
        for name in self.reads:
            builder.read(name, access="storage" if name in self.writes else "sampled")
        for name in self.writes:
            builder.write(name, access="storage")

    @property
    def program(self):
        return self.gpu.program(compute_shader=self.compute, defines=self.defines())

    def groups(self, size) -> tuple[int, ...]:
        """Work groups covering ``size`` with this pass's ``local_size``."""
        return work_groups(size, self.local_size)
