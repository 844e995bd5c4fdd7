"""How translucent layers give the media passes a distance of their own.

Clouds write no scene depth (they are not opaque), so a media pass (fog) would attenuate a cloud
by whatever lies behind it. A translucent layer that knows its distance draws it premultiplied
into ``"cloud_distance"`` (RG float32, full frame, blended like its colour: ONE,
ONE_MINUS_SRC_ALPHA over a target cleared to 0): ``r = Σ aᵢ dᵢ Πⱼ₍in front₎ (1 − aⱼ)`` and
``g = 1 − Π (1 − aᵢ)``, so ``r / g`` is the transmittance-weighted distance (m, from the camera)
and ``g`` the layer's coverage. A media pass then fogs a pixel by ``g · f(r / g) + (1 − g) · f(d)``
(``d`` from the depth buffer): exact where the layer is opaque or absent.

A pass cannot declare an optional read, so the plugins meet in the App resource
:class:`Composition`: a layer that can write the distance adds its name to ``writers`` in
``build``, a media pass that wants it adds itself to ``readers``. When there are both, the pass
:class:`ClearDistance` (phase clear, added with the Composition) creates ``"cloud_distance"`` and
clears it to 0, every layer reads and writes it (the far field, then the sprites over it), and the
readers read it: a scene without fog allocates no distance target, a fog without clouds reads none.
A writer that writes every pixel when it runs (the far field's compute pass, the ray march's) says so in
``covers`` (name -> whether it runs this frame), and one drawn behind every other layer (the far field)
also in ``behind``. The first of them (:attr:`Composition.distance_first`: the one behind, else the only
one that runs) creates the target instead, storing its distance without reading one, and the clear is
culled.

Local media and the air. A local medium (the fog) blends its (light L, transmittance T) over the colour;
the aerial perspective, which spans the whole ray, would then add the air's light over the fog as if the
fog were not there (an opaque fog would still show the air behind it). So the media are mixed instead:
where a local medium writes (``media_writers``) and the aerial perspective reads (``media_readers``),
:class:`ClearMedia` creates ``"media_light"`` (RGB, cleared to 0) and ``"media_transmittance"`` (R,
cleared to 1); each local medium blends its (L, T) onto them as onto the colour (so they hold the local
media composited), and the aerial perspective mixes the air with them along the ray in proportion
(:func:`media_mix`, ``shaders/lib/media_mix.glsl``): exact for two homogeneous media, each alone as
before. A local medium that writes every pixel when it runs says so in ``media_covers``; while it is the
only one and runs, it creates the two targets and stores its (L, T) instead of blending them onto a
clear (``LOCAL_MEDIA`` 2 in ``shaders/lib/media_image.glsl``), and the clear is culled.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from atmos.graph import RenderPass, TextureDesc

CLOUD_DISTANCE = "cloud_distance"
MEDIA_LIGHT = "media_light"                    # the local media's in-scattered light, composited (RGB)
MEDIA_TRANSMITTANCE = "media_transmittance"    # and their transmittance (R)


def distance_desc(size) -> TextureDesc:
    """The distance target at ``size`` (width, height): RG float32 (premultiplied distance, coverage),
    drawn into or composited onto in place (an rg32f image)."""
    return TextureDesc(tuple(size), components=2, dtype="f4", filter="nearest", storage=True)


def media_mix(light_a, t_a, light_b, t_b) -> np.ndarray:
    """float64 (..., 3): the light of two media on one ray, each alone giving (light (..., 3), grey
    transmittance (...,)), mixed in proportion (their extinctions in one ratio all along the ray):
    (1 − T_a T_b) / (τ_a + τ_b) · (L_a τ_a / (1 − T_a) + L_b τ_b / (1 − T_b)), τ = −ln T; together they
    transmit T_a T_b. Either alone (T = 1, L = 0 for the other) gives itself back."""
    def tau(t):
        return -np.log(np.clip(np.asarray(t, np.float64), 1e-30, 1.0))

    def per_depth(t, x):            # τ / (1 − T), 1 + τ/2 as τ → 0
        return np.where(x < 1e-4, 1.0 + 0.5 * x, x / np.maximum(1.0 - np.asarray(t, np.float64), 1e-300))

    ta, tb = tau(t_a), tau(t_b)
    total = ta + tb
    share = np.where(total < 1e-4, 1.0 - 0.5 * total, -np.expm1(-total) / np.maximum(total, 1e-300))
    return share[..., None] * (np.asarray(light_a, np.float64) * per_depth(t_a, ta)[..., None]
                               + np.asarray(light_b, np.float64) * per_depth(t_b, tb)[..., None])


@dataclass
class Composition:
    """App resource: which plugins write ``"cloud_distance"`` and which read it (names); which local
    media write ``"media_light"``/``"media_transmittance"`` and which passes read them; which passes fill
    the colour's background."""
    writers: set = field(default_factory=set)
    readers: set = field(default_factory=set)
    covers: dict = field(default_factory=dict)     # name -> () -> bool: that writer writes every pixel
    behind: set = field(default_factory=set)       # covering writers drawn behind every other layer
    media_writers: set = field(default_factory=set)
    media_readers: set = field(default_factory=set)
    media_covers: dict = field(default_factory=dict)   # name -> () -> bool: that medium writes every pixel
    backgrounds: set = field(default_factory=set)      # passes that write every pixel of "color" before the
    #                                                    geometry (a sky: the depth is all 1 then), so the colour needs no clear

    @property
    def distance(self) -> bool:
        """True when the distance is both written and read: the writer creates it, the readers read it."""
        return bool(self.writers) and bool(self.readers)

    @property
    def distance_first(self) -> str | None:
        """The writer that creates the distance this frame (storing its own, nothing cleared): of the
        covering writers that run, the one drawn behind the others (``behind``), else the only one; None
        when the distance is not wanted or no such writer runs."""
        if not (self.writers and self.readers):
            return None
        behind, others = [], []
        for name, runs in self.covers.items():      # a loop, not comprehensions: this runs every frame
            if runs():
                (behind if name in self.behind else others).append(name)
        first = behind or others
        return first[0] if len(first) == 1 else None

    @property
    def distance_cleared(self) -> bool:
        """True when the distance is wanted and no first writer that covers every pixel runs: the clear makes it."""
        return self.distance and self.distance_first is None

    @property
    def media(self) -> bool:
        """True when a local medium writes the media targets and a pass reads them."""
        return bool(self.media_writers) and bool(self.media_readers)

    @property
    def media_first(self) -> str | None:
        """The local medium that creates the media targets (storing its own (L, T), nothing cleared): the
        only one that writes them, when it writes every pixel and runs this frame; else None."""
        if not self.media or len(self.media_writers) != 1:
            return None
        (name,) = self.media_writers
        runs = self.media_covers.get(name)
        return name if runs is not None and runs() else None


