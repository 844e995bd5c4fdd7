"""ShadowMapProbe: the cloud shadow map's optical depth against the exact column sums at given world
points, on the GPU in the frame the map was baked (tests and benchmarks; shaders/clouds/shadows/probe.comp)."""
from __future__ import annotations

import numpy as np

from atmos.graph import ComputePass
from atmos.gpu.uniforms import write_uniforms
from atmos.lighting import unit_sun
from atmos.plugins.clouds.shadows.shadow_map import cloud_extinctions, read_shadow_map, use_shadow_map
from atmos.plugins.clouds.volume.column import column_uniforms
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, FAR_FIELD


class ShadowMapProbe(ComputePass):
    """Set ``points`` (n, 3); after a frame ``result`` is (n, 2): (exact, map) optical depths with the
    volume's sigma_t and, when imported, the far field's column optical depth."""
    name = "cloud_shadow_map_probe"
    phase = "post"
    compute = "clouds/shadows/probe.comp"
    local_size = (64,)

    def __init__(self, graph):
        super().__init__()
        self.graph = graph
        self.points = None
        self.result = None

    def defines(self) -> dict:
        return {"CLOUD_FAR_FIELD": 1} if self.graph.imports(FAR_FIELD) else {}

    def setup(self, builder) -> None:
        read_shadow_map(builder, self.graph)
        builder.side_effect()

    def execute(self, frame) -> None:
        if self.points is None:
            return
        ctx, p = self.gpu.ctx, self.program
        sim = frame.resource(CLOUD_SETS)
        sigma, field_tau = cloud_extinctions(frame)
        layer = frame.resource(FAR_FIELD) if frame.declares(FAR_FIELD) else None
        if layer is not None:                   # first: its measure dispatches programs of its own
            layer.prepare(frame.view, sim)
        column_uniforms(p, sim, sim.layout(), sigma)
        if layer is not None:
            layer.use(p, frame.view, sim)
            p["field_column_tau"].value = field_tau
        use_shadow_map(frame, p, sigma, field_tau)
        self.weights = (sigma, float(field_tau))
        n = len(self.points)
        pts = np.zeros((n, 4), "f4")
        pts[:, :3] = self.points
        src, out = ctx.buffer(pts.tobytes()), ctx.buffer(reserve=8 * n)
        sun = unit_sun(frame.view.sun.direction)
        write_uniforms(p, probe_sun=tuple(float(v) for v in sun), count=n)
        frame.dispatch(p, self.groups((n,)), buffers={"Points": src, "Taus": out})
        self.result = np.frombuffer(out.read(), "f4").reshape(n, 2).astype(np.float64)
        src.release()
        out.release()
        self.points = None
