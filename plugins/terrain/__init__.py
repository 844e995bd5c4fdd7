"""A heightfield terrain with valleys (about 10,000 triangles by default), lit by the Sun; writes color + depth."""
from atmos.plugins.terrain.heightfield import heightfield, triangle_count
from atmos.plugins.terrain.plugin import TerrainPass, TerrainPlugin, TerrainSettings

__all__ = ["TerrainPlugin", "TerrainPass", "TerrainSettings", "heightfield", "triangle_count"]
