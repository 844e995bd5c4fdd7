"""Plugins register systems, resources and render passes; groups of them can be edited before use."""
from __future__ import annotations

from importlib.metadata import entry_points
from typing import Any

from atmos.checks import configure_settings, plugin_settings

ENTRY_POINT_GROUP = "atmos.plugins"


class Plugin:
    """An effect or a piece of the engine. ``build`` registers; ``finish`` runs once all are built.

    Settings (the convention, :mod:`atmos.checks`): a plugin with settings names its frozen, checked
    ``<Thing>Settings`` dataclass in ``settings_class``; ``Plugin(settings=None, **fields)`` keeps
    ``self.settings`` (``fields`` on top of ``settings`` or the defaults, all checked) and
    :meth:`configure` changes them while running. Passes and systems read ``plugin.settings``
    every frame, so a change shows on the next frame.
    """

    settings_class: type | None = None

    def __init__(self, settings=None, **fields):
        cls = type(self).settings_class
        if cls is None:
            if settings is not None or fields:
                given = (["settings"] if settings is not None else []) + sorted(fields)
                raise ValueError(f"{self.name} takes no settings, got {', '.join(given)}")
            self.settings = None
            return
        self.settings = plugin_settings(self.name, cls, settings, fields)

    def configure(self, **changes) -> Any:
        """Change settings while running; returns the new settings. All ``changes`` are checked
        together (unknown names, bad values, the ``FIXED`` fields that cannot change while running):
        on any error a ValueError says why and nothing changes. Takes effect on the next frame."""
        if getattr(self, "settings", None) is None:
            raise ValueError(f"{self.name} has no settings to configure")
        self.settings = configure_settings(self.name, self.settings, changes)
        return self.settings

    def build(self, app) -> None:
        """Add systems, resources and render passes to ``app`` (an :class:`atmos.App`)."""

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

    def set(self, plugin: Plugin) -> "PluginGroup":
        """Replace the member of ``plugin``'s type with ``plugin`` (configured as you want it), as in
        ``DefaultPlugins().set(RenderCorePlugin(exposure=1.5))``."""
        self.plugins[self._index(type(plugin))] = plugin
        return self

    def configure(self, kind: type, **changes) -> "PluginGroup":
        """Change settings of the member of type ``kind`` (checked like :meth:`Plugin.configure`)."""
        self.plugins[self._index(kind)].configure(**changes)
        return self

    def get(self, kind: type) -> Plugin:
        """The member of type ``kind``."""
        return self.plugins[self._index(kind)]

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
