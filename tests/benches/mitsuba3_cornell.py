"""Mitsuba 3's side of tests/benches/mitsuba3-cornell.sh: its CPU time on docs/cornell_point-mitsuba3.xml,
and the RMSE of EXR images against a reference.

    python mitsuba3_cornell.py time SPP SAMPLER SEED [OUT.exr]   # prints CPU seconds
    python mitsuba3_cornell.py rmse REF.exr IMAGE.exr...          # prints RMSE (and / mean)

`time` renders with the variant llvm_ad_rgb (MI_VARIANT overrides it) after a 1-spp warm-up
(the kernel then comes from Dr.Jit's cache), and measures time.process_time() around
mi.render + dr.eval + dr.sync_thread: Dr.Jit evaluates lazily, so the render's own log line
can read 0 ms. SAMPLER replaces the file's `independent` (multijitter, stratified, ldsampler,
orthogonal...). Needs mitsuba 3.9.1 and numpy.
"""

import os
import sys
import time
from pathlib import Path

XML = Path(__file__).resolve().parents[2] / "docs" / "cornell_point-mitsuba3.xml"


def load(mi, sampler, spp):
    text = XML.read_text().replace('<sampler type="independent">', f'<sampler type="{sampler}">')
    return mi.load_string(text, spp=str(spp))


def cpu_time(spp, sampler, seed, out=None):
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(os.environ.get("MI_VARIANT", "llvm_ad_rgb"))
    warm = load(mi, sampler, 1)
    dr.eval(mi.render(warm, spp=1, seed=seed))
    dr.sync_thread()
    scene = load(mi, sampler, spp)
    start = time.process_time()
    image = mi.render(scene, spp=spp, seed=seed)
    dr.eval(image)
    dr.sync_thread()
    seconds = time.process_time() - start
    if out:
        mi.Bitmap(image).write(out)
    return seconds


def rmse(reference, images):
    import mitsuba as mi
    import numpy as np

    mi.set_variant("scalar_rgb")
    ref = np.array(mi.Bitmap(reference), dtype=np.float64)[..., :3]
    for path in images:
        img = np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]
        e = float(np.sqrt(np.mean((img - ref) ** 2)))
        print(f"{path}: RMSE {e:.4f} ({e / ref.mean():.3f} of the mean), mean {img.mean():.5f}")


if __name__ == "__main__":
    if sys.argv[1] == "time":
        spp, sampler, seed = int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
        out = sys.argv[5] if len(sys.argv) > 5 else None
        print(f"{cpu_time(spp, sampler, seed, out):.2f}")
    elif sys.argv[1] == "rmse":
        rmse(sys.argv[2], sys.argv[3:])
    else:
        sys.exit(__doc__)
