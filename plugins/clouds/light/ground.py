"""The clouds' shadow on the ground as the clouds' light from below sees it: ``G`` of
:mod:`atmos.plugins.clouds.light.medium`, the ground's mean sun transmittance, so the ground under an
overcast sends back sky light only and cloud bases darken as they should.

Once per frame (phase shadows) one work group (``shaders/clouds/light/ground.comp``) averages
``exp(−τ)`` over ``GRID × GRID`` ground points whose rays toward the sun cross the layer's middle plane
at an even grid over the volume's footprint (τ = sigma × the column sum there, as the ground shadows
take it), weighted by the volume's edge weight (the far field beyond the fade continues the volume's
own statistics, so its core stands for the sky around); sets A and B each over their own footprint,
mixed by t, so ``G`` runs on smoothly when a step arrives at a moved placement; and writes ``G`` into the
16-byte buffer ``"cloud_ground"``; the cloud renderers read it as the uniform block ``CloudGround``
(``clouds/volume/volume.glsl``): nothing is read back.
"""
from __future__ import annotations

import numpy as np

from atmos.graph import BufferDesc, ComputePass
from atmos.gpu.uniforms import bind_blocks
from atmos.plugins.clouds.volume.column import column_uniforms, drawn_types
from atmos.plugins.clouds.volume.sets import CLOUD_SETS

GROUND = "cloud_ground"                # buffer: vec4 (G, 0, 0, 0)
GROUND_BLOCK = "CloudGround"           # volume.glsl's uniform block that reads it
GRID = 64                              # ground.comp's GRID: sample points per side of the footprint


class GroundSunPass(ComputePass):
    """Writes "cloud_ground" from "cloud_sets"; culled unread."""
    name = "cloud_ground"
    phase = "shadows"
    compute = "clouds/light/ground.comp"
    local_size = (256,)

    def __init__(self, graph):
        super().__init__()
        self.graph = graph

    def setup_key(self) -> tuple:
        return (self.graph.imports(CLOUD_SETS),)

    def setup(self, builder) -> None:
        if not self.graph.imports(CLOUD_SETS):
            return
        builder.create(GROUND, BufferDesc(16), access="storage")
        builder.read(CLOUD_SETS)

    def execute(self, frame) -> None:
        p, sim = self.program, frame.resource(CLOUD_SETS)
        column_uniforms(p, sim, sim.layout(), float(sim.settings.sigma))
        frame.dispatch(p, (1,), buffers={GROUND_BLOCK: GROUND})


def ground_sun_pass(graph) -> GroundSunPass:
    """The graph's GroundSunPass, added by the first cloud renderer that reads it."""
    return graph.shared_pass(GroundSunPass, lambda: GroundSunPass(graph))[0]


def bind_ground(program, buffer) -> None:
    """Bind ``buffer`` (the frame's "cloud_ground") at ``program``'s CloudGround block, where it has one."""
    bind_blocks(program, {GROUND_BLOCK: buffer})


def ground_sun_reference(sums_a, sums_b, t: float, layout, extinction: float, edge_fade: float = 0.0,
                         cloud_type=None, type_map=None) -> float:
    """float64 G: ground.comp's mix over t of each set's edge-weighted mean of exp(−extinction × column
    sum) over its points (``sums_a``/``sums_b``: the (nx, nz) top-view sums of sets A and B, each at its
    own placement; ``layout``: the volume's shape and cells); each sum the shape drawn with ``cloud_type``
    / ``type_map`` (:func:`~atmos.plugins.clouds.volume.shape.typed_column`; both None: as simulated)."""
    from atmos.plugins.clouds.shadows.reference import zero_border_bilinear
    from atmos.plugins.clouds.volume.edge import edge_weight
    from atmos.plugins.clouds.volume.shape import typed_column
    shape = np.array([layout.shape[0], layout.shape[2]], np.float64)
    k = np.arange(GRID, dtype=np.float64) + 0.5
    v = np.stack(np.meshgrid(k * shape[0] / GRID - 0.5, k * shape[1] / GRID - 0.5, indexing="xy"), -1)
    w = edge_weight((v + 0.5) / shape, edge_fade)
    lo, cell = np.asarray(layout.lo, np.float64), np.asarray(layout.cell, np.float64)
    x, z = lo[0] + (v[..., 0] + 0.5) * cell[0], lo[2] + (v[..., 1] + 0.5) * cell[2]
    g = [(w * np.exp(-extinction * typed_column(zero_border_bilinear(np.asarray(s, np.float64), v), x, z,
                                                 layout.shape[1], cloud_type, type_map))).sum() / w.sum()
         for s in (sums_a, sums_b)]
    return float((1.0 - t) * g[0] + t * g[1])


def ground_sun_of(sets) -> float:
    """float64 G for a frame's CloudSets from the column sums its maps hold on the GPU (a read back:
    tests and benchmarks, not per frame)."""
    a, b, t = sets.view()
    sums = []
    for texture_set in (a, b):
        tex = sets.maps_of(texture_set).sums
        nx, nz = tex.size[:2]
        sums.append(np.frombuffer(tex.read(), np.float32).reshape(-1, nz, nx)[0].T.astype(np.float64))
    return ground_sun_reference(sums[0], sums[1], t, sets.layout(), float(sets.settings.sigma),
                                float(sets.settings.edge_fade), **drawn_types(sets))
