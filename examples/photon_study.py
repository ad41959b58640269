#!/usr/bin/env python3
"""The course's photon-mapping study, from Python: photons x k, and error against time.

On scenes/caustics-area.toml (the caustic scene with an area light, so that the path tracer
can render it and give the reference):

1. **Photons x k.** `photon` with 1k, 10k and 100k photons and k = 10, 50, 100 photons per
   estimate: a grid of images beside the path tracer's reference, and a table of the error of
   each (rel_mse, bias, as `foton compare` computes them) with its render time. The photons
   go into one map (`caustic_photons = 0`: the global map keeps the caustic photons too), as
   in the course; a separate caustic map of 1k photons would store too few for k = 100.
2. **Error against time.** `path` (samples per pixel), `photon` (photons and samples) and
   `sppm` (iterations) at growing budgets: the relative MSE against the seconds taken, log-log.
   Read it at equal time: at a given time, the lowest curve is the best method.

    python examples/photon_study.py            # 128x128, about 3 minutes on 2 cores
    python examples/photon_study.py --small    # 32x32, a few seconds (CI runs this)

Writes into --out (default photon-study/): study.png, curve.png, study.md (the table) and
reference.exr (reused by the next run with the same settings). Needs matplotlib.
The notebook photon_study.ipynb is the same study, step by step.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; the notebook shows its plots inline
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import foton  # noqa: E402

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "caustics-area.toml"

FULL = {
    "size": 128,
    "reference_spp": 2048,
    "spp": 4,  # camera samples of the study's photon renders (antialiasing)
    "photons": [1_000, 10_000, 100_000],
    "ks": [10, 50, 100],
    # The error curves: budgets that double.
    "path_spp": [4, 8, 16, 32, 64, 128, 256],
    "photon_budgets": [(5_000, 1), (10_000, 2), (20_000, 4), (40_000, 8), (80_000, 16), (160_000, 32)],
    "sppm_iterations": [2, 4, 8, 16, 32, 64, 128],
    "sppm_photons": 20_000,
}
SMALL = {
    "size": 32,
    "reference_spp": 256,
    "spp": 2,
    "photons": [1_000, 10_000, 100_000],
    "ks": [10, 50, 100],
    "path_spp": [2, 4, 8],
    "photon_budgets": [(2_000, 1), (4_000, 2), (8_000, 4)],
    "sppm_iterations": [2, 4, 8],
    "sppm_photons": 4_000,
}


def load(settings: dict) -> foton.Scene:
    size = settings["size"]
    return foton.load(SCENE, film={"width": size, "height": size})


def reference(scene: foton.Scene, settings: dict, out: Path) -> np.ndarray:
    """The path tracer's image at many samples (reused from `out` if it is there, at the size)."""
    path = out / f"reference-{settings['size']}px-{settings['reference_spp']}spp.exr"
    if path.exists():
        return foton.read(path)
    print(f"reference: path, {settings['reference_spp']} spp ...", flush=True)
    image = scene.render(integrator="path", spp=settings["reference_spp"], seed=1000)
    foton.write(image, path)
    return image


def photons_by_k(scene: foton.Scene, settings: dict, ref: np.ndarray) -> list[dict]:
    """Step 1: a photon render for each photon count and k; its error and time."""
    rows = []
    for n in settings["photons"]:
        for k in settings["ks"]:
            image = scene.render(
                integrator="photon",
                spp=settings["spp"],
                params={"global_photons": n, "caustic_photons": 0, "k": k},
                progress=False,
            )
            errors = foton.compare(image, ref)
            rows.append(
                {
                    "photons": n,
                    "k": k,
                    "seconds": scene.last_render["seconds"],
                    "rel_mse": errors.rel_mse,
                    "bias": errors.bias,
                    "image": image,
                }
            )
            print(f"photon: {n:>7} photons, k = {k:>3}: rel_mse {errors.rel_mse:.4f}, "
                  f"bias {errors.bias:+.4f}, {scene.last_render['seconds']:.2f} s", flush=True)
    return rows


def error_curves(scene: foton.Scene, settings: dict, ref: np.ndarray) -> dict[str, list[tuple]]:
    """Step 2: (seconds, rel_mse) of each integrator at growing budgets."""
    budgets = {
        "path": [dict(spp=s) for s in settings["path_spp"]],
        "photon": [
            dict(spp=s, params={"global_photons": n, "caustic_photons": n})
            for n, s in settings["photon_budgets"]
        ],
        "sppm": [
            dict(params={"iterations": i, "photons_per_iteration": settings["sppm_photons"]})
            for i in settings["sppm_iterations"]
        ],
    }
    curves = {}
    for integrator, runs in budgets.items():
        points = []
        for run in runs:
            image = scene.render(integrator=integrator, progress=False, **run)
            points.append((scene.last_render["seconds"], foton.compare(image, ref).rel_mse))
        curves[integrator] = points
        print(f"{integrator}: " + ", ".join(f"{e:.4f} in {t:.2f} s" for t, e in points), flush=True)
    return curves


def table(rows: list[dict]) -> str:
    lines = ["| photons | k | rel_mse | bias | seconds |", "|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['photons']} | {r['k']} | {r['rel_mse']:.4f} | {r['bias']:+.4f} "
                     f"| {r['seconds']:.2f} |")
    return "\n".join(lines)


def plot_study(rows: list[dict], ref: np.ndarray, display: dict, path: Path) -> None:
    photons = sorted({r["photons"] for r in rows})
    ks = sorted({r["k"] for r in rows})
    fig, axes = plt.subplots(len(photons), len(ks) + 1, figsize=(2.6 * (len(ks) + 1), 2.8 * len(photons)))
    for i, n in enumerate(photons):
        for j, k in enumerate(ks):
            r = next(r for r in rows if r["photons"] == n and r["k"] == k)
            ax = axes[i][j]
            ax.imshow(foton.to_display(r["image"], **display))
            ax.set_title(f"{n} photons, k = {k}\nrel_mse {r['rel_mse']:.4f}", fontsize=8)
        axes[i][-1].imshow(foton.to_display(ref, **display))
        axes[i][-1].set_title("path (reference)", fontsize=8)
    for ax in np.ravel(axes):
        ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_curves(curves: dict[str, list[tuple]], path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5, 4))
    for integrator, points in curves.items():
        t, e = zip(*points)
        ax.loglog(t, e, "o-", label=integrator)
    ax.set_xlabel("render time (s)")
    ax.set_ylabel("relative MSE against the reference")
    ax.set_title("caustics-area: error against time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="tiny settings (seconds, for CI)")
    parser.add_argument("--out", type=Path, default=Path("photon-study"), help="output folder")
    args = parser.parse_args()
    settings = SMALL if args.small else FULL
    args.out.mkdir(parents=True, exist_ok=True)

    start = time.perf_counter()
    scene = load(settings)
    ref = reference(scene, settings, args.out)
    rows = photons_by_k(scene, settings, ref)
    curves = error_curves(scene, settings, ref)

    plot_study(rows, ref, scene.display, args.out / "study.png")
    plot_curves(curves, args.out / "curve.png")
    text = table(rows)
    (args.out / "study.md").write_text(text + "\n")
    print(text)
    # What the study is expected to show; a run that does not is worth a look.
    best = min(rows, key=lambda r: r["rel_mse"])
    worst = max(rows, key=lambda r: r["rel_mse"])
    assert best["photons"] > worst["photons"], "more photons should reduce the error"
    print(f"lowest error: {best['photons']} photons, k = {best['k']}")
    print(f"wrote {args.out}/study.png, curve.png, study.md in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
