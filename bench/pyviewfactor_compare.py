#!/usr/bin/env python3
"""Exact form factors of radiosity against pyviewfactor, on the same polygon pairs.

For each pair of planar convex polygons below, computes F_12 (from polygon 1 to polygon 2)
with radiosity's `form_factor::exact::polygon_to_polygon` (through the example
`viewfactor_pairs`, which reads the pairs as JSON lines on stdin) and with pyviewfactor's
`compute_viewfactor`, times both per pair, and prints a Markdown table with the closed
forms of Howell's catalogue (C-11 parallel rectangles, C-14 perpendicular rectangles, the
formulas of crates/radiosity/src/form_factor/reference.rs) where one exists.

Conventions. Both codes integrate the same double contour integral (Stokes twice) and
both want each polygon counter-clockwise seen from its own front, the fronts facing each
other; the polygons here are built that way and checked with pyviewfactor's
`get_visibility`. `pyviewfactor.compute_viewfactor(cell1, cell2)` returns F(cell2 -> cell1)
(normalised by the area of cell2), so F_12 is `compute_viewfactor(poly2, poly1)`.
pyviewfactor does not clip polygons that are partly behind each other (radiosity does);
every pair here lies wholly in front of the other polygon, so the two compute the same
quantity.

Timing: each pair is computed once untimed (for pyviewfactor this also triggers Numba's
JIT compilation), then in batches doubled until a batch takes at least --min-time seconds;
the mean time per call of that batch is reported. "pvf" times the public call
(`compute_viewfactor` on pyvista PolyData: vertex extraction, rounding, area, SA-30
kernel); "pvf kernel" times the Numba kernel `compute_viewfactor_sa30` alone on prepared
arrays, for an engine-to-engine comparison.

Setup (outside the repository):

    python3 -m venv /tmp/pvf-venv
    /tmp/pvf-venv/bin/pip install pyviewfactor mpmath
    /tmp/pvf-venv/bin/python bench/pyviewfactor_compare.py

mpmath (optional) evaluates the closed forms at 40 digits; without it they are evaluated
in double precision. Not part of the test suite: it measures, it does not check.
"""
import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time

import numpy as np
import pyvista as pv
import pyviewfactor as pvf
from pyviewfactor.pvf_geometry_preprocess import face_to_array, polygon_area
from pyviewfactor.pvf_integrators import compute_viewfactor_sa30

try:
    import mpmath

    mpmath.mp.dps = 40
    M = mpmath
except ImportError:  # double precision fallback
    M = None

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# --- closed forms (reference.rs, Howell C-11 and C-14) --------------------------------

def _fns():
    if M is not None:
        return M.mpf, M.log, M.atan, M.sqrt, M.pi
    return float, math.log, math.atan, math.sqrt, math.pi


def parallel_rectangles(a, b, c):
    """F between identical directly opposed parallel a x b rectangles at distance c (C-11)."""
    f, log, atan, sqrt, pi = _fns()
    x, y = f(a) / f(c), f(b) / f(c)
    x2, y2 = x * x, y * y
    return 2 / (pi * x * y) * (
        log((1 + x2) * (1 + y2) / (1 + x2 + y2)) / 2
        + x * sqrt(1 + y2) * atan(x / sqrt(1 + y2))
        + y * sqrt(1 + x2) * atan(y / sqrt(1 + x2))
        - x * atan(x)
        - y * atan(y)
    )


def perpendicular_rectangles(w, h, l):
    """F from a w x l rectangle to a perpendicular h x l one sharing the edge l (C-14)."""
    f, log, atan, sqrt, pi = _fns()
    hh, ww = f(h) / f(l), f(w) / f(l)
    h2, w2 = hh * hh, ww * ww
    s = sqrt(h2 + w2)
    log_term = (
        log((1 + w2) * (1 + h2) / (1 + w2 + h2))
        + w2 * log(w2 * (1 + w2 + h2) / ((1 + w2) * (w2 + h2)))
        + h2 * log(h2 * (1 + h2 + w2) / ((1 + h2) * (h2 + w2)))
    )
    return 1 / (pi * ww) * (ww * atan(1 / ww) + hh * atan(1 / hh) - s * atan(1 / s) + log_term / 4)


# --- the pairs --------------------------------------------------------------------------

def newell_normal(poly):
    p = np.asarray(poly, dtype=float)
    q = np.roll(p, -1, axis=0)
    n = np.array([
        np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
        np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
        np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
    ])
    return n / np.linalg.norm(n)


