import sys, numpy as np
sys.path.insert(0, "/work/main/benches/peers/cycles")
from render import load_rgb
d = sys.argv[1]; variants = sys.argv[2].split(","); seeds = [int(x) for x in sys.argv[3].split(",")]
im = {v: [load_rgb(f"{d}/{v}-{s}.exr") for s in seeds] for v in variants}
cy = [load_rgb(f"/tmp/ffs/cyc-{s}.exr") for s in range(3, 11)]
allim = [a for v in variants for a in im[v]] + cy
r = sum(allim) / len(allim)
n = len(seeds)
for v in variants:
    own = sum(im[v]) / n
    es = [np.mean((a - own) ** 2 / (r * r + 0.01), axis=2) * n / (n - 1) for a in im[v]]
    print(v, "relvar %.4e" % np.mean(es), "means", np.round(own.mean(axis=(0, 1)), 4))
