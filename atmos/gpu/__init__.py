"""GPU access: one context type for windows and headless EGL, and GLSL loading with readable errors."""
from atmos.gpu.context import (GpuContext, GpuError, MIN_GL_VERSION, create_headless, from_current,
                               release_gl)
from atmos.gpu.shaders import ShaderError, load_source

__all__ = ["GpuContext", "GpuError", "MIN_GL_VERSION", "create_headless", "from_current", "release_gl",
           "ShaderError", "load_source"]
