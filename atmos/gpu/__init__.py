"""GPU access: one context type for windows and headless EGL, and GLSL loading (a shader search path
that plugins add their own directories to, ``#include``, errors naming the real file and line)."""
from atmos.gpu.context import (GpuContext, GpuError, MIN_GL_VERSION, clamp_sampler, create_headless, from_current,
                               release_gl, require_gpu, wrap_context)
from atmos.gpu.shaders import GlslSource, ShaderError, add_shader_path, load_source, remove_shader_path, shader_paths

__all__ = ["GpuContext", "GpuError", "MIN_GL_VERSION", "clamp_sampler", "create_headless", "from_current", "release_gl",
           "require_gpu", "wrap_context", "GlslSource", "ShaderError", "load_source", "add_shader_path", "remove_shader_path", "shader_paths"]
