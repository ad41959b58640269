"""Mitsuba 3's load time for the mesh of the serialized_load benchmark, for docs/PERFORMANCE.md.

Not a test (neither CI nor cargo runs it). It needs Mitsuba 3 (pip install mitsuba) and the
file the benchmark keeps:

    FOTON_SERIALIZED_KEEP=1 cargo bench -p foton-loader --bench serialized_load
    python core/loader/benches/serialized_load_mitsuba.py /tmp/foton-serialized-bench-.../sphere.serialized [runs]

Each timing is one load in a fresh Python process, after `import mitsuba` and `set_variant`
(not counted); it prints the best of `runs` (3 by default) of the mesh alone
(`mi.load_dict({'type': 'serialized', ...})`) and of a scene holding it (plus the
acceleration structure, built on all cores).
"""

import subprocess
import sys
import time


def once(kind, path):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mesh = {"type": "serialized", "filename": path}
    what = mesh if kind == "mesh" else {"type": "scene", "mesh": mesh}
    start = time.perf_counter()
    loaded = mi.load_dict(what)
    seconds = time.perf_counter() - start
    shape = loaded if kind == "mesh" else loaded.shapes()[0]
    assert shape.face_count() == 2 * 708 * 708
    print(f"{seconds:.6f}")


def main():
    if sys.argv[1] == "--once":
        once(sys.argv[2], sys.argv[3])
        return
    path = sys.argv[1]
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    for kind in ("mesh", "scene"):
        times = []
        for _ in range(runs):
            out = subprocess.run(
                [sys.executable, __file__, "--once", kind, path],
                check=True,
                capture_output=True,
                text=True,
            ).stdout
            times.append(float(out.split()[0]))
        runs_text = " ".join(f"{t:.3f}" for t in times)
        print(f"mitsuba {kind}: best {min(times):.3f} s of {runs_text}")


if __name__ == "__main__":
    main()
