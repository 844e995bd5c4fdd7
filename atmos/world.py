"""An esper world owned by one App, so two Apps in one process never share entities.

esper 3 keeps module-level worlds and one "current" world; every call here switches esper to this
world first (a string compare when it already is current).
"""
from __future__ import annotations

import itertools

import esper

_names = itertools.count()


class World:
    """The ECS world of one App: entities with small slotted dataclass components."""

    def __init__(self):
        self.name = f"atmos-world-{next(_names)}"
        self.activate()

    def activate(self) -> None:
        """Make this esper's current world."""
        if esper.current_world != self.name:
            esper.switch_world(self.name)

    def create_entity(self, *components) -> int:
        self.activate()
        return esper.create_entity(*components)

    def delete_entity(self, entity: int, immediate: bool = False) -> None:
        """Delete ``entity`` at the end of this stage (``immediate``: now; not while iterating a
        query). Deleting one already deleted this stage does nothing; one that never existed or is
        long gone is a ValueError."""
        self.activate()
        if entity in esper._dead_entities and not immediate:
            return
        if entity not in esper._entities:
            raise ValueError(f"entity {entity!r} does not exist in this world (deleted already, or never made)")
        esper.delete_entity(entity, immediate)

    def add_component(self, entity: int, component) -> None:
        self.activate()
        esper.add_component(entity, component)

    def remove_component(self, entity: int, component_type: type):
        self.activate()
        return esper.remove_component(entity, component_type)

    def component_for_entity(self, entity: int, component_type: type):
        self.activate()
        return esper.component_for_entity(entity, component_type)

    def has_entity(self, entity: int) -> bool:
        """True while ``entity`` exists and is not deleted (deferred deletes count as deleted)."""
        self.activate()
        return esper.entity_exists(entity)

    def try_component(self, entity: int, component_type: type):
        """The entity's component of that type, or None."""
        self.activate()
        return esper.try_component(entity, component_type)

    def has_component(self, entity: int, component_type: type) -> bool:
        self.activate()
        return esper.has_component(entity, component_type)

    def get_component(self, component_type: type) -> list:
        """[(entity, component)] for every entity that has ``component_type``."""
        self.activate()
        return esper.get_component(component_type)

    def get_components(self, *component_types: type) -> list:
        """[(entity, (c1, c2, ...))] for every entity that has all ``component_types``."""
        self.activate()
        return esper.get_components(*component_types)

    def entity_count(self) -> int:
        self.activate()
        return len(esper._entities)

    def clear_dead_entities(self) -> None:
        """Carry out deferred deletes (the App does it after every stage, so an entity deleted in one
        is gone from the next stage's queries). Nothing to do costs nothing: esper's query cache is
        only cleared when something was deleted."""
        self.activate()
        if esper._dead_entities:
            esper.clear_dead_entities()

    def close(self) -> None:
        """Delete this world and everything in it."""
        if esper.current_world == self.name:
            esper.switch_world("default")
        if self.name in esper.list_worlds():
            esper.delete_world(self.name)
