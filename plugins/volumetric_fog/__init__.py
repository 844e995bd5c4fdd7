"""Ray-marched volumetric fog (fbm-raymarched-fog.txt): rotated value-noise FBM density, a march with
Beer-Lambert absorption and early exit, an inner light march toward the sun (through the clouds' shadow
map when the scene has clouds), ambient + scattered light.
A scene that does not add :class:`VolumetricFogPlugin` runs and compiles none of it.
"""
from atmos.plugins.volumetric_fog.settings import VolumetricFogSettings
from atmos.plugins.volumetric_fog.plugin import VolumetricFogPlugin, VolumetricFogPass

__all__ = ["VolumetricFogSettings", "VolumetricFogPlugin", "VolumetricFogPass"]
