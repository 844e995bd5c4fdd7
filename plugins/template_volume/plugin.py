"""TemplateVolumePlugin: sliced density generation into three texture sets, and its ray-march pass."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_int, check_shape, int_field, num_field, vec_field
from atmos.slicing import SlicedJob, SliceTask, TripleSet
from atmos.graph import ComputePass, PassContext, TextureDesc
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_images, write_uniforms
from atmos.gpu.hazards import dispatch

TEMPLATE_VOLUME_SETS = "template_volume_sets"     # the imported (A, B, t) of the template volume's texture sets


@dataclass(frozen=True)
class VolumeBox(CheckedSettings):
    """Where the volume sits in the world, in metres (y is up)."""
    center: tuple = vec_field((0.0, 7.0, 0.0), 3, doc="the box's centre (x, y, z)")
    size: tuple = vec_field((28.0, 8.0, 28.0), 3, "positive", "the box's full size (x, y, z)")


@dataclass(frozen=True)
class TemplateVolumeSettings(CheckedSettings):
    """The template volume: a sliced job fills its texture sets, a pass marches it. ``resolution`` and
    ``slices`` size the texture sets and the job: FIXED (``configure`` refuses them); the others are live.

    Checked by hand (not in the list below):

    ``resolution`` = (64, 32, 64): cells (x, y, z) of the texture sets (three positive ints; fixed).
    ``slices`` = 8: slices the job fills per step, a divisor of the z resolution (1..z; fixed).
    ``box`` = VolumeBox(): where the volume is drawn (a :class:`VolumeBox`).
    """
    __test__ = False  # not a pytest test class despite the name
    FIXED = ("resolution", "slices")

    resolution: tuple = (64, 32, 64)
    slices: int = 8
    step_seconds: float = num_field(0.25, 0.0, doc="animation time per step", lo_open=True)
    box: VolumeBox = VolumeBox()
    march_steps: int = int_field(48, 1, 1024, "samples per ray, a shader define: the pass fetches that "
                                 "program variant on the next frame")

    def __post_init__(self):
        super().__post_init__()
        o = "TemplateVolumeSettings"
        resolution = check_shape(self.resolution, f"{o}.resolution")
        slices = check_int(o, "slices", self.slices, 1, resolution[2])
        if resolution[2] % slices:
            raise ValueError(f"{o}.slices must divide the z resolution {resolution[2]}, got {self.slices!r}")
        if not isinstance(self.box, VolumeBox):
            raise ValueError(f"{o}.box must be a VolumeBox, got {self.box!r}")
        self.store(dict(resolution=resolution, slices=slices))


class TemplateVolumePlugin(Plugin):
    """``TemplateVolumePlugin(settings=None, **fields)`` with :class:`TemplateVolumeSettings`;
    ``configure(**changes)`` changes the live ones on the next frame."""
    __test__ = False  # not a pytest test class despite the name
    settings_class = TemplateVolumeSettings

    def __init__(self, settings: TemplateVolumeSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.triple = self.job = None
        self._time = 0.0

    def build(self, app) -> None:
        s = self.settings
        desc = TextureDesc(s.resolution, components=1, dtype="f2")
        self.triple = TripleSet(app.gpu, {"density": desc})
        self.program = app.gpu.program(compute_shader="template_volume/density.comp")
        self.job = SlicedJob("template_volume", [SliceTask("density", s.slices, self._fill_slice)],
                             self.triple, begin=self._begin_step)
        app.add_system(lambda app: self.job.prime(), "startup", label="template_volume_prime")
        app.frames.add(self.job)
        app.graph.import_resource(TEMPLATE_VOLUME_SETS, self.job.view)
        app.graph.add_pass(TemplateVolumePass(self))

    def _begin_step(self, step: int) -> None:
        self._time = step * self.settings.step_seconds

    def _fill_slice(self, index: int, job) -> None:
        nx, ny, nz = self.settings.resolution
        layers = nz // self.settings.slices
        bind_images(self.program, density=job.target["density"])
        self.program["time"].value = self._time
        self.program["z0"].value = index * layers
        dispatch(self.program, math.ceil(nx / 8), math.ceil(ny / 4), math.ceil(layers / 4))

    def cleanup(self, app) -> None:
        if self.triple is not None:
            if self.job in app.frames:              # a scene may have paused the job
                app.frames.remove(self.job)
            self.triple.release()
            self.triple = None


class TemplateVolumePass(ComputePass):
    """Ray-marches mix(A, B, t) inside the box, occluded by scene depth, one compute invocation per pixel,
    composited over the colour premultiplied (``template_volume/march.comp``): it covers the sky like a
    cloud."""
    name = "template_volume"
    phase = "translucent"
    compute = "template_volume/march.comp"
    reads = (COLOR, DEPTH, TEMPLATE_VOLUME_SETS)
    writes = (COLOR,)

    def defines(self) -> dict:
        return {"MARCH_STEPS": self.plugin.settings.march_steps}

    def execute(self, frame: PassContext) -> None:
        p = self.program
        a, b, t = frame.resource(TEMPLATE_VOLUME_SETS)
        box = self.plugin.settings.box
        write_uniforms(p, t=t, box_min=tuple(c - s / 2 for c, s in zip(box.center, box.size)),
                       box_max=tuple(c + s / 2 for c, s in zip(box.center, box.size)))
        color = frame.image(COLOR)
        frame.dispatch(p, self.groups(color.size), textures={"density_a": a["density"], "density_b": b["density"],
                                                             "scene_depth": DEPTH}, images={"color_image": color})
