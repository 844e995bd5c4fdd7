"""The fixed order of a frame's render phases. Every pass declares one; registration order decides nothing.

==============  =================================================================================
phase           what runs there
==============  =================================================================================
``clear``       passes that create and clear the frame's targets (``color``, ``depth``)
``sky``         the background: a sky overwrites ``color``; layers on the sky dome blend over it
``opaque``      depth-tested geometry (ground, terrain, the game's meshes); their writes commute
                (the depth test decides), so several run in name order without an error
``shadows``     passes that darken what ``opaque`` drew (cloud shadows)
``translucent`` blended layers in front of the scene (clouds, volumes)
``media``       participating media between the camera and everything (fog, volumetric fog)
``post``        screen-space effects on the finished HDR image (light shafts)
``present``     tone mapping into the screen
``overlay``     drawn over the presented screen (frame-time bars, HUD)
``readback``    copies of finished frames to the CPU (capture, video output)
==============  =================================================================================

Inside a phase the order follows the data (:mod:`atmos.graph.compiler`): a pass that overwrites a
resource (writes it without reading it) runs before passes that modify it (read and write: blend
onto it), and both before passes that only read it. Two overwriters, or two modifiers, of one
resource in one phase with nothing ordering them are a compile error (except in ``opaque``).
"""
from __future__ import annotations

PHASES: tuple[str, ...] = ("clear", "sky", "opaque", "shadows", "translucent", "media", "post", "present",
                           "overlay", "readback")
PHASE_INDEX: dict[str, int] = {name: i for i, name in enumerate(PHASES)}
COMMUTING: frozenset[str] = frozenset({"opaque"})   # phases whose writers need no order among them
