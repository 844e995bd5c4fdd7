"""The sprites splatted in compute (thesis ch. 6 sprites, drawn as tiled front-to-back compositing):
their cost follows the pixels they cover, not the overdraw of blended points.

Four dispatches (``shaders/clouds/sprites/splat_*.comp``): ``setup`` runs the point draw's vertex stage
per block (``sprite.glsl``) and appends a record for every drawn sprite, counting it in each 16×16 tile
its point square covers; ``scan`` turns the counts into offsets; ``bin`` writes (key, record) into the
tiles' lists (the key: its place in the point draw's back-to-front order); ``blend`` sorts each tile's
list by key and blends every pixel's sprites front to back until T < 1/255, then over the target (or,
off screen, into it). The image is the point draw's up to float16 rounding of each blend there and the
1/255 left out here, except that a sprite centred off screen (which GL clips) still draws its part.

The lists' buffers belong to the pass: records for every block submitted, entries for 8 per block to
start; the entries a frame needed come back through a ring of small buffers read once a fence says the
GPU is done with them (never waiting), and the list grows to hold them from then on. Nothing is cleared
from the CPU (a mapped clear waits for the GPU): the scan and the blend leave the counts at 0.
"""
from __future__ import annotations

import numpy as np

from atmos.gpu.hazards import hazards_of
from atmos.gpu.queries import Fence
from atmos.gpu.uniforms import write_uniforms
from atmos.graph import work_groups

TILE = 16                # splat.glsl
RECORD_BYTES = 160       # splat.glsl: RECORD uvec4
ENTRY_BYTES = 8
SETUP_GROUP = 64
MAX_GROUPS_Y = 65535     # the least maximum work-group count GL guarantees per axis
RING = 3                 # readbacks of the entries needed in flight


def _pow2(n: int) -> int:
    """The least power of two >= n (at least 2): buffer sizes that settle instead of following every frame."""
    return 1 << max(int(n) - 1, 1).bit_length()


