"""Renders Mitsuba scene files with foton and with Mitsuba 3 and compares the two images.

    pip install mitsuba          # 3.x
    python3 tests/corpus/vs_mitsuba3.py --foton target/release/foton [--size 128] \
        [--spp 256] [--variant scalar_rgb] [--integrator NAME] [--set KEY=VALUE] FILE.xml [...]

Each file is copied beside itself (so that its relative paths resolve), with the film's
`width` and `height` scaled so that the larger is `--size` and any crop window dropped, then
rendered by Mitsuba 3 twice (seeds 1 and 2) and by foton once (`foton render --spp N`), at
`--spp` samples per pixel each. The copy is removed afterwards.

For each file it prints the relative difference of the image means (foton against Mitsuba's
first render) and the median and worst relative difference of 16x16-pixel blocks, next to the
same numbers for Mitsuba against itself (the two seeds): the noise the comparison has to be
read against. A file agrees when the mean differs by less than 1 % (or less than three times
Mitsuba's own mean difference) and the worst block by less than twice Mitsuba's own worst
block plus 1 %. Blocks darker than 1 % of the image mean are left out of the relative
numbers (their relative error is noise over nothing).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np

import mitsuba as mi


def scaled_copy(path, size):
    """A copy of `path` beside it with the film scaled to `size` on its larger side."""
    tree = ET.parse(path)
    root = tree.getroot()
    defaults = {d.get("name"): d.get("value") for d in root.iter("default")}

    def value(el):
        v = el.get("value", "")
        return defaults.get(v[1:], v) if v.startswith("$") else v

    for film in root.iter("film"):
        dims = {}
        for child in list(film):
            name = child.get("name", "")
            if child.tag == "integer" and name in ("width", "height"):
                dims[name] = child
            if name.replace("_", "").lower() in (
                "cropoffsetx",
                "cropoffsety",
                "cropwidth",
                "cropheight",
            ):
                film.remove(child)
        w = h = None
        if dims:
            try:
                w = int(value(dims["width"])) if "width" in dims else 768
                h = int(value(dims["height"])) if "height" in dims else 576
            except ValueError:
                w = h = None
        if w is None:
            w, h = 768, 576
        k = size / max(w, h)
        for name, v in (("width", w), ("height", h)):
            el = dims.get(name)
            if el is None:
                el = ET.SubElement(film, "integer", {"name": name})
            el.set("value", str(max(1, round(v * k))))
    fd, copy = tempfile.mkstemp(suffix=".xml", prefix=".vs-mi3-", dir=os.path.dirname(path) or ".")
    os.close(fd)
    tree.write(copy)
    return copy


def mitsuba_render(path, spp, seed):
    scene = mi.load_file(path)
    img = mi.render(scene, spp=spp, seed=seed)
    return np.array(img, dtype=np.float64)[:, :, :3]


def foton_render(foton, path, spp, out, extra=()):
    cmd = [foton, "render", path, "--spp", str(spp), "-q", "-o", out, *extra]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "failed")
    return np.array(mi.Bitmap(out), dtype=np.float64)[:, :, :3]


def stats(a, b, block=16):
    """Relative difference of the means, and the median and maximum relative difference of
    block means (blocks of `b` darker than 1 % of its mean left out)."""
    ma, mb = a.mean(), b.mean()
    mean = (ma - mb) / mb if mb > 0 else 0.0
    h, w = b.shape[:2]
    rel = []
    for y in range(0, h - h % block or h, block):
        for x in range(0, w - w % block or w, block):
            ba = a[y : y + block, x : x + block].mean()
            bb = b[y : y + block, x : x + block].mean()
            if bb > 0.01 * mb:
                rel.append(abs(ba - bb) / bb)
    rel = np.array(rel) if rel else np.zeros(1)
    return mean, float(np.median(rel)), float(rel.max())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--foton", required=True)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--integrator", help="foton's integrator, instead of the file's")
    ap.add_argument("--set", action="append", default=[], help="foton's --set (repeatable)")
    ap.add_argument("files", nargs="+")
    args = ap.parse_args()
    mi.set_variant(args.variant)
    foton = os.path.abspath(args.foton)
    print("| file | mean (foton vs mi) | block median | block worst | mi vs mi: mean | median | worst | agrees |")
    print("|---|---|---|---|---|---|---|---|")
    failures = 0
    for f in args.files:
        copy = scaled_copy(f, args.size)
        out = tempfile.mktemp(suffix=".exr")
        try:
            ref = mitsuba_render(copy, args.spp, 1)
            ref2 = mitsuba_render(copy, args.spp, 2)
            extra = ["--integrator", args.integrator] if args.integrator else []
            for kv in args.set:
                extra += ["--set", kv]
            img = foton_render(foton, copy, args.spp, out, extra)
            if img.shape != ref.shape:
                raise RuntimeError(f"sizes differ: foton {img.shape}, mitsuba {ref.shape}")
            m, med, worst = stats(img, ref)
            m0, med0, worst0 = stats(ref2, ref)
            ok = (abs(m) < 0.01 or abs(m) < 3 * abs(m0)) and worst < 2 * worst0 + 0.01
            failures += not ok
            print(
                f"| {f} | {100 * m:+.2f} % | {100 * med:.2f} % | {100 * worst:.2f} % "
                f"| {100 * m0:+.2f} % | {100 * med0:.2f} % | {100 * worst0:.2f} % | {'yes' if ok else 'NO'} |"
            )
        except Exception as e:  # one file's failure does not stop the others
            failures += 1
            msg = " ".join(str(e).split())[-160:] or type(e).__name__
            print(f"| {f} | error: {msg} | | | | | | NO |")
        finally:
            os.remove(copy)
            if os.path.exists(out):
                os.remove(out)
        sys.stdout.flush()
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
