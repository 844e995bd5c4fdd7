"""The one uniform writer and the binders: values, textures, images and storage buffers by name into a
program, skipping what its compiler dropped. A unit is written once, in the GLSL that declares the
sampler, image or buffer (``layout(binding = N)``); Python binds by name and never names a unit.
A bind is also the declaration of a use (:mod:`atmos.gpu.hazards`): it gets the memory barrier the
use needs after earlier storage writes, and stages its own storage writes for the next dispatch.
A moderngl texture's or buffer's bind method is one call of its C object (``mglo``); the binders make
that call directly (state changes only: GL work, transfers and uniform writes still go through
moderngl, where :class:`atmos.gpu.gl_meter.GLMeter` and the hazard guard see them)."""
from __future__ import annotations

from collections.abc import Mapping
from struct import pack as _pack

import moderngl
import numpy as np

from atmos.gpu.hazards import hazards_of


def _hazards(program):
    """The program's context's Hazards (kept in ``program.extra`` by the compiler check)."""
    extra = program.extra
    hazards = extra.get("hazards") if isinstance(extra, dict) else None
    return hazards if hazards is not None else hazards_of(program.ctx)


_TEXTURES = frozenset((moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray, moderngl.TextureCube))
_SCALARS = frozenset((float, int, bool, tuple, bytes, np.float64, np.float32, np.int64, np.int32, np.bool_))
# values compared with the last one written (a cheap ==); a 1-D numpy array is compared as a tuple


def _tables(program):
    """(members, written) of ``program``: its uniforms by name (None where the compiler dropped the
    name) and the last value :func:`write_uniforms` wrote to each, kept in ``program.extra`` (None,
    None for a program without it: nothing cached)."""
    extra = program.extra
    if type(extra) is not dict:
        return None, None
    try:
        return extra["members"], extra["last"]
    except KeyError:
        extra["members"], extra["last"] = {}, {}
        return extra["members"], extra["last"]


def write_uniforms(program, values: Mapping[str, object] | None = None, /, **more) -> None:
    """Write each value to ``program``'s uniform of that name; a name the program does not have (the
    compiler drops uniforms it proves unused, and shader variants use different ones) is skipped.
    ``bytes`` are written as they are (matrices, arrays); a ``list`` fills an array uniform, cut to the
    length the compiler kept (a tuple is one vector); anything else is the uniform's ``value``.
    A program keeps its uniforms' values: a number, tuple, 1-D array or ``bytes`` equal to the one this
    wrote last is not written again (a float zero only of the same sign; a uniform written past this
    function must be forgotten: :func:`forget_uniform`)."""
    extra = program.extra                      # _tables, inlined
    if type(extra) is dict and "last" in extra:
        members, last = extra["members"], extra["last"]
    else:
        members, last = _tables(program)
        if members is None:
            members, last = {}, None
    values = {**values, **more} if values else more
    for name in values:
        value = values[name]
        try:
            member = members[name]
        except KeyError:
            member = members[name] = program.get(name, None)
        if member is None:
            continue
        kind = type(value)
        if kind is np.ndarray and value.ndim == 1:
            value = tuple(value.tolist())
            kind = tuple
        if kind in _SCALARS and last is not None:
            if name in last and last[name] == value and (value or kind is not float or str(value) == str(last[name])):
                continue                      # (a float zero only of the same sign: -0.0 is not 0.0)
            last[name] = value
        elif last is not None and name in last:
            del last[name]
        if kind is bytes or kind is bytearray or kind is memoryview:
            member.write(value)
        elif kind is list:
            member.value = value[:member.array_length] if member.array_length > 1 else value[0]
        elif member.array_length == 1:          # Uniform.value's packing, without its Python setter
            member.write(_pack(member.fmt, *value) if member.dimension > 1 else _pack(member.fmt, value))
        else:
            member.value = value


def has_member(program, name: str) -> bool:
    """Whether ``program`` has a uniform, sampler or block ``name`` (``name in program`` walks every member)."""
    extra = program.extra                      # _tables, inlined (per pass, per frame)
    members = extra["members"] if type(extra) is dict and "members" in extra else _tables(program)[0]
    if members is None:
        return program.get(name, None) is not None
    try:
        return members[name] is not None
    except KeyError:
        member = members[name] = program.get(name, None)
        return member is not None


