"""Means of two EXR images and the largest relative difference of their 8x8-pixel blocks."""
import sys

import numpy as np
import OpenEXR


def load(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


foton, pbrt = load(sys.argv[1]), load(sys.argv[2])
ratio = foton.mean((0, 1)) / pbrt.mean((0, 1))
h, w, _ = foton.shape
worst = 0.0
for y in range(0, h, 8):
    for x in range(0, w, 8):
        a, b = foton[y:y + 8, x:x + 8].mean(), pbrt[y:y + 8, x:x + 8].mean()
        if b > 1e-3:
            worst = max(worst, abs(a / b - 1))
print(f"foton / pbrt mean RGB {ratio[0]:.4f} {ratio[1]:.4f} {ratio[2]:.4f}, "
      f"worst 8x8 block {100 * worst:.1f} %")