class CompositedElsewhere:
    """Mixed into a medium's published resource (the fog's FogMedium, the sky's SkyLight): another pass may
    composite the medium instead of its own pass (the light shafts' froxel apply, with what it takes away
    in one write) while ``wants()`` says so; the medium's own pass is then culled."""
    _compositor = None                  # () -> bool

    def composite_elsewhere(self, wants) -> None:
        """Let another pass composite this medium while ``wants()`` is true; None gives it back to its pass."""
        self._compositor = wants

    @property
    def composited_elsewhere(self) -> bool:
        """Whether another pass composites this medium this frame (:meth:`composite_elsewhere`)."""
        return self._compositor is not None and self._compositor()


def media_targets(size) -> tuple:
    """(name, TextureDesc, clear value) of the media targets at ``size``: ``"media_light"`` (RGBA float32,
    clear 0) and ``"media_transmittance"`` (R float32, clear 1)."""
    size = tuple(size)
    return ((MEDIA_LIGHT, TextureDesc(size, components=4, dtype="f4", filter="nearest", storage=True), 0.0),
            (MEDIA_TRANSMITTANCE, TextureDesc(size, components=1, dtype="f4", filter="nearest", storage=True), 1.0))


class CompositionClear(RenderPass):
    """A pass of phase clear that creates a Composition's shared targets at the frame's size and clears
    them while ``wanted()`` (its plugins both write and read them); else declares nothing (culled).
    ``targets(size)``: (name, TextureDesc, clear value) of each."""
    phase = "clear"

    def __init__(self, gpu, wanted, targets):
        self.gpu, self.wanted, self.targets = gpu, wanted, targets

    def setup_key(self) -> tuple:
        return (self.wanted(), self.gpu.size)

    def setup(self, builder) -> None:
        if self.wanted():
            for name, desc, _ in self.targets(tuple(self.gpu.size)):
                builder.create(name, desc)

    def execute(self, frame) -> None:
        for name, _, value in self.targets(tuple(self.gpu.size)):
            frame.framebuffer(color=[name]).clear(value, value, value, value)


class ClearDistance(CompositionClear):
    """Pass "cloud_distance_clear": ``"cloud_distance"`` cleared to 0 (no layer) when the Composition
    has a writer and a reader, and no first writer covers every pixel (``distance_cleared``)."""
    name = "cloud_distance_clear"

    def __init__(self, comp: Composition, gpu):
        super().__init__(gpu, lambda: comp.distance_cleared,
                         lambda size: ((CLOUD_DISTANCE, distance_desc(size), 0.0),))


class ClearMedia(CompositionClear):
    """Pass "media_clear": ``"media_light"`` (RGBA float32, cleared to 0) and ``"media_transmittance"``
    (R float32, cleared to 1) when the Composition's media are written and read, and no one medium
    makes them (:attr:`Composition.media_first`)."""
    name = "media_clear"

    def __init__(self, comp: Composition, gpu):
        super().__init__(gpu, lambda: comp.media and comp.media_first is None, media_targets)


def composition(app) -> Composition:
    """The App's :class:`Composition` (made on first use, with its :class:`ClearDistance` and
    :class:`ClearMedia` passes)."""
    comp = app.get_resource(Composition)
    if comp is None:
        comp = Composition()
        app.insert_resource(comp)
        if app.graph is not None:
            app.graph.add_pass(ClearDistance(comp, app.gpu))
            app.graph.add_pass(ClearMedia(comp, app.gpu))
    return comp