def facing(poly, direction):
    """The polygon, reversed if needed so that it is counter-clockwise seen from `direction`."""
    poly = [list(map(float, v)) for v in poly]
    return poly if np.dot(newell_normal(poly), direction) > 0 else poly[::-1]


def rect_z(x0, x1, y0, y1, z, up):
    return facing([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], [0, 0, 1 if up else -1])


def regular_polygon(n, r, z, up):
    return facing([[r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n), z] for k in range(n)],
                  [0, 0, 1 if up else -1])


def pairs():
    """(name, p1, p2, closed form of F_12 or None)."""
    out = []
    out.append(("opposed unit squares, 1 apart",
                rect_z(0, 1, 0, 1, 0, True), rect_z(0, 1, 0, 1, 1, False),
                parallel_rectangles(1, 1, 1)))
    # p1 in z = 0 facing +z, p2 in y = 0 facing +y; the shared edge is x in [0, 1].
    out.append(("perpendicular unit squares, shared edge",
                rect_z(0, 1, 0, 1, 0, True),
                facing([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], [0, 1, 0]),
                perpendicular_rectangles(1, 1, 1)))
    out.append(("opposed 2 x 1 rectangles, 0.5 apart",
                rect_z(0, 2, 0, 1, 0, True), rect_z(0, 2, 0, 1, 0.5, False),
                parallel_rectangles(2, 1, 0.5)))
    # Shared edge of length l = 1.5 along x; p1 (width w = 2 along y) in z = 0 facing +z,
    # p2 (height h = 0.5 along z) in y = 0 facing +y.
    out.append(("perpendicular w=2, h=0.5, l=1.5 (w to h)",
                rect_z(0, 1.5, 0, 2, 0, True),
                facing([[0, 0, 0], [1.5, 0, 0], [1.5, 0, 0.5], [0, 0, 0.5]], [0, 1, 0]),
                perpendicular_rectangles(2, 0.5, 1.5)))
    out.append(("opposed regular 64-gons, r=1, 1 apart",
                regular_polygon(64, 1.0, 0, True), regular_polygon(64, 1.0, 1, False),
                None))
    # A convex quad in z = 0 facing +z, and a convex quad in the tilted plane
    # z = 1 + 0.3 x - 0.2 y facing down (z between 0.78 and 1.39 over it): each lies
    # wholly in front of the other.
    tilted = lambda x, y: [x, y, 1 + 0.3 * x - 0.2 * y]  # noqa: E731
    out.append(("general quads, tilted",
                facing([[0, 0, 0], [1.2, 0.1, 0], [1.0, 0.9, 0], [0.1, 0.7, 0]], [0, 0, 1]),
                facing([tilted(0.2, 0.1), tilted(1.1, 0.0), tilted(1.3, 0.8), tilted(0.3, 1.1)],
                       [0.3, -0.2, -1.0]),
                None))
    out.append(("distant unit squares, 10 apart",
                rect_z(0, 1, 0, 1, 0, True), rect_z(0, 1, 0, 1, 10, False),
                parallel_rectangles(1, 1, 10)))
    return out


# --- the two codes ---------------------------------------------------------------------

def run_radiosity(prs, binary):
    lines = "".join(json.dumps({"name": n, "p1": p1, "p2": p2}) + "\n" for n, p1, p2, _ in prs)
    if binary:
        cmd = [binary]
    else:
        cmd = ["cargo", "run", "--quiet", "--release", "-p", "radiosity", "--example", "viewfactor_pairs"]
    run = subprocess.run(cmd, input=lines, capture_output=True, text=True, cwd=REPO)
    if run.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{run.stderr}")
    out = [json.loads(l) for l in run.stdout.splitlines() if l.strip()]
    assert [o["name"] for o in out] == [n for n, *_ in prs], "radiosity answered other pairs"
    return out


def poly_data(poly):
    return pv.PolyData(np.array(poly, dtype=float), faces=[len(poly)] + list(range(len(poly))))


def time_per_call(fn, min_time):
    fn()  # untimed: JIT compilation, caches
    calls = 10
    while True:
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        dt = time.perf_counter() - t0
        if dt >= min_time:
            return dt / calls
        calls *= 2


