"""Who draws the cloud far field this frame: its own 2D pass, or a renderer that marches on through it.

The far-field plugin says in :attr:`FarFieldLink.shown` whether it draws (set in ``build``: enabled);
a renderer that can march the far field volumetrically (the ray march's ``far_field``) adds itself to
``marchers`` and answers ``marches_far_field()``. While one does, the 2D pass steps aside and the far
field is lit with that renderer's settings. The plugins
meet in this App resource in any order, as in :mod:`atmos.composition`, never through each other.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable


@dataclass
class FarFieldLink:
    """App resource: whether a far field is shown, and the renderers that may march it themselves."""
    shown: Callable[[], bool] | None = None     # the far-field plugin's: whether it is enabled (None: none)
    marchers: set = field(default_factory=set)  # renderers with marches_far_field()

    def present(self) -> bool:
        """True while a far-field plugin is in the scene and enabled."""
        shown = self.shown
        return shown is not None and bool(shown())

    def marcher(self):
        """The registered renderer that marches the far field itself this frame (None: none does); its
        ``settings`` light the far field."""
        for marcher in self.marchers:               # a loop, not any(generator): this runs every frame
            if marcher.marches_far_field():
                return marcher
        return None

    def marched(self) -> bool:
        """True while a registered renderer marches the far field itself this frame."""
        return self.marcher() is not None


def far_field_link(app) -> FarFieldLink:
    """The App's :class:`FarFieldLink` (made on first use)."""
    return app.init_resource(FarFieldLink)
