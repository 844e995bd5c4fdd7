"""PhysicalCameraPlugin: the frame exposed by a camera in EV100, metered and adapted on the GPU, with
bloom; the present (:class:`atmos.render_core.PresentPass`) applies both.

Pass "camera_exposure" (phase present, after everything that changes ``color``): with
``auto_exposure`` a 16 × 16-group histogram of the frame's EV100 (``histogram.comp``) into a transient
buffer, then one group (``adapt.comp``) takes the filtered mean, and moves the held EV100 toward it;
without, the manual EV100. Either way it writes the buffer "camera_exposure" (``shaders/lib/camera.glsl``:
exposure, bloom weight, EV100, target), which lives across frames and which the present reads on the GPU:
no frame waits for a read-back. Pass "bloom" (``bloom`` > 0): ``bloom_levels`` halvings of ``color``
(``bloom_down.comp``), then from the smallest up each level in place half itself, half the ones below
upsampled (``bloom_up.comp``: level k weighs 2^-k, a halo that fades with distance); the present
mixes the half-size result in by ``bloom`` (energy kept). float64
twins: :mod:`.reference`.
"""
from __future__ import annotations

import numpy as np

from atmos.checks import check_num

from atmos.graph import BufferDesc, ComputePass, PassBuilder, PassContext, TextureDesc
from atmos.offscreen import low_size
from atmos.plugin import Plugin
from atmos.render_core import BLOOM, CAMERA_EXPOSURE, COLOR, present_inputs
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures, write_uniforms
from atmos.plugins.physical_camera.reference import BINS
from atmos.plugins.physical_camera.settings import PhysicalCameraSettings

HISTOGRAM = "luminance_histogram"
STATE_FIELDS = ("exposure", "bloom", "ev100", "target", "primed")    # lib/camera.glsl's floats, in order


def level_name(k: int) -> str:
    """The bloom chain's level k (1: half size, the result the present reads)."""
    return BLOOM if k == 1 else f"bloom_{k}"


def level_sizes(size, levels: int) -> list[tuple[int, int]]:
    """(w, h) of levels 1 .. ``levels``: each half the last, rounded up (``size`` / 2^k, rounded up)."""
    return [low_size(size, 2 ** k) for k in range(1, levels + 1)]


class ExposurePass(ComputePass):
    """Pass "camera_exposure": meters (or takes the manual EV100) and writes the camera's buffer."""
    name = "camera_exposure"
    phase = "present"
    local_size = (16, 16)

    def setup_key(self) -> tuple:
        return (self.plugin.settings,)

    def setup(self, builder: PassBuilder) -> None:
        s = self.plugin.settings
        if not s.enabled:
            return
        if s.auto_exposure:
            builder.read(COLOR)
            builder.create(HISTOGRAM, BufferDesc(4 * BINS, clear=True))
        builder.write(CAMERA_EXPOSURE, access="storage")

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.meter = gpu.program(compute_shader="physical_camera/histogram.comp")
        self.adapt = {m: gpu.program(compute_shader="physical_camera/adapt.comp", defines={"METERED": m}) for m in (0, 1)}

    def execute(self, frame: PassContext) -> None:
        s = self.plugin.settings
        state = frame.resource(CAMERA_EXPOSURE)
        if s.auto_exposure:
            meter, adapt, counts = self.meter, self.adapt[1], frame.resource(HISTOGRAM)
            write_uniforms(meter, ev_range=s.ev_range)
            bind_textures(meter, hdr=frame.resource(COLOR))
            bind_buffers(meter, Histogram=counts)
            dispatch(meter, *self.groups(frame.gpu.size))
            write_uniforms(adapt, ev_range=s.ev_range, metering_filter=s.metering_filter, compensation=s.compensation,
                           speed=(s.speed_up, s.speed_down, s.transition), dt=float(frame.view.clock.dt),
                           bloom_weight=s.bloom)
            bind_buffers(adapt, Histogram=counts, Camera=state)
        else:
            adapt = self.adapt[0]
            write_uniforms(adapt, manual_ev100=s.ev100, bloom_weight=s.bloom)
            bind_buffers(adapt, Camera=state)
        dispatch(adapt, 1)


