"""Block errors of renders against a reference, as docs/PERFORMANCE.md and the vpm and ppb
READMEs give them for the fog scenes.

    python tests/benches/blocks.py REF.exr IMAGE.exr... [--block 16] [--lamp 20]

For each image: the worst and the median block (16x16 pixels by default) of the channel mean,
|block - reference block| / max(reference block, 2 % of the reference's image mean); the image
mean's bias; and `foton compare`'s rel_mse, the mean over pixels and channels of
(x - r)^2 / (r^2 + 0.01). Pixels that see a lamp (the reference's channel mean above `--lamp`
times its image mean) and the pixels beside them (the lamp's anti-aliased edge, which moves an
image's mean by several per cent from one render to the next) are left out of all of them.

Reads EXR files with the foton Python package (`pip install ./python`).
"""

import argparse

import numpy as np


def read(path):
    import foton

    return np.asarray(foton.read(path), dtype=np.float64)[..., :3]


def lamp_mask(ref_mean, lamp):
    bright = ref_mean > lamp * ref_mean.mean()
    grown = bright.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(bright, dy, axis=0), dx, axis=1)
    return grown


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("reference")
    parser.add_argument("images", nargs="+")
    parser.add_argument("--block", type=int, default=16)
    parser.add_argument("--lamp", type=float, default=20.0)
    args = parser.parse_args()

    ref = read(args.reference)
    ref_mean = ref.mean(axis=2)
    keep = ~lamp_mask(ref_mean, args.lamp)
    floor = 0.02 * ref_mean[keep].mean()
    h, w = ref_mean.shape
    b = args.block
    for path in args.images:
        img = read(path)
        img_mean = img.mean(axis=2)
        errors = []
        for y in range(0, h - b + 1, b):
            for x in range(0, w - b + 1, b):
                k = keep[y : y + b, x : x + b]
                if not k.any():
                    continue
                r = ref_mean[y : y + b, x : x + b][k].mean()
                v = img_mean[y : y + b, x : x + b][k].mean()
                errors.append((abs(v - r) / max(r, floor), (v - r) / max(r, floor), y, x))
        errors.sort()
        worst = errors[-1]
        median = errors[len(errors) // 2][0]
        bias = img_mean[keep].mean() / ref_mean[keep].mean() - 1.0
        rel_mse = np.mean(((img - ref) ** 2 / (ref**2 + 0.01))[keep])
        print(
            f"{path}: worst block {100 * worst[0]:.1f} % ({100 * worst[1]:+.1f} % at row {worst[2]}, "
            f"column {worst[3]}), median {100 * median:.1f} %, mean {100 * bias:+.2f} %, "
            f"rel_mse {rel_mse:.5f} ({(~keep).sum()} lamp pixels left out)"
        )


if __name__ == "__main__":
    main()
