"""Mitsuba 3's load time for the PLY mesh of the ply_load benchmark, for docs/PERFORMANCE.md.

Not a test (neither CI nor cargo runs it). It needs Mitsuba 3 (pip install mitsuba) and the
file the benchmark keeps:

    FOTON_PLY_KEEP=1 cargo bench -p foton-tests --bench ply_load   # prints the file's path
    python tests/benches/ply_load_mitsuba.py /tmp/foton-test-.../sphere.ply [runs]

Each timing is one load in a fresh Python process (as the benchmark's foton load is the first
in its process), after `import mitsuba` and `set_variant`, which are not counted. It prints
every run and the best of `runs` (3 by default) of:

  ply:   mi.load_dict({'type': 'ply', ...}), the mesh alone: PLY parse into Mitsuba's buffers;
  scene: a scene holding the mesh: the same, plus the acceleration structure (in scalar_rgb
         an Embree BVH when Mitsuba is built with Embree, as the pip wheels are, else
         Mitsuba's own kd-tree), built on all cores.
"""

import subprocess
import sys
import time


def once(kind, path):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mesh = {"type": "ply", "filename": path}
    what = mesh if kind == "ply" else {"type": "scene", "mesh": mesh}
    start = time.perf_counter()
    loaded = mi.load_dict(what)
    seconds = time.perf_counter() - start
    if kind == "scene":
        # The scene's shape is the mesh, with all its faces.
        assert loaded.shapes()[0].face_count() > 0
    print(f"{seconds:.6f} {int(mi.MI_ENABLE_EMBREE)}")


def main():
    if sys.argv[1] == "--once":
        once(sys.argv[2], sys.argv[3])
        return
    path = sys.argv[1]
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    for kind in ("ply", "scene"):
        times = []
        for _ in range(runs):
            out = subprocess.run(
                [sys.executable, __file__, "--once", kind, path],
                check=True,
                capture_output=True,
                text=True,
            ).stdout.split()
            times.append(float(out[0]))
            embree = out[1] == "1"
        runs_text = " ".join(f"{t:.3f}" for t in times)
        accel = (" (Embree BVH)" if embree else " (Mitsuba's kd-tree)") if kind == "scene" else ""
        print(f"mitsuba {kind}{accel}: best {min(times):.3f} s of {runs_text}")


if __name__ == "__main__":
    main()
