// The compute splat's lists (splat_*.comp; plugins/clouds/sprites/splat.py): a record of RECORD uvec4
// per drawn sprite, a count per TILE × TILE pixel tile (then its cursor; the blend sets it back to 0),
// the tiles' offsets into one list of (key, record) entries, followed by the frame's totals (entries,
// sprites). A key is the sprite's place in the point draw's order (segment × unit_blocks + block):
// ascending is back to front. Nothing is cleared from the CPU: the scan and the blend leave the counts
// at 0 for the next frame.
const int TILE = 16;
const int RECORD = 10;
const uint SPRITES = 0u;      // counters: sprites drawn so far (the scan moves the total behind the offsets)
// with SPLAT_COUNT (a benchmark's work counts, splat.py SpriteSplat.work; cleared by the CPU): the pixels
// the sprites' point squares cover (what blended points would fill), the sprite-pixel pairs the blend
// tests, and those it shades
const uint COVERED = 1u;
const uint TESTED = 2u;
const uint SHADED = 3u;
layout(std430, binding = 0) buffer SplatCounters { uint counters[]; };
layout(std430, binding = 1) buffer SplatRecords { uvec4 records[]; };   // floats as their bits: keys and rectangles
                                                                       // stay integers (no float path to flush them)
layout(std430, binding = 2) buffer SplatTiles { uint tile_count[]; };   // per tile: its count, then its cursor
layout(std430, binding = 3) buffer SplatOffsets { uint tile_offset[]; };  // per tile: exclusive sums; then entries, sprites
layout(std430, binding = 4) buffer SplatEntries { uvec2 entries[]; };
uniform ivec2 target_size;    // pixels of the target drawn into
uniform ivec2 tiles;          // tiles per row and column
uniform uint entry_capacity;  // entries the list holds

vec4 record(uint i) { return uintBitsToFloat(records[i]); }
void put_record(uint i, vec4 v) { records[i] = floatBitsToUint(v); }
