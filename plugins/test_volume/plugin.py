"""TestVolumePlugin: sliced density generation into three texture sets, and its ray-march pass."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_int, check_num, check_shape, check_vec
from atmos.slicing import SlicedJob, SliceTask, TripleSet
from atmos.graph import FullscreenPass, PassContext, TextureDesc
from atmos.scene_uniforms import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_images, bind_textures

TEST_VOLUME_SETS = "test_volume_sets"     # the imported (A, B, t) of the test volume's texture sets


@dataclass(frozen=True)
class VolumeBox(CheckedSettings):
    """Where the volume sits in the world: centre and full size in metres (y is up)."""
    center: tuple = (0.0, 7.0, 0.0)
    size: tuple = (28.0, 8.0, 28.0)

    def __post_init__(self):
        self.store(dict(center=check_vec("VolumeBox", "center", self.center, 3),
                        size=check_vec("VolumeBox", "size", self.size, 3, "positive")))


@dataclass(frozen=True)
class TestVolumeSettings(CheckedSettings):
    """``resolution`` cells (x, y, z) and ``slices`` slices per step (a divisor of z) size the texture
    sets and the sliced job: FIXED (``configure`` refuses them). Live: ``step_seconds`` animation
    time per step, ``box`` (a :class:`VolumeBox`) where it is drawn, ``march_steps`` (1..1024, a
    shader define: the pass fetches that program variant on the next frame)."""
    __test__ = False  # not a pytest test class despite the name
    FIXED = ("resolution", "slices")

    resolution: tuple = (64, 32, 64)
    slices: int = 8
    step_seconds: float = 0.25
    box: VolumeBox = VolumeBox()
    march_steps: int = 48

    def __post_init__(self):
        o = "TestVolumeSettings"
        resolution = check_shape(self.resolution, f"{o}.resolution")
        slices = check_int(o, "slices", self.slices, 1, resolution[2])
        if resolution[2] % slices:
            raise ValueError(f"{o}.slices must divide the z resolution {resolution[2]}, got {self.slices!r}")
        if not isinstance(self.box, VolumeBox):
            raise ValueError(f"{o}.box must be a VolumeBox, got {self.box!r}")
        self.store(dict(resolution=resolution, slices=slices,
                        step_seconds=check_num(o, "step_seconds", self.step_seconds, 0.0, lo_open=True),
                        march_steps=check_int(o, "march_steps", self.march_steps, 1, 1024)))


class TestVolumePlugin(Plugin):
    """``TestVolumePlugin(settings=None, **fields)`` with :class:`TestVolumeSettings`;
    ``configure(**changes)`` changes the live ones on the next frame."""
    __test__ = False  # not a pytest test class despite the name
    settings_class = TestVolumeSettings

    def __init__(self, settings: TestVolumeSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.triple = self.job = None
        self._time = 0.0

    def build(self, app) -> None:
        s = self.settings
        desc = TextureDesc(s.resolution, components=1, dtype="f2")
        self.triple = TripleSet(app.gpu, {"density": desc})
        self.program = app.gpu.program(compute_shader="test_volume/density.comp")
        self.job = SlicedJob("test_volume", [SliceTask("density", s.slices, self._fill_slice)],
                             self.triple, begin=self._begin_step)
        app.add_system(lambda app: self.job.prime(), "startup", label="test_volume_prime")
        app.frames.add(self.job)
        app.graph.import_resource(TEST_VOLUME_SETS, self.job.view)
        app.graph.add_pass(TestVolumePass(self))

    def _begin_step(self, step: int) -> None:
        self._time = step * self.settings.step_seconds

    def _fill_slice(self, index: int, job) -> None:
        nx, ny, nz = self.settings.resolution
        layers = nz // self.settings.slices
        bind_images(self.program, density=job.target["density"])
        self.program["time"].value = self._time
        self.program["z0"].value = index * layers
        self.program.run(math.ceil(nx / 8), math.ceil(ny / 4), math.ceil(layers / 4))
        self.program.ctx.memory_barrier()

    def cleanup(self, app) -> None:
        if self.triple is not None:
            if self.job in app.frames:              # a scene may have paused the job
                app.frames.remove(self.job)
            self.triple.release()
            self.triple = None


class TestVolumePass(FullscreenPass):
    """Ray-marches mix(A, B, t) inside the box, occluded by scene depth, blended over the colour
    premultiplied (:meth:`PassContext.blend_over`): it covers the sky like a cloud."""
    name = "test_volume"
    phase = "translucent"
    fragment = "test_volume/march.frag"
    reads = (COLOR, DEPTH, TEST_VOLUME_SETS)

    def defines(self) -> dict:
        return {"MARCH_STEPS": self.plugin.settings.march_steps}

    def execute(self, frame: PassContext) -> None:
        p = self.program
        a, b, t = frame.resource(TEST_VOLUME_SETS)
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_over()
        bind_textures(p, density_a=a["density"], density_b=b["density"], scene_depth=frame.resource(DEPTH))
        set_scene_uniforms(p, frame.view)
        p["t"].value = t
        box = self.plugin.settings.box
        p["box_min"].value = tuple(c - s / 2 for c, s in zip(box.center, box.size))
        p["box_max"].value = tuple(c + s / 2 for c, s in zip(box.center, box.size))
        frame.fullscreen(p)
