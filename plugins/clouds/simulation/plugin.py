"""CloudsPlugin: the cloud simulation chain added to an App and fed to its frame scheduler."""
from __future__ import annotations

from atmos.lighting import Sun
from atmos.plugin import Plugin
from atmos.plugins.clouds.volume.field_demand import field_demand
from atmos.plugins.clouds.volume.shape import drawn_shape
from atmos.plugins.clouds.volume.sets import CLOUD_SETS
from atmos.plugins.clouds.simulation.chain import CloudSettings, CloudSimulation
from atmos.checks import check_int
from atmos.plugins.clouds.simulation.static import StaticClouds
from atmos.plugins.clouds.light.grid import check_density
from atmos.plugins.clouds.weather import VolumeOrigin


class CloudsPlugin(Plugin):
    """Weather ellipsoids → region volume → automaton → smoothing → density maps, sliced over frames.

    ``CloudsPlugin(settings=None, *, seed=0, warmup_steps=0, density=None, **fields)`` with :class:`CloudSettings`
    (its ``weather`` field the :class:`~atmos.plugins.clouds.weather.WeatherSettings`);
    ``configure(**changes)`` changes the live ones (``configure(weather={"cloud_density": 300})``
    moves the cover from the next step on). ``seed`` (the random streams) and ``warmup_steps``
    (whole steps run at start-up, so a scene can open on formed clouds) are how it starts, not settings.
    The shading task reads the ``Sun`` resource's direction when a step starts (DaylightPlugin
    moves it). Resources it adds: ``VolumeOrigin`` (move it with the viewer; one already present is
    used) and the :class:`CloudSimulation` (readers take ``view()`` and ``max_maps()`` from it).
    ``density``: a float volume ``[x, y, z]`` (>= 0) drawn as static clouds instead, placed by the
    documented layout (:class:`~atmos.plugins.clouds.simulation.static.StaticClouds`; no automaton or weather;
    the settings' medium, light, cell size and base altitude apply).
    """

    settings_class = CloudSettings

    def __init__(self, settings: CloudSettings | None = None, *, seed: int = 0, warmup_steps: int = 0,
                 density=None, **fields):
        super().__init__(settings, **fields)
        self.density = None if density is None else check_density(density)
        self.seed = check_int("CloudsPlugin", "seed", seed, 0, 2**32 - 1)
        self.warmup_steps = check_int("CloudsPlugin", "warmup_steps", warmup_steps, 0, 10**6)
        self.simulation: CloudSimulation | None = None

    def configure(self, **changes) -> CloudSettings:
        settings = super().configure(**changes)
        if self.simulation is not None:
            self.simulation.settings = settings       # what its next step (and frame) reads
        return settings

    def build(self, app) -> None:
        if app.gpu is None:
            raise ValueError("CloudsPlugin needs an App with a GPU context (App(gpu))")
        origin = app.get_resource(VolumeOrigin) or VolumeOrigin()
        default_sun = Sun()

        def sun():
            return (app.get_resource(Sun) or default_sun).direction
        if self.density is not None:
            self.simulation = StaticClouds(app.gpu, self.density, self.settings, origin, sun, field_demand(app))
            self.simulation.drawn = drawn_shape(app)
            app.insert_resource(origin)
            app.graph.import_resource(CLOUD_SETS, self.simulation.sets)
            return
        self.simulation = CloudSimulation(app.gpu, app.world, self.settings, self.seed, origin, sun, field_demand(app))
        self.simulation.drawn = drawn_shape(app)
        app.insert_resource(origin)
        app.insert_resource(self.simulation)
        app.graph.import_resource(CLOUD_SETS, self.simulation.sets)
        app.add_system(self._warm_up, "startup", label="clouds_warm_up")
        app.frames.add(self.simulation.job)

    def _warm_up(self, app) -> None:
        """Fill sets A and B (and ``warmup_steps`` more steps) before the first frame; at start-up,
        not in ``build``, so building a scene (``atmos graph``) runs no simulation."""
        self.simulation.warm_up(self.warmup_steps)

    def cleanup(self, app) -> None:
        if self.simulation is not None:
            if self.simulation.drawn is not None:
                self.simulation.drawn.release()
            app.graph.remove_import(CLOUD_SETS)
            if isinstance(self.simulation, CloudSimulation) and self.simulation.job in app.frames:      # a scene may have paused the simulation
                app.frames.remove(self.simulation.job)
            self.simulation.release()
            self.simulation = None
