"""What OIDN's own options do to the studio preview's denoise (docs/performance.md §1.7): a
480×270 random input with albedo and normal, fast quality, `cleanAux` off, through OIDN's C API
(ctypes; numpy from the Cycles venv): device `numThreads`, `setAffinity`, filter `maxMemoryMB`,
half-precision inputs, and the coarse stage's own sizes. Prints the median wall and CPU
milliseconds of 7 executions after a warm-up; CPU / 2 is about the idle 2-core wall time.

    MCCTRACE_OIDN=.venv/lib/python3.11/site-packages/pyoidn/oidn/lib \
        target/peers/cycles/venv/bin/python benches/oidn_options.py
"""
import ctypes as C, time, os, sys
import numpy as np
lib = C.CDLL(os.environ["MCCTRACE_OIDN"] + "/libOpenImageDenoise.so.2")
lib.oidnNewDevice.restype = C.c_void_p
lib.oidnNewFilter.restype = C.c_void_p
lib.oidnNewFilter.argtypes = [C.c_void_p, C.c_char_p]
for f in ["oidnCommitDevice", "oidnCommitFilter", "oidnExecuteFilter", "oidnReleaseFilter", "oidnReleaseDevice"]:
    getattr(lib, f).argtypes = [C.c_void_p]
lib.oidnSetDeviceInt.argtypes = [C.c_void_p, C.c_char_p, C.c_int]
lib.oidnSetDeviceBool.argtypes = [C.c_void_p, C.c_char_p, C.c_bool]
lib.oidnSetFilterInt.argtypes = [C.c_void_p, C.c_char_p, C.c_int]
lib.oidnSetFilterBool.argtypes = [C.c_void_p, C.c_char_p, C.c_bool]
lib.oidnSetSharedFilterImage.argtypes = [C.c_void_p, C.c_char_p, C.c_void_p, C.c_int, C.c_size_t, C.c_size_t, C.c_size_t, C.c_size_t, C.c_size_t]
lib.oidnGetDeviceError.argtypes = [C.c_void_p, C.POINTER(C.c_char_p)]
FLOAT3, HALF3 = 3, 259
rng = np.random.default_rng(1)

def run(threads=None, affinity=None, mem=None, half=False, size=(480, 270), quality=4, n=7):
    dev = lib.oidnNewDevice(1)
    if threads is not None: lib.oidnSetDeviceInt(dev, b"numThreads", threads)
    if affinity is not None: lib.oidnSetDeviceBool(dev, b"setAffinity", affinity)
    lib.oidnCommitDevice(dev)
    w, h = size
    dt = np.float16 if half else np.float32
    col = (rng.random((h, w, 3)) * 2).astype(dt)
    alb = rng.random((h, w, 3)).astype(dt)
    nrm = (rng.random((h, w, 3)) * 2 - 1).astype(dt)
    out = np.zeros((h, w, 3), dt)
    f = lib.oidnNewFilter(dev, b"RT")
    fmt = HALF3 if half else FLOAT3
    for name, a in [(b"color", col), (b"albedo", alb), (b"normal", nrm), (b"output", out)]:
        lib.oidnSetSharedFilterImage(f, name, a.ctypes.data, fmt, w, h, 0, 0, 0)
    lib.oidnSetFilterBool(f, b"hdr", True)
    lib.oidnSetFilterInt(f, b"quality", quality)
    if mem is not None: lib.oidnSetFilterInt(f, b"maxMemoryMB", mem)
    lib.oidnCommitFilter(f)
    lib.oidnExecuteFilter(f)
    walls, cpus = [], []
    for _ in range(n):
        t, c = time.perf_counter(), time.process_time()
        lib.oidnExecuteFilter(f)
        walls.append(time.perf_counter() - t); cpus.append(time.process_time() - c)
    msg = C.c_char_p()
    err = lib.oidnGetDeviceError(dev, C.byref(msg))
    lib.oidnReleaseFilter(f); lib.oidnReleaseDevice(dev)
    return sorted(walls)[n // 2], sorted(cpus)[n // 2], err

print("load", open("/proc/loadavg").read().strip())
print("option,size,wall_ms,cpu_ms,cpu_ms/2")
cases = [
    ("default (2 threads, affinity on)", {}),
    ("numThreads 1", {"threads": 1}),
    ("setAffinity off", {"affinity": False}),
    ("maxMemoryMB 32", {"mem": 32}),
    ("maxMemoryMB 256", {"mem": 256}),
    ("half-precision inputs", {"half": True}),
    ("coarse 120x68", {"size": (120, 68)}),
    ("240x135", {"size": (240, 135)}),
]
for name, kw in cases:
    w, c, e = run(**kw)
    size = kw.get("size", (480, 270))
    print(f"{name},{size[0]}x{size[1]},{w*1e3:.1f},{c*1e3:.1f},{c*5e2:.1f}" + (f",error {e}" if e else ""))
print("load", open("/proc/loadavg").read().strip())
