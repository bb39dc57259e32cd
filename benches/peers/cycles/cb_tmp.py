import sys, numpy as np
sys.path.insert(0, "/work/main/benches/peers/cycles")
from render import load_rgb
ref = load_rgb("/work/main/tests/data/cornell/reference-mitsuba3-16384spp.exr")
for v in sys.argv[1].split(","):
    rs = []
    for s in (1, 2, 3, 4):
        a = load_rgb(f"/tmp/cb/{v}-{s}.exr")
        rs.append(np.mean((a - ref) ** 2 / (ref * ref + 0.01)))
    print(v, "relMSE %.4e" % np.mean(rs), " ".join("%.3e" % x for x in rs))
