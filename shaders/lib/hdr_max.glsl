// The most light one effect writes or blends into a pixel of the float16 HDR colour (atmos/render_core.py
// HDR_MAX): 2^14, about a quarter of float16's largest finite 65504. A blend past 65504 is +inf on NVIDIA (Mesa stops
// at 65504) and NaN after the tone map; premultiplied "over" blends of values at most this stay at most
// this, with room for float16 blending's rounding and for what other passes add.
#ifndef HDR_MAX_INCLUDED
#define HDR_MAX_INCLUDED
const float HDR_MAX = 16384.0;
#endif
