"""CloudsPlugin: the cloud simulation chain added to an App and fed to its frame scheduler."""
from __future__ import annotations

from atmos.lighting import Sun
from atmos.plugin import Plugin
from atmos.plugins.clouds.simulation import CloudSettings, CloudSimulation
from atmos.plugins.weather import VolumeOrigin, WeatherParams


class CloudsPlugin(Plugin):
    """Weather ellipsoids → region volume → automaton → smoothing → density maps, sliced over frames.

    The shading stage reads the ``Sun`` resource's direction when a step starts (DaylightPlugin
    moves it). Resources it adds: ``WeatherParams`` (change ``cloud_density`` at run time to move the cover),
    ``VolumeOrigin`` (move it with the viewer; one already present is used) and the
    :class:`CloudSimulation` (readers take ``view()`` and ``max_maps()`` from it).
    ``warmup_steps`` whole steps run at start-up, so a scene can open on formed clouds.
    """

    def __init__(self, params: WeatherParams | None = None, settings: CloudSettings | None = None,
                 seed: int = 0, warmup_steps: int = 0):
        if not isinstance(warmup_steps, int) or warmup_steps < 0:
            raise ValueError(f"warmup_steps must be an int >= 0, got {warmup_steps!r}")
        self.params = params or WeatherParams()
        self.settings = settings
        self.seed = seed
        self.warmup_steps = warmup_steps
        self.simulation: CloudSimulation | None = None

    def build(self, app) -> None:
        if app.gpu is None:
            raise ValueError("CloudsPlugin needs an App with a GPU context (App(gpu))")
        origin = app.get_resource(VolumeOrigin) or VolumeOrigin()
        default_sun = Sun()

        def sun():
            return (app.get_resource(Sun) or default_sun).direction
        self.simulation = CloudSimulation(app.gpu, app.world, self.params, self.settings, self.seed, origin, sun)
        app.insert_resource(self.params)
        app.insert_resource(origin)
        app.insert_resource(self.simulation)
        self.simulation.job.prime()
        for _ in range(self.warmup_steps):
            self.simulation.job.run_step()
        app.frames.add(self.simulation.job)

    def cleanup(self, app) -> None:
        if self.simulation is not None:
            if self.simulation.job in app.frames:      # a scene may have paused the simulation
                app.frames.remove(self.simulation.job)
            self.simulation.release()
            self.simulation = None
