"""The render graph: passes declare a phase and resources, compile() orders, versions and culls
them, execute() runs a frame."""
from atmos.graph.compiler import CompiledGraph, ResourceInfo
from atmos.graph.compute import ComputePass, work_groups
from atmos.graph.errors import GraphError
from atmos.graph.frame import PassContext
from atmos.graph.fullscreen import FullscreenPass
from atmos.graph.graph import RenderGraph
from atmos.graph.passes import PassBuilder, RenderPass
from atmos.graph.phases import PHASES
from atmos.graph.resources import BufferDesc, TextureDesc, TexturePool
from atmos.graph.timing import PassTimers

__all__ = ["RenderGraph", "RenderPass", "PassBuilder", "PassContext", "TextureDesc", "TexturePool",
           "GraphError", "CompiledGraph", "ResourceInfo", "PassTimers", "FullscreenPass", "PHASES",
           "ComputePass", "BufferDesc", "work_groups"]
