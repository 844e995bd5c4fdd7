"""TestVolumePlugin: sliced density generation into three texture sets, and its ray-march pass."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.frames import SlicedJob, SliceStage, TripleSet
from atmos.graph import FullscreenPass, PassContext, TextureDesc
from atmos.lighting import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH


@dataclass(slots=True)
class VolumeBox:
    """Where the volume sits in the world: centre and full size in metres (y is up)."""
    center: tuple = (0.0, 7.0, 0.0)
    size: tuple = (28.0, 8.0, 28.0)


class TestVolumePlugin(Plugin):
    """``resolution`` cells (x, y, z); ``slices`` slices per step; ``step_seconds`` animation time per step."""
    __test__ = False  # not a pytest test class despite the name

    def __init__(self, resolution=(64, 32, 64), slices: int = 8, step_seconds: float = 0.25,
                 box: VolumeBox | None = None, march_steps: int = 48):
        nz = resolution[2]
        if slices < 1 or nz % slices:
            raise ValueError(f"slices must be a positive divisor of the z resolution {nz} (got {slices})")
        self.resolution = tuple(int(n) for n in resolution)
        self.slices = slices
        self.step_seconds = step_seconds
        self.box = box or VolumeBox()
        self.march_steps = march_steps
        self.triple = self.job = None
        self._time = 0.0

    def build(self, app) -> None:
        app.insert_resource(self.box)
        desc = TextureDesc(self.resolution, components=1, dtype="f2")
        self.triple = TripleSet(app.gpu, {"density": desc})
        self.program = app.gpu.program(compute_shader="test_volume/density.comp")
        self.job = SlicedJob("test_volume", [SliceStage("density", self.slices, self._fill_slice)],
                             self.triple, begin=self._begin_step)
        self.job.prime()
        app.frames.add(self.job)
        app.graph.add_pass(TestVolumePass(self))

    def _begin_step(self, step: int) -> None:
        self._time = step * self.step_seconds

    def _fill_slice(self, index: int, job) -> None:
        nx, ny, nz = self.resolution
        layers = nz // self.slices
        job.target["density"].bind_to_image(0, read=False, write=True)
        self.program["time"].value = self._time
        self.program["z0"].value = index * layers
        self.program.run(math.ceil(nx / 8), math.ceil(ny / 4), math.ceil(layers / 4))
        self.program.ctx.memory_barrier()

    def cleanup(self, app) -> None:
        if self.triple is not None:
            app.frames.remove(self.job)
            self.triple.release()
            self.triple = None


class TestVolumePass(FullscreenPass):
    """Ray-marches mix(A, B, t) inside the box, occluded by scene depth, blended over the colour
    premultiplied (:meth:`PassContext.blend_over`): it covers the sky like a cloud."""
    name = "test_volume"
    fragment = "test_volume/march.frag"
    reads = (DEPTH,)

    def defines(self) -> dict:
        return {"MARCH_STEPS": self.plugin.march_steps}

    def execute(self, frame: PassContext) -> None:
        app, gpu, p = frame.data["app"], frame.gpu, self.program
        a, b, t = self.plugin.job.view()
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_over()
        a["density"].use(0)
        b["density"].use(1)
        frame.texture(DEPTH).use(2)
        set_scene_uniforms(p, app, gpu.size[0] / gpu.size[1])
        p["t"].value = t
        box = self.plugin.box
        p["box_min"].value = tuple(c - s / 2 for c, s in zip(box.center, box.size))
        p["box_max"].value = tuple(c + s / 2 for c, s in zip(box.center, box.size))
        frame.fullscreen(p)
