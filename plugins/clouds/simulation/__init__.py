"""The cloud simulation chain: CloudsPlugin, the sliced job into three texture sets, smoothing and
density maps."""
