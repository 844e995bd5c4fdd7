"""A heightfield terrain with valleys (about 10,000 triangles by default) continued to the horizon by a
far ring, grass, rock and snow with detail, lit by the Sun; writes color + depth."""
from atmos.plugins.terrain.heightfield import heightfield, terrain_mesh, triangle_count
from atmos.plugins.terrain.plugin import TerrainPass, TerrainPlugin, TerrainSettings

__all__ = ["TerrainPlugin", "TerrainPass", "TerrainSettings", "heightfield", "terrain_mesh", "triangle_count"]
