"""Plugins register systems, resources and render passes; groups of them can be edited before use."""
from __future__ import annotations

from importlib.metadata import entry_points

ENTRY_POINT_GROUP = "atmos.plugins"


class Plugin:
    """An effect or a piece of the engine. ``build`` registers; ``finish`` runs once all are built."""

    def build(self, app) -> None:
        """Add systems, resources and render passes to ``app``."""

    def finish(self, app) -> None:
        """Late setup, after every plugin's ``build`` (e.g. read other plugins' resources)."""

    def cleanup(self, app) -> None:
        """Release what ``build``/``finish`` created (GL objects above all); called by App.close()."""

    @property
    def name(self) -> str:
        return type(self).__name__


class PluginGroup:
    """An ordered, editable list of plugins: ``DefaultPlugins().disable(FooPlugin).add_before(Bar, Baz())``."""

    def __init__(self, *plugins: Plugin):
        self.plugins: list[Plugin] = list(plugins)

    def _index(self, kind: type) -> int:
        for i, plugin in enumerate(self.plugins):
            if isinstance(plugin, kind):
                return i
        names = ", ".join(p.name for p in self.plugins) or "none"
        raise ValueError(f"{kind.__name__} is not in {type(self).__name__}; it holds: {names}")

    def disable(self, kind: type) -> "PluginGroup":
        """Leave out the plugin of type ``kind``."""
        del self.plugins[self._index(kind)]
        return self

    def add_before(self, kind: type, plugin: Plugin) -> "PluginGroup":
        self.plugins.insert(self._index(kind), plugin)
        return self

    def add_after(self, kind: type, plugin: Plugin) -> "PluginGroup":
        self.plugins.insert(self._index(kind) + 1, plugin)
        return self

    def add(self, plugin: Plugin) -> "PluginGroup":
        self.plugins.append(plugin)
        return self

    def __iter__(self):
        return iter(self.plugins)


def discover_plugins() -> dict[str, type]:
    """Third-party plugin classes registered under the ``atmos.plugins`` entry-point group, by name."""
    found = {}
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            found[ep.name] = ep.load()
        except Exception as error:  # a broken third-party package must not stop the engine
            raise ImportError(f"plugin entry point {ep.name!r} ({ep.value}) failed to load: {error}") from error
    return found
