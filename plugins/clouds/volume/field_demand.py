"""Which cloud renderers read the diffusion field, so the cloud chain solves it only for them.

The field (:mod:`atmos.plugins.clouds.light.diffusion`) is the chain's costliest task. A renderer that reads it
(its settings have ``enabled`` and ``ms_diffusion``, the field's weight) adds itself to ``readers`` of
the App resource :class:`FieldDemand` in ``build`` and takes itself out in ``cleanup``; the simulation asks
:meth:`FieldDemand.wanted` when each step begins (static clouds: when they are shaded). A scene
whose renderers give the field no weight (none added, ``enabled=False`` or ``ms_diffusion=0``)
solves nothing and allocates no field texture. The plugins meet there in any order, as in
:mod:`atmos.composition`.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class FieldDemand:
    """App resource: the renderer plugins that read the field."""
    readers: set = field(default_factory=set)

    def wanted(self) -> bool:
        """True when an enabled reader gives the field a weight (``ms_diffusion``) above 0."""
        return any(r.settings.enabled and r.settings.ms_diffusion > 0 for r in self.readers)

    def light(self):
        """The light settings (a CloudLightSettings: octaves, ``ms_diffusion``) of the renderer that draws
        the clouds, for passes that light clouds without being a renderer (the 2D far field): an enabled
        reader's (the one giving the field the most weight), else any reader's; None: no renderer."""
        readers = sorted(self.readers, key=lambda r: (bool(r.settings.enabled), float(r.settings.ms_diffusion),
                                                      type(r).__name__))
        return readers[-1].settings if readers else None


def field_demand(app) -> FieldDemand:
    """The App's :class:`FieldDemand` (made on first use)."""
    return app.init_resource(FieldDemand)