def sampler_units(program, name: str):
    """The unit of ``program``'s sampler ``name`` (a list of units for a sampler array; None where it has
    none), as :func:`bind_textures` binds it."""
    extra = program.extra
    units_of = extra.setdefault("units", {}) if type(extra) is dict else {}
    try:
        return units_of[name]
    except KeyError:
        member = program.get(name, None)
        value = units_of[name] = None if member is None else member.value
        return value


def forget_uniform(program, name: str) -> None:
    """``name`` was written past :func:`write_uniforms`: its next value there is written whatever it is."""
    members, last = _tables(program)
    if last is not None and name in last:
        del last[name]


def bind_textures(program, textures: Mapping[str, object] | None = None, /, sampler=None, **more) -> list[int]:
    """Bind each texture to the unit of ``program``'s sampler of that name (the ``layout(binding = N)``
    of its declaration; a sequence of textures to a sampler array, element by element); a name the
    program does not use is skipped. ``sampler`` (a moderngl Sampler) is bound at those units too.
    Returns the units bound (to clear ``sampler`` from afterwards)."""
    extra = program.extra
    if type(extra) is dict:
        try:
            units_of, hazards = extra["units"], extra["hazards"]
        except KeyError:
            units_of = extra["units"] = {}
            hazards = _hazards(program)
    else:
        units_of, hazards = {}, _hazards(program)
    units = []
    dirty = hazards._dirty
    textures = {**textures, **more} if textures else more
    for name in textures:
        texture = textures[name]
        try:
            value = units_of[name]
        except KeyError:
            member = program.get(name, None)   # a sampler array: its units (one int where one element is used)
            value = units_of[name] = None if member is None else member.value
        if value is None:
            continue
        if type(texture) is list or type(texture) is tuple:
            pairs = zip(value if type(value) is list else [value], texture)
        else:
            pairs = ((value, texture),)
        for unit, one in pairs:
            if dirty and (key := id(one)) in dirty and (entry := dirty[key])[0]() is one:   # Hazards.need, inlined
                hazards._need |= entry[2] & moderngl.TEXTURE_FETCH_BARRIER_BIT
            if type(one) in _TEXTURES:
                one.mglo.use(unit)            # Texture.use, without its Python wrapper
            else:
                one.use(unit)
            if sampler is not None:
                if type(sampler) is moderngl.Sampler and sampler.texture is None:
                    sampler.mglo.use(unit)        # Sampler.use, unwrapped (no texture of its own to bind)
                else:
                    sampler.use(unit)
            units += (unit,)
    return units


def bind_images(program, images: Mapping[str, object] | None = None, /, **more) -> None:
    """Bind each texture as an image at the unit of ``program``'s image uniform of that name (its
    ``layout(binding = N, format)``), for the access its declaration gives (``readonly``,
    ``writeonly`` or both); a name the program does not use is skipped."""
    extra = program.extra
    declared = extra["images"]                # (unit, read, write) by name, from the compiler check
    hazards = extra["hazards"] if "hazards" in extra else _hazards(program)
    dirty = hazards._dirty
    images = {**images, **more} if images else more
    for name in images:
        if name in declared:
            texture = images[name]
            unit, read, write = declared[name]
            key = id(texture)
            if dirty and key in dirty and (entry := dirty[key])[0]() is texture:
                hazards._need |= entry[2] & moderngl.SHADER_IMAGE_ACCESS_BARRIER_BIT
            if write:
                if type(texture) in _TEXTURES:       # Hazards.stage, inlined
                    hazards._staged[key] = (texture, "texture")
                else:
                    hazards.stage(texture)
            if type(texture) in _TEXTURES:
                texture.mglo.bind(unit, read, write, 0, 0)     # Texture.bind_to_image, unwrapped
            else:
                texture.bind_to_image(unit, read, write)


def bind_buffers(program, buffers: Mapping[str, object] | None = None, /, **more) -> None:
    """Bind each buffer at the binding of ``program``'s storage block of that name (its
    ``layout(std430, binding = N) buffer Name``); a name the program does not use is skipped. A
    block not declared ``readonly`` counts as written by the next dispatch."""
    extra = program.extra                        # storage blocks not declared readonly, from the compiler check
    if type(extra) is dict:
        written = extra["written"] if "written" in extra else None
        hazards = extra["hazards"] if "hazards" in extra else hazards_of(program.ctx)
        try:
            bindings = extra["bindings"]
        except KeyError:
            bindings = extra["bindings"] = {}
    else:
        written, hazards, bindings = None, hazards_of(program.ctx), {}   # unknown: every block may be written
    dirty = hazards._dirty
    buffers = {**buffers, **more} if buffers else more
    for name in buffers:
        buffer = buffers[name]
        try:
            binding = bindings[name]
        except KeyError:
            member = program.get(name, None)
            binding = bindings[name] = None if member is None else member.binding
        if binding is not None:
            key = id(buffer)
            if dirty and key in dirty and (entry := dirty[key])[0]() is buffer:
                hazards._need |= entry[2] & moderngl.SHADER_STORAGE_BARRIER_BIT
            if written is None or name in written:
                if type(buffer) is moderngl.Buffer:     # Hazards.stage, inlined
                    hazards._staged[key] = (buffer, "buffer")
                else:
                    hazards.stage(buffer)
            if type(buffer) is moderngl.Buffer:
                buffer.mglo.bind_to_storage_buffer(binding, 0, -1)   # Buffer.bind_to_storage_buffer, unwrapped
            else:
                buffer.bind_to_storage_buffer(binding)


