"""Which cloud renderers read the diffusion field, so the cloud chain solves it only for them.

The field (:mod:`atmos.shading.diffusion`) is the chain's costliest task. A renderer that reads it
adds a zero-argument callable giving its weight (``ms_diffusion``, 0 when disabled) to the App
resource :class:`FieldDemand` in ``build`` and takes it out in ``cleanup``; the simulation asks
:meth:`FieldDemand.wanted` when each step begins (static clouds: when they are shaded). A scene
whose renderers give the field no weight (none added, ``enabled=False`` or ``ms_diffusion=0``)
solves nothing and allocates no field texture. The plugins meet there in any order, as in
:mod:`atmos.composition`.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class FieldDemand:
    """App resource: reader name → zero-argument callable giving the weight it reads the field with."""
    weights: dict = field(default_factory=dict)

    def wanted(self) -> bool:
        """True when some reader gives the field a weight above 0."""
        return any(float(weight()) > 0 for weight in self.weights.values())


def field_demand(app) -> FieldDemand:
    """The App's :class:`FieldDemand` (made on first use)."""
    demand = app.get_resource(FieldDemand)
    if demand is None:
        demand = FieldDemand()
        app.insert_resource(demand)
    return demand
