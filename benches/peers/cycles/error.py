"""Time × relMSE of mcctrace and Cycles from `cafe.sh`'s (or `glass.sh`'s) folder: per view and renderer, the
variance part of relMSE from its two seeds, mean over pixels and channels of
(a − b)² / 2 / (r² + 0.01), r the mean of all four renders (one r for both renderers), times the
mean seconds of its two renders; then mcctrace's product over Cycles' (≤ 0.5 is issue 25's
target: the same relMSE in half Cycles' time).

    error.py FOLDER    (reads FOLDER/times.csv and FOLDER/{mcc,cycles}-VIEW-{1,2}.exr)
"""

import csv
import os
import sys

import numpy as np
from render import load_rgb  # Blender's image loader, as render.py reads its EXRs


def main():
    folder = sys.argv[1]
    seconds = {}
    with open(os.path.join(folder, "times.csv")) as f:
        for who, view, _seed, spp, s in csv.reader(f):
            seconds.setdefault((who, view), []).append(float(s))
            seconds[(who, view, "spp")] = int(spp)
    order = ["wide", "left", "right"]
    views = sorted({k[1] for k in seconds if len(k) == 2}, key=lambda v: (order + [v]).index(v))
    print("view,renderer,spp,seconds,rel_mse,time_x_rel_mse,ratio_to_cycles")
    for view in views:
        images = {w: [load_rgb(os.path.join(folder, f"{w}-{view}-{s}.exr")) for s in (1, 2)]
                  for w in ("mcc", "cycles")}
        r = sum(images["mcc"] + images["cycles"]) / 4.0
        product = {}
        for who, key in (("cycles", "cycles"), ("mcctrace", "mcc")):
            a, b = images[key]
            rel = float(np.mean((a - b) ** 2 / 2.0 / (r * r + 0.01)))
            t = float(np.mean(seconds[(who, view)]))
            product[who] = t * rel
            ratio = product[who] / product["cycles"]
            print(f"{view},{who},{seconds[(who, view, 'spp')]},{t:.2f},{rel:.4e},"
                  f"{product[who]:.4e},{ratio:.3f}")
        means = {k: np.mean(v[0] + v[1], axis=(0, 1)) / 2 for k, v in images.items()}
        print(f"# {view}: channel means mcctrace {means['mcc']}, cycles {means['cycles']}")


if __name__ == "__main__":
    main()
