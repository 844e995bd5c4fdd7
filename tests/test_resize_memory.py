"""A window dragged through many sizes keeps no memory per size, clouds included: the pool evicts the
textures of sizes no frame uses any more, and on a software rasterizer (textures in host memory) the
heap's freed pages go back to the system (before: +4 to +13 MB over 20 sizes of the cloud scene)."""
import subprocess
import sys
from pathlib import Path

SCENE = f"""
import gc, sys
sys.path.insert(0, {str(Path(__file__).parent.parent / "benchmarks")!r})
from bench_soak import cloud_scene
from bench_resize_memory import rss_mb
from atmos.gpu import create_headless
gpu = create_headless((320, 180))
app = cloud_scene(gpu)
app.run_frames(5)
def drag(n):
    for k in range(n):
        gpu.resize((320 + 7 * k, 180 + 5 * k)); app.run_frames(2)
    gpu.resize((320, 180)); app.run_frames(6)
    gc.collect()
drag(3)                                   # every size's programs and caches made once
before = rss_mb()
drag(20)
print(gpu.software, rss_mb() - before)
"""


def test_resizing_the_cloud_scene_keeps_no_memory_per_size():
    done = subprocess.run([sys.executable, "-c", SCENE], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    software, growth = done.stdout.split()
    assert float(growth) < 1.5, f"resident memory grew by {float(growth):.2f} MB over 20 sizes"
