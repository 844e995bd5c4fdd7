"""A window dragged through many sizes keeps no memory per size, clouds included: the pool evicts the
textures of sizes no frame uses any more, and on a software rasterizer (textures in host memory) the
heap's freed pages go back to the system (before: +2 to +5 MB over 20 new sizes of the cloud scene; now ~0.1)."""
import subprocess
import sys
from pathlib import Path

SCENE = f"""
import gc, sys
sys.path.insert(0, {str(Path(__file__).parent.parent / "benchmarks")!r})
from bench_soak import cloud_scene
from atmos.gpu import create_headless


def rss_mb():   # anonymous resident MB: heap and textures, not library pages (a late compile pages in more)
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("RssAnon:")) / 1024
gpu = create_headless((320, 180))
app = cloud_scene(gpu)
app.run_frames(5)
def drag(first, n):
    for k in range(first, first + n):
        gpu.resize((320 + 7 * k, 180 + 5 * k)); app.run_frames(2)
    gpu.resize((320, 180)); app.run_frames(6)
    gc.collect()
drag(0, 12)                               # programs, caches and the allocator's own pools made once
before = rss_mb()
drag(12, 20)                              # 20 sizes never seen before
print(gpu.software, rss_mb() - before)
"""


def test_resizing_the_cloud_scene_keeps_no_memory_per_size():
    done = subprocess.run([sys.executable, "-c", SCENE], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    software, growth = done.stdout.split()
    assert float(growth) < 1.0, f"resident memory grew by {float(growth):.2f} MB over 20 new sizes"
