"""The one uniform writer and the binders: values, textures, images and storage buffers by name into a
program, skipping what its compiler dropped. A unit is written once, in the GLSL that declares the
sampler, image or buffer (``layout(binding = N)``); Python binds by name and never names a unit.
A bind is also the declaration of a use (:mod:`atmos.gpu.hazards`): it gets the memory barrier the
use needs after earlier storage writes, and stages its own storage writes for the next dispatch."""
from __future__ import annotations

from collections.abc import Mapping

import moderngl

from atmos.gpu.hazards import hazards_of


def _hazards(program):
    """The program's context's Hazards (kept in ``program.extra`` by the compiler check)."""
    extra = program.extra
    hazards = extra.get("hazards") if isinstance(extra, dict) else None
    return hazards if hazards is not None else hazards_of(program.ctx)


def write_uniforms(program, values: Mapping[str, object] | None = None, /, **more) -> None:
    """Write each value to ``program``'s uniform of that name; a name the program does not have (the
    compiler drops uniforms it proves unused, and shader variants use different ones) is skipped.
    ``bytes`` are written as they are (matrices, arrays); a ``list`` fills an array uniform, cut to the
    length the compiler kept (a tuple is one vector); anything else is the uniform's ``value``."""
    get = program.get
    for name, value in ({**values, **more} if values else more).items():
        member = get(name, None)
        if member is None:
            continue
        if isinstance(value, (bytes, bytearray, memoryview)):
            member.write(value)
        elif isinstance(value, list):
            member.value = value[:member.array_length] if member.array_length > 1 else value[0]
        else:
            member.value = value


def bind_textures(program, textures: Mapping[str, object] | None = None, /, sampler=None, **more) -> list[int]:
    """Bind each texture to the unit of ``program``'s sampler of that name (the ``layout(binding = N)``
    of its declaration; a sequence of textures to a sampler array, element by element); a name the
    program does not use is skipped. ``sampler`` (a moderngl Sampler) is bound at those units too.
    Returns the units bound (to clear ``sampler`` from afterwards)."""
    get = program.get
    units = []
    dirty = (hazards := _hazards(program))._dirty
    for name, texture in ({**textures, **more} if textures else more).items():
        member = get(name, None)
        if member is None:
            continue
        value = member.value                 # a sampler array: its units (one int where one element is used)
        if isinstance(texture, (list, tuple)):
            pairs = zip(value if isinstance(value, list) else [value], texture)
        else:
            pairs = ((value, texture),)
        for unit, one in pairs:
            if id(one) in dirty:
                hazards.need(one, moderngl.TEXTURE_FETCH_BARRIER_BIT)
            one.use(unit)
            if sampler is not None:
                sampler.use(unit)
            units.append(unit)
    return units


def bind_images(program, images: Mapping[str, object] | None = None, /, **more) -> None:
    """Bind each texture as an image at the unit of ``program``'s image uniform of that name (its
    ``layout(binding = N, format)``), for the access its declaration gives (``readonly``,
    ``writeonly`` or both); a name the program does not use is skipped."""
    declared = program.extra["images"]        # (unit, read, write) by name, from the compiler check
    dirty = (hazards := _hazards(program))._dirty
    for name, texture in ({**images, **more} if images else more).items():
        if name in declared:
            unit, read, write = declared[name]
            if id(texture) in dirty:
                hazards.need(texture, moderngl.SHADER_IMAGE_ACCESS_BARRIER_BIT)
            if write:
                hazards.stage(texture)
            texture.bind_to_image(unit, read=read, write=write)


def bind_buffers(program, buffers: Mapping[str, object] | None = None, /, **more) -> None:
    """Bind each buffer at the binding of ``program``'s storage block of that name (its
    ``layout(std430, binding = N) buffer Name``); a name the program does not use is skipped. A
    block not declared ``readonly`` counts as written by the next dispatch."""
    get = program.get
    extra = program.extra                        # storage blocks not declared readonly, from the compiler check
    written = extra.get("written") if isinstance(extra, dict) else None   # unknown: every block may be
    dirty = (hazards := _hazards(program))._dirty
    for name, buffer in ({**buffers, **more} if buffers else more).items():
        member = get(name, None)
        if member is not None:
            if id(buffer) in dirty:
                hazards.need(buffer, moderngl.SHADER_STORAGE_BARRIER_BIT)
            if written is None or name in written:
                hazards.stage(buffer)
            buffer.bind_to_storage_buffer(member.binding)