class SpriteSplat:
    """The compute splat's programs' use and its buffers, for one :class:`CloudSpritePass`."""

    first_entries = 8    # list entries per submitted block before a frame's need has come back
    count = False        # SPLAT_COUNT: the blend counts its work for :meth:`work` (a benchmark's; costs atomics)

    def __init__(self, gpu):
        self.gpu = gpu
        ctx = gpu.ctx
        self.counters = ctx.buffer(bytes(16))         # zero: the scan leaves it so for the next frame
        self.records = self.tile_count = self.tile_offset = self.entries = None
        self._binds = None                      # storage block name -> buffer, made again when one grows
        self.ring = [ctx.buffer(reserve=8) for _ in range(RING)]
        self.fences: list = [None] * RING
        self.slot = 0
        self.needed = 0                  # the most entries a frame was seen to need
        self.tiles = 0                   # the last frame's tiles
        self.dropped = 0                 # frames whose list was too short (read back late)

    def _grow(self, name: str, nbytes: int, zero: bool = False):
        """Buffer ``name`` holding at least ``nbytes`` (made anew, zero-filled with ``zero``, when smaller)."""
        buffer, nbytes = getattr(self, name), max(int(nbytes), 16)
        if buffer is None or buffer.size < nbytes:
            if buffer is not None:
                buffer.release()
            buffer = self.gpu.ctx.buffer(bytes(nbytes)) if zero else self.gpu.ctx.buffer(reserve=nbytes)
            setattr(self, name, buffer)
            self._binds = None
        return buffer

    def _read_back(self) -> None:
        """The entries needed by frames whose fence is done (never waits)."""
        for i, fence in enumerate(self.fences):
            if fence is not None and fence.done():
                needed = int(np.frombuffer(self.ring[i].read(), np.uint32)[0])
                if needed > self.entries.size // ENTRY_BYTES:
                    self.dropped += 1
                self.needed = max(self.needed, needed)
                self.fences[i] = None

    def draw(self, frame, programs, segments_buffer, segment_count: int, group, sprites: int, size,
             textures: dict, images: dict) -> None:
        """Splat ``segment_count`` segments (``sprites`` blocks in all) into ``images`` ("color_image",
        "distance_image") of ``size``; ``programs`` (setup, scan, bin, blend) have their other
        uniforms and the volume bound; ``textures`` holds "scene_depth"."""
        setup, scan, binning, blend = programs
        w, h = int(size[0]), int(size[1])
        tiles = (-(-w // TILE), -(-h // TILE))
        count = self.tiles = tiles[0] * tiles[1]
        records = _pow2(max(sprites, 1))
        if self.entries is not None:
            self._read_back()
        capacity = _pow2(max(self.first_entries * records, self.needed + self.needed // 4, 1 << 10))
        self._grow("records", records * RECORD_BYTES)
        self._grow("tile_count", 4 * count, zero=True)       # the blend leaves it at 0 for the next frame
        self._grow("tile_offset", 4 * (count + 2))
        self._grow("entries", capacity * ENTRY_BYTES)
        capacity = self.entries.size // ENTRY_BYTES
        if self.count:
            self.counters.write(bytes(16))      # the work counts (a benchmark's: it waits for the GPU)
        buffers = self._binds
        if buffers is None:                     # the storage blocks' buffers, named once per (re)allocation
            buffers = self._binds = {"SplatCounters": self.counters, "SplatRecords": self.records,
                                     "SplatTiles": self.tile_count, "SplatOffsets": self.tile_offset,
                                     "SplatEntries": self.entries}
        common = {"target_size": (w, h), "tiles": tiles, "entry_capacity": capacity}
        unit_blocks = 4 * int(group[0]) * int(group[1])
        gy = min(segment_count, MAX_GROUPS_Y)
        write_uniforms(setup, common, segment_count=segment_count, unit_blocks=unit_blocks, record_capacity=records)
        frame.dispatch(setup, (-(-unit_blocks // SETUP_GROUP), gy, -(-segment_count // gy)),
                       buffers={**buffers, "SplatSegments": segments_buffer})
        write_uniforms(scan, common)
        frame.dispatch(scan, (1,), buffers=buffers)
        write_uniforms(binning, common)
        frame.dispatch(binning, work_groups((records,), (SETUP_GROUP,)), buffers=buffers)
        write_uniforms(blend, common)
        frame.dispatch(blend, tiles, textures=textures, images=images, buffers=buffers)
        if self.fences[self.slot] is None:
            ring = self.ring[self.slot]             # the totals behind the offsets: (entries, sprites)
            hazards_of(frame.gpu.ctx).use(reads=[(self.tile_offset, "copy")], writes=[(ring, "copy")])
            frame.gpu.ctx.copy_buffer(ring, self.tile_offset, 8, read_offset=4 * count)
            self.fences[self.slot] = Fence()
            self.slot = (self.slot + 1) % RING

    def work(self) -> dict:
        """The last frame's counts (waits for the GPU: a benchmark's, with ``count`` on): sprites drawn, the
        pixels their point squares cover (what blended points fill), the sprite-pixel pairs the blend
        tested and shaded, list entries."""
        entries, sprites = (int(v) for v in np.frombuffer(self.tile_offset.read(8, offset=4 * self.tiles), np.uint32))
        _, covered, tested, shaded = (int(v) for v in np.frombuffer(self.counters.read(), np.uint32))
        return {"sprites": sprites, "entries": entries, "covered": covered, "tested": tested, "shaded": shaded}

    def release(self) -> None:
        for fence in self.fences:
            if fence is not None:
                fence.delete()
        self.fences = [None] * RING
        for obj in (self.counters, self.records, self.tile_count, self.tile_offset, self.entries, *self.ring):
            if obj is not None:
                obj.release()
        self.counters = self.records = self.tile_count = self.tile_offset = self.entries = self._binds = None
        self.ring = []
