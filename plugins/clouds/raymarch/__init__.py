"""Ray-marched clouds (issue 15), beside the sprite renderer: :class:`RaymarchCloudsPlugin` marches the
CloudsPlugin's smoothed density with the sprites' light model (:mod:`.plugin`, settings
:mod:`.settings`, float64 reference :mod:`.reference`; ``RaymarchCloudsPlugin.reference()`` is the
reference image the sprites and the real-time settings are measured against), shaped by a cloud type (stratus,
cumulus, congestus, one or by region with a :class:`CloudTypeMap`: :mod:`.shape`), eroded by tileable detail noise (:mod:`.noise`) and resolved over frames by
temporal reprojection (:mod:`.temporal`)."""
from atmos.plugins.clouds.raymarch.plugin import RaymarchCloudsPlugin, RaymarchPass
from atmos.plugins.clouds.raymarch.settings import RaymarchCloudSettings
from atmos.plugins.clouds.volume.shape import CLOUD_TYPES, CloudTypeMap

__all__ = ["CLOUD_TYPES", "CloudTypeMap", "RaymarchCloudSettings", "RaymarchCloudsPlugin", "RaymarchPass"]
