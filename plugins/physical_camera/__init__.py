"""The physical camera: exposure in EV100, metered on the GPU and adapted over time (or set by hand), and
bloom around the sun and bright clouds; the present applies both (:mod:`.plugin`)."""
from atmos.plugins.physical_camera.plugin import BloomPass, ExposurePass, PhysicalCameraPlugin
from atmos.plugins.physical_camera.settings import PhysicalCameraSettings

__all__ = ["BloomPass", "ExposurePass", "PhysicalCameraPlugin", "PhysicalCameraSettings"]
