"""The one uniform writer: values by name into a program, skipping the uniforms its compiler dropped."""
from __future__ import annotations

from collections.abc import Mapping


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
