"""Where SG-PRT's sun shadow lies against Cycles': the truth suite's diffuse_sun (Suzanne on a floor under a sun of
angle 0.05 rad, Blender's defaults), SG-PRT at its defaults against the Cycles truth.

    .venv/bin/python -m benchmarks.sun_shadow_alignment [--size 128] [--cycles-samples 256]

Prints the relative RMSE over the surface pixels (eroded by three, away from the silhouettes) with SG-PRT's image
moved by sub-pixel shifts of -1.5 .. 1.5 pixels along each axis (bilinear): a shadow outline off by a pixel puts
the best shift there, not at 0; and the pixels brighter than the truth by more than 10% of its mean (light
leaking into a shadow) and darker by as much.
"""
import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def measure(size, cycles_samples):
    import numpy as np
    from scipy import ndimage

    from benchmarks import truth_suite

    run = truth_suite.SceneRun("diffuse_sun", dict(size=size, cycles_samples=cycles_samples, eevee_samples=(16,)),
                               lambda message: None, methods=("SG-PRT", "Cycles"))
    run.run()
    truth = run.truth[..., :3].mean(axis=-1)
    engine = next(image for (method, _), image in run.images.items() if method == "SG-PRT")[..., :3].mean(axis=-1)
    inner = ndimage.binary_erosion(run.mask, iterations=3)
    scale = truth[inner].mean()
    shifts = []
    for dy in np.arange(-1.5, 1.51, 0.25):
        for dx in np.arange(-1.5, 1.51, 0.25):
            moved = ndimage.shift(engine, (dy, dx), order=1, mode="nearest")
            shifts.append((float(np.sqrt(np.mean((moved - truth)[inner] ** 2)) / scale), float(dy), float(dx)))
    shifts.sort()
    difference = (engine - truth)[inner]
    return {"best": shifts[:3], "unshifted": next(s for s in shifts if s[1] == 0 and s[2] == 0),
            "brighter": int((difference > 0.1 * scale).sum()), "darker": int((difference < -0.1 * scale).sum()),
            "pixels": int(inner.sum())}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--cycles-samples", type=int, default=256)
    args = parser.parse_args(argv)
    result = measure(args.size, args.cycles_samples)
    print("relative RMSE by shift (dy, dx pixels), best first: "
          + ", ".join(f"{rmse:.4f} at ({dy:+.2f}, {dx:+.2f})" for rmse, dy, dx in result["best"]))
    print(f"unshifted: {result['unshifted'][0]:.4f}; of {result['pixels']} pixels, {result['brighter']} brighter and "
          f"{result['darker']} darker than the truth by more than 10% of its mean")
    return result


if __name__ == "__main__":
    main()
