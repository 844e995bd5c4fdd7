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
"""
from __future__ import annotations

from dataclasses import dataclass, field

from atmos.graph import RenderPass, TextureDesc

CLOUD_DISTANCE = "cloud_distance"


def distance_desc(size) -> TextureDesc:
    """The distance target at ``size`` (width, height): RG float32 (premultiplied distance, coverage)."""
    return TextureDesc(tuple(size), components=2, dtype="f4", filter="nearest")


@dataclass
class Composition:
    """App resource: which plugins write ``"cloud_distance"`` and which read it (names)."""
    writers: set = field(default_factory=set)
    readers: set = field(default_factory=set)

    @property
    def distance(self) -> bool:
        """True when the distance is both written and read: the writer creates it, the readers read it."""
        return bool(self.writers) and bool(self.readers)


class ClearDistance(RenderPass):
    """Pass "cloud_distance_clear" (phase clear): creates ``"cloud_distance"`` at the frame's size and
    clears it to 0 (no layer) when the Composition has a writer and a reader; else declares nothing
    (culled)."""
    name = "cloud_distance_clear"
    phase = "clear"

    def __init__(self, comp: Composition, gpu):
        self.comp, self.gpu = comp, gpu

    def setup(self, builder) -> None:
        if self.comp.distance:
            builder.create(CLOUD_DISTANCE, distance_desc(self.gpu.size))

    def execute(self, frame) -> None:
        frame.framebuffer(color=[CLOUD_DISTANCE]).clear(0.0, 0.0, 0.0, 0.0)


def composition(app) -> Composition:
    """The App's :class:`Composition` (made on first use, with its :class:`ClearDistance` pass)."""
    comp = app.get_resource(Composition)
    if comp is None:
        comp = Composition()
        app.insert_resource(comp)
        if app.graph is not None:
            app.graph.add_pass(ClearDistance(comp, app.gpu))
    return comp
