"""DefaultPlugins: what every rendered scene starts from."""
from atmos.camera import CameraPlugin
from atmos.plugin import PluginGroup
from atmos.plugins.overlay import OverlayPlugin
from atmos.render_core import RenderCorePlugin


class DefaultPlugins(PluginGroup):
    """RenderCorePlugin (clear + present), CameraPlugin (camera, input, fly camera), OverlayPlugin."""

    def __init__(self, overlay: bool = True):
        super().__init__(RenderCorePlugin(), CameraPlugin(), OverlayPlugin(visible=overlay))
