import sys, numpy as np
sys.path.insert(0, "/work/main/benches/peers/cycles")
from render import load_rgb
variants = ["m0d5", "m3d3", "m3d2", "m1d3"]
im = {v: [load_rgb(f"/tmp/rr3/{v}-{s}.exr") for s in (1, 2)] for v in variants}
old = [load_rgb(f"/tmp/cafe-s28/mcc-wide-{s}.exr") for s in (1, 2)]
cy = [load_rgb(f"/tmp/cafe-s28/cycles-wide-{s}.exr") for s in (1, 2)]
print("m0d5 == run F bits:", all(np.array_equal(a, b) for a, b in zip(im["m0d5"], old)))
r = (sum(old) + sum(cy)) / 4  # error.py's common r
for v in variants + ["cycles"]:
    a, b = cy if v == "cycles" else im[v]
    rel = float(np.mean((a - b) ** 2 / 2.0 / (r * r + 0.01)))
    print(v, "relMSE(var part, run F's r) %.4e" % rel)
