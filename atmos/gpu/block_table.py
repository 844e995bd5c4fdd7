"""Per-dispatch constants without uniform writes: the records of one std140 uniform block, all in one
buffer written once, each at a multiple of the context's uniform-buffer offset alignment; binding
record ``i`` (``glBindBufferRange``) selects the constants the next dispatch or draw reads."""
from __future__ import annotations

import struct


class BlockTable:
    """``records`` (bytes, std140-packed by the caller) of the uniform block at ``binding``, uploaded
    once; :meth:`use` binds one of them at that binding. The owner releases it (:meth:`release`)."""

    def __init__(self, gpu, binding: int, records):
        records = [bytes(r) for r in records]
        if not records:
            raise ValueError("BlockTable needs at least one record")
        ctx = gpu.ctx
        align = int(ctx.info.get("GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT") or 256)
        self.size = -(-max(len(r) for r in records) // 16) * 16        # std140 blocks end on a vec4
        self.stride = -(-self.size // align) * align
        self.binding = int(binding)
        self.count = len(records)
        self.buffer = ctx.buffer((b"".join(r.ljust(self.stride, b"\0") for r in records)))

    def use(self, index: int) -> None:
        """Bind record ``index`` at the block's binding (moderngl's Buffer.bind_to_uniform_block, unwrapped)."""
        self.buffer.mglo.bind_to_uniform_block(self.binding, index * self.stride, self.size)

    def release(self) -> None:
        if self.buffer is not None:
            self.buffer.release()
            self.buffer = None


def ints(*values: int) -> bytes:
    """std140 ints (4 bytes each) in declaration order."""
    return struct.pack(f"<{len(values)}i", *values)