class BloomPass(ComputePass):
    """Pass "bloom": the blur chain of ``color``; level 1 ("bloom", half size) is the result."""
    name = "bloom"
    phase = "present"
    _plan = None                        # (size, levels) -> [(name, desc, groups)] per level, made once per change

    def setup_key(self) -> tuple:
        return (self.plugin.settings, self.plugin.gpu.size)

    def setup(self, builder: PassBuilder) -> None:
        s = self.plugin.settings
        if not (s.enabled and s.bloom > 0.0):
            return
        builder.read(COLOR)
        for name, desc, _ in self.plan(tuple(self.plugin.gpu.size), s.bloom_levels):
            builder.create(name, desc, access="storage")

    def plan(self, size, levels: int) -> list:
        if self._plan is None or self._plan[0] != (size, levels):
            self._plan = ((size, levels), [(level_name(k), TextureDesc(wh, components=4, dtype="f2", filter="nearest",
                                                                        storage=True), self.groups(wh))
                                            for k, wh in enumerate(level_sizes(size, levels), 1)])
        return self._plan[1]

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.down = gpu.program(compute_shader="physical_camera/bloom_down.comp")
        self.up = gpu.program(compute_shader="physical_camera/bloom_up.comp")

    def execute(self, frame: PassContext) -> None:
        plan = self._plan[1]
        down, up = self.down, self.up
        source = frame.resource(COLOR)
        levels = [(frame.image(name), groups) for name, _, groups in plan]
        for image, groups in levels:
            bind_textures(down, source=source)
            bind_images(down, level=image)
            dispatch(down, *groups)
            source = image
        for k in range(len(levels) - 2, -1, -1):
            image, groups = levels[k]
            bind_textures(up, coarse=levels[k + 1][0])
            bind_images(up, level=image)
            dispatch(up, *groups)


class PhysicalCameraPlugin(Plugin):
    """Exposure in EV100 (metered and adapted, or by hand) and bloom, applied by the present:
    ``PhysicalCameraPlugin(settings=None, **fields)`` with :class:`PhysicalCameraSettings`;
    ``configure(**changes)`` changes any of them live. :meth:`read_state` reads the camera back."""

    settings_class = PhysicalCameraSettings

    def __init__(self, settings: PhysicalCameraSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.gpu = self.state = self.inputs = None

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("PhysicalCameraPlugin needs an App with a GPU context (App(gpu))")
        self.gpu = app.gpu
        self.state = app.gpu.track(app.gpu.ctx.buffer(np.zeros(8, np.float32).tobytes()))   # primed 0: meter at once
        app.graph.import_resource(CAMERA_EXPOSURE, self.state)
        app.graph.add_pass(ExposurePass(self))
        app.graph.add_pass(BloomPass(self))
        self.inputs = present_inputs(app)
        self.inputs.camera = lambda: self.settings.enabled
        self.inputs.bloom = lambda: self.settings.enabled and self.settings.bloom > 0.0

    def cleanup(self, app) -> None:
        if self.inputs is not None:
            self.inputs.camera = self.inputs.bloom = None
            self.inputs = None
        if self.state is not None:
            self.state.release()
            self.state = None

    def reset(self, ev100: float | None = None) -> None:
        """Forget the adapted EV100: None takes the next metered frame at once (a cut to another scene);
        a number adapts from that EV100 (walking out of a dark cave: from its EV)."""
        if self.state is None:
            raise RuntimeError("PhysicalCameraPlugin.reset: the plugin is not built (add it to an App)")
        state = np.zeros(8, np.float32)
        if ev100 is not None:
            ev100 = check_num("PhysicalCameraPlugin.reset", "ev100", ev100, -64.0, 64.0)
            state[[2, 3, 4]] = ev100, ev100, 1.0           # ev100, target, primed (lib/camera.glsl)
        self.gpu.hazards.use(writes=[(self.state, "copy")])
        self.state.write(state.tobytes())

    def read_state(self) -> dict:
        """The camera as last written on the GPU: exposure, bloom weight, EV100, target EV100 and whether
        it was primed (a GPU → CPU read: tests and tools, not per frame)."""
        if self.state is None:
            raise RuntimeError("PhysicalCameraPlugin.read_state: the plugin is not built (add it to an App)")
        self.gpu.hazards.use(reads=[(self.state, "copy")])
        values = np.frombuffer(self.state.read(), np.float32)[:len(STATE_FIELDS)].astype(np.float64)
        return dict(zip(STATE_FIELDS, values))
