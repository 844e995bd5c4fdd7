"""DefaultPlugins: what every rendered scene starts from."""
from atmos.camera_control import CameraPlugin
from atmos.checks import check_bool
from atmos.camera_control import FlyCameraPlugin
from atmos.input import InputPlugin
from atmos.plugin import PluginGroup
from atmos.overlay import OverlayPlugin
from atmos.render_core import RenderCorePlugin
from atmos.transform import TransformPlugin


class DefaultPlugins(PluginGroup):
    """RenderCorePlugin (clear + present), InputPlugin, CameraPlugin, TransformPlugin (interpolation
    between fixed steps), FlyCameraPlugin (WASD; ``fly_camera=False`` leaves it out) and OverlayPlugin
    (the frame-time bars: hidden unless ``overlay=True``; F1 shows and hides them)."""

    def __init__(self, overlay: bool = False, fly_camera: bool = True):
        overlay, fly_camera = check_bool("DefaultPlugins", "overlay", overlay), check_bool("DefaultPlugins", "fly_camera", fly_camera)
        plugins = [RenderCorePlugin(), InputPlugin(), CameraPlugin(), TransformPlugin()]
        plugins += [FlyCameraPlugin()] if fly_camera else []
        super().__init__(*plugins, OverlayPlugin(visible=overlay))
