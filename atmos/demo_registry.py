"""Demo scenes: modules of ``atmos.demos`` with ``TITLE`` and ``build(app, settings)``."""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass

from atmos.checks import check_choice

DEFAULT_DEMO = "sunset"
CLOUD_RENDERERS = ("sprites", "march")
DEFAULT_CLOUDS = "march"      # the cloud renderer a cloud scene uses unless told (DemoSettings, atmos.run, --clouds)
SKY_MODELS = ("preetham", "physical")      # atmos.plugins.sky.MODELS (kept here so the CLI imports no plugin)
HAZES = ("fog", "air", "both")   # the hazy demos' distance haze: a FogPlugin toward the sky, the physical sky's
                                 # aerial perspective, or both mixed along each ray (atmos.composition)
EXPOSURES = ("auto", "fixed")    # the outdoor demos' camera: metered and adapted EV100 with bloom
                                 # (atmos.plugins.physical_camera), or RenderCoreSettings.exposure alone


def haze_conflict(haze: str, sky: str) -> str | None:
    """Why ``haze`` cannot go with ``sky`` (the end of a message; None: it can). The one rule that
    DemoSettings, ``atmos.run`` and the CLI state in their own words."""
    if haze in ("air", "both") and sky != "physical":
        return f"the physical sky's aerial perspective: it needs sky='physical', got sky={sky!r}"
    return None


@dataclass
class DemoSettings:
    size: tuple[int, int] = (960, 540)
    seed: int = 0
    frames: int | None = None     # None: until the window closes (headless: the demo's DEFAULT_FRAMES)
    headless: bool = False
    clouds: str = DEFAULT_CLOUDS  # the cloud scenes' renderer: the ray march or point sprites (key C flips it)
    sky: str = "physical"         # the sky's model in the demos with a sky (SkySettings.model)
    haze: str = "fog"             # sunset's and flight's haze: "fog" (FogPlugin toward the sky), "air" (aerial perspective) or "both"
    exposure: str = "auto"        # the outdoor demos' camera: "auto" (metered EV100 and bloom) or "fixed" (exposure 1)

    def __post_init__(self):
        check_choice("DemoSettings", "clouds", self.clouds, CLOUD_RENDERERS)
        check_choice("DemoSettings", "sky", self.sky, SKY_MODELS)
        check_choice("DemoSettings", "haze", self.haze, HAZES)
        check_choice("DemoSettings", "exposure", self.exposure, EXPOSURES)
        conflict = haze_conflict(self.haze, self.sky)
        if conflict:
            raise ValueError(f"DemoSettings.haze {self.haze!r} is {conflict} (or take haze='fog')")


def add_demo_camera(app, settings: DemoSettings) -> None:
    """The outdoor demos' camera: with ``settings.exposure`` "auto" a PhysicalCameraPlugin (metered,
    adapted EV100 and bloom); "fixed" adds nothing (RenderCoreSettings.exposure)."""
    if settings.exposure == "auto":
        from atmos.plugins.physical_camera import PhysicalCameraPlugin
        app.add_plugins(PhysicalCameraPlugin())


def list_demos() -> dict[str, str]:
    """Demo name -> one-line title."""
    import atmos.demos
    demos = {}
    for info in pkgutil.iter_modules(atmos.demos.__path__):
        if not info.name.startswith("_"):
            demos[info.name] = load_demo(info.name).TITLE
    return demos


def load_demo(name: str):
    import atmos.demos
    known = [i.name for i in pkgutil.iter_modules(atmos.demos.__path__) if not i.name.startswith("_")]
    if name not in known:
        raise ValueError(f"unknown demo {name!r}; available: {', '.join(sorted(known))} (atmos demo --list)")
    return importlib.import_module(f"atmos.demos.{name}")
