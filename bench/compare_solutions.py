#!/usr/bin/env python3
"""Solution error per second of each form-factor method on the Cornell box.

Runs `radiosity solve` on the built-in Cornell box with each method and compares the
element radiosities with a reference (the contour method, exact geometry, with 8 x 8 by
8 x 8 point pairs for visibility): area-weighted RMS relative error of B (summed over
bands), the form-factor time the program reports, and their product (lower is better).

    cargo build --release
    python3 bench/compare_solutions.py [--max-area 4000] [--binary target/release/radiosity]

Not part of the test suite: it measures, it does not check.
"""
import argparse, csv, math, os, re, subprocess, sys, tempfile

METHODS = [
    ("area", ["--method", "area", "--steps", "1"]),
    ("area", ["--method", "area", "--steps", "2"]),
    ("area", ["--method", "area", "--steps", "4"]),
    ("contour", ["--method", "contour", "--steps", "2"]),
    ("analytic", ["--method", "analytic", "--steps", "2"]),
    ("analytic", ["--method", "analytic", "--steps", "4"]),
    ("hemicube", ["--method", "hemicube", "--resolution", "64"]),
    ("hemicube", ["--method", "hemicube", "--resolution", "256"]),
    ("montecarlo", ["--method", "montecarlo", "--samples", "256"]),
    ("montecarlo", ["--method", "montecarlo", "--samples", "4096"]),
]


def solve(binary, max_area, extra, out):
    cmd = [binary, "solve", "--max-area", str(max_area), "-o", out] + extra
    run = subprocess.run(cmd, capture_output=True, text=True, check=True)
    seconds = float(re.search(r"in ([0-9.]+) s \(", run.stderr).group(1))
    method = re.search(r"form factors \(([^)]*)\)", run.stderr).group(1)
    return method, seconds


def load(path):
    with open(path) as f:
        return [(float(r["area"]), sum(float(r[k]) for k in ("radiosity_r", "radiosity_g", "radiosity_b"))) for r in csv.DictReader(f)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-area", type=float, default=4000)
    ap.add_argument("--binary", default="target/release/radiosity")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ref_path = os.path.join(tmp, "ref.csv")
        ref_method, ref_s = solve(args.binary, args.max_area, ["--method", "contour", "--steps", "8"], ref_path)
        ref = load(ref_path)
        print(f"Cornell box, MAX_PATCH_AREA {args.max_area}: {len(ref)} elements; reference {ref_method} ({ref_s:.2f} s)\n")
        print("| method | RMS relative error of B | form factors (s) | error x seconds |")
        print("|---|---:|---:|---:|")
        for _, extra in METHODS:
            path = os.path.join(tmp, "m.csv")
            method, seconds = solve(args.binary, args.max_area, extra, path)
            got = load(path)
            num = sum(a * (b - r) ** 2 for (a, b), (_, r) in zip(got, ref))
            den = sum(a * r ** 2 for a, r in ref)
            err = math.sqrt(num / den)
            print(f"| {method} | {err:.2e} | {seconds:.3f} | {err * seconds:.2e} |")


if __name__ == "__main__":
    sys.exit(main())