def bind_blocks(program, blocks: Mapping[str, object] | None = None, /, **more) -> None:
    """Bind each buffer at the binding of ``program``'s uniform block of that name (its ``layout(std140,
    binding = N) uniform Name``), a buffer another pass wrote (declared ``uniform`` in the graph, which
    issues its barrier); a name the program does not use is skipped. A block the CPU writes goes
    through :func:`write_block` instead."""
    blocks = {**blocks, **more} if blocks else more
    for name in blocks:
        member = program.get(name, None)
        if member is not None:
            blocks[name].bind_to_uniform_block(member.binding)


def buffer_uses(program, buffers: Mapping[str, object]) -> tuple:
    """(buffer, its id, binding, written) for each of ``buffers`` (block name -> buffer) that ``program``
    has: what :func:`bind_buffers` works out, once, for a loop of dispatches (:func:`use_buffers`)."""
    extra = program.extra
    written = extra.get("written") if type(extra) is dict else None
    uses = []
    for name, buffer in buffers.items():
        member = program.get(name, None)
        if member is not None:
            uses.append((buffer, id(buffer), member.binding, written is None or name in written))
    return tuple(uses)


def use_buffers(program, uses: tuple, bind: bool = True) -> None:
    """:func:`bind_buffers` from :func:`buffer_uses`: each buffer's barrier asked for and its storage
    writes staged for the next dispatch; ``bind=False`` where they are still bound at their
    bindings (a loop of dispatches of ``program`` with nothing else in between)."""
    extra = program.extra
    hazards = extra["hazards"] if type(extra) is dict and "hazards" in extra else hazards_of(program.ctx)
    dirty, staged = hazards._dirty, hazards._staged
    for buffer, key, binding, written in uses:
        if dirty and key in dirty and (entry := dirty[key])[0]() is buffer:
            hazards._need |= entry[2] & moderngl.SHADER_STORAGE_BARRIER_BIT
        if written:
            staged[key] = (buffer, "buffer")
        if bind:
            if type(buffer) is moderngl.Buffer:
                buffer.mglo.bind_to_storage_buffer(binding, 0, -1)
            else:
                buffer.bind_to_storage_buffer(binding)


def std140_mat3(data: bytes) -> np.ndarray:
    """float32 (12,): a column-major mat3 (36 bytes, as :func:`atmos.camera.gl_matrix` writes it) laid out
    as a uniform block holds it under std140: three vec4 columns, each padded to 16 bytes."""
    out = np.zeros((3, 4), np.float32)
    out[:, :3] = np.frombuffer(data, np.float32).reshape(3, 3)
    return out.reshape(-1)


def write_block(program, name: str, binding: int, data: bytes) -> bool:
    """Bind ``program``'s own buffer of uniform block ``name`` at ``binding`` with ``data`` (std140,
    packed by the caller), written only when it changed (the buffer is kept in ``program.extra`` and
    released with the program by the GpuContext that owns it). Returns False, doing nothing, where the program has no such block."""
    if not has_member(program, name):
        return False
    extra = program.extra
    if type(extra) is not dict:                  # a program made past the compiler check
        extra = program.extra = {}
    blocks = extra.setdefault("blocks", {})
    entry = blocks.get(name)
    if entry is None or len(entry[1]) != len(data):
        if entry is not None:
            entry[0].release()
            extra["owned"].remove(entry[0])
        entry = blocks[name] = [program.ctx.buffer(reserve=len(data)), b""]
        extra.setdefault("owned", []).append(entry[0])
    if entry[1] != data:
        entry[0].write(data)
        entry[1] = data
    entry[0].bind_to_uniform_block(binding)
    return True
