"""numpy reference of ``text/label.frag`` over a uint8 screen."""
import numpy as np


def draw_label(screen: np.ndarray, coverage: np.ndarray, x: int, y: int, color) -> np.ndarray:
    """``screen`` (h, w, 3) uint8, rows top-down, with ``coverage`` (uint8, top-down) blended in at pixel
    (x, y) (its top-left corner) in ``color`` (r, g, b, a in [0, 1]): out = c·a + screen·(1 − a)."""
    out = screen.astype(np.float64) / 255.0
    h, w = coverage.shape
    H, W = screen.shape[:2]
    x0, y0, x1, y1 = max(x, 0), max(y, 0), min(x + w, W), min(y + h, H)
    if x1 <= x0 or y1 <= y0:
        return out
    a = coverage[y0 - y:y1 - y, x0 - x:x1 - x, None] / 255.0 * color[3]
    out[y0:y1, x0:x1] = np.asarray(color[:3]) * a + out[y0:y1, x0:x1] * (1.0 - a)
    return out
