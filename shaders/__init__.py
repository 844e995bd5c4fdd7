"""GLSL sources, located at run time through importlib.resources (see atmos.gpu.shaders)."""