def run_pyviewfactor(prs, min_time):
    out = []
    for name, p1, p2, _ in prs:
        c1, c2 = poly_data(p1), poly_data(p2)
        visible, msg = pvf.get_visibility(c1, c2, strict=True)
        assert visible, f"{name}: pyviewfactor says the polygons do not face each other ({msg})"
        f = pvf.compute_viewfactor(c2, c1)  # F(c1 -> c2): receiver first, emitter second
        t = time_per_call(lambda: pvf.compute_viewfactor(c2, c1), min_time)
        # The kernel alone, on the arrays compute_viewfactor prepares (rounded to 8 decimals).
        a2, a1 = face_to_array(c2), face_to_array(c1)
        const = 4.0 * np.pi * polygon_area(a1)
        fk = compute_viewfactor_sa30(a2, a1, const)
        assert fk == f or (fk < 0 and f == 0)
        tk = time_per_call(lambda: compute_viewfactor_sa30(a2, a1, const), min_time)
        # The kernel on the unrounded coordinates, to tell rounding from integration error.
        u2, u1 = np.array(p2, dtype=float), np.array(p1, dtype=float)
        fu = compute_viewfactor_sa30(u2, u1, 4.0 * np.pi * polygon_area(u1))
        out.append({"f": f, "seconds_per_pair": t, "kernel_seconds_per_pair": tk, "f_unrounded": fu})
    return out


# --- report ----------------------------------------------------------------------------

def fmt_f(x):
    return f"{x:.15f}"


def fmt_e(x):
    return "0" if x == 0 else f"{x:.1e}"


def fmt_us(s):
    return f"{s * 1e6:.3g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", help="the built viewfactor_pairs example (default: cargo run --release)")
    ap.add_argument("--min-time", type=float, default=0.02, help="seconds of work per timed batch (default 0.02)")
    args = ap.parse_args()

    prs = pairs()
    # Sanity: the closed forms reproduce Howell's published values.
    assert abs(float(parallel_rectangles(1, 1, 1)) - 0.1998248957) < 1e-10
    assert abs(float(perpendicular_rectangles(1, 1, 1)) - 0.2000437761) < 1e-10

    rad = run_radiosity(prs, args.binary)
    py = run_pyviewfactor(prs, args.min_time)

    print(f"pyviewfactor {pvf.__version__}, pyvista {pv.__version__}, numpy {np.__version__}, "
          f"Python {platform.python_version()}; closed forms "
          f"{'mpmath ' + mpmath.__version__ + ', 40 digits' if M is not None else 'double precision'}\n")
    print("| pair | closed form | radiosity F | pyviewfactor F | \\|difference\\| "
          "| radiosity error | pyviewfactor error | radiosity µs/pair | pvf µs/pair "
          "| pvf kernel µs/pair | speed ratio (pvf / radiosity) | kernel ratio |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for (name, _, _, exact), r, p in zip(prs, rad, py):
        fr, fp = r["f"], p["f"]
        if exact is not None:
            ex = exact
            er = fmt_e(float(abs(M.mpf(fr) - ex)) if M else abs(fr - ex))
            ep = fmt_e(float(abs(M.mpf(fp) - ex)) if M else abs(fp - ex))
            cf = fmt_f(float(exact))
        else:
            cf, er, ep = "—", "—", "—"
        print(f"| {name} | {cf} | {fmt_f(fr)} | {fmt_f(fp)} | {fmt_e(abs(fr - fp))} | {er} | {ep} "
              f"| {fmt_us(r['seconds_per_pair'])} | {fmt_us(p['seconds_per_pair'])} "
              f"| {fmt_us(p['kernel_seconds_per_pair'])} "
              f"| {p['seconds_per_pair'] / r['seconds_per_pair']:.3g} "
              f"| {p['kernel_seconds_per_pair'] / r['seconds_per_pair']:.3g} |")
    notes = [(name, r["f"], p) for (name, *_), r, p in zip(prs, rad, py) if p["f_unrounded"] != p["f"]]
    if notes:
        print("\npyviewfactor rounds vertex coordinates to 8 decimals (`rounding_decimal=8`) before "
              "integrating. Its kernel on the unrounded coordinates:\n")
        for name, fr, p in notes:
            print(f"- {name}: F = {fmt_f(p['f_unrounded'])}, |difference| to radiosity "
                  f"{fmt_e(abs(p['f_unrounded'] - fr))} (rounded: {fmt_e(abs(p['f'] - fr))})")


if __name__ == "__main__":
    main()
