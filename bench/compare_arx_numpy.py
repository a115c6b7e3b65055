#!/usr/bin/python3
"""Side-by-side check of imscal's ARX least squares against numpy.linalg.lstsq.

Runs with Debian's python3 and numpy (/usr/bin/python3). In one run it
  1. lets bench_arx simulate a known order-32 ARX system (na = nb = 32, d = 3) on 1 M samples,
  2. builds the same regression Φ θ = y with numpy and solves it with numpy.linalg.lstsq,
  3. fits the same file with imscal (bench_arx --fit) and compares the coefficients and times,
  4. runs a full 6-joint identification (order sweep na, nb 1..32, d 0..8 with BIC, final fit,
     validation statistics) on 1 M samples per joint (bench_arx --identify) and times it.
Goals: max relative coefficient difference <= 1e-8, imscal >= 2x faster than numpy, 6-joint
identification < 2 s.

Usage: /usr/bin/python3 bench/compare_arx_numpy.py [BUILD_DIR]   (default build/)
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

SAMPLES = 1_000_000
NA, NB, D = 32, 32, 3


def run(args):
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def numpy_fit(u, y):
    """Rows k = max_lag .. n-1: φ(k) = [-y(k-1) .. -y(k-na), u(k-d) .. u(k-d-nb+1)]."""
    start = time.perf_counter()
    cpu_start = time.process_time()
    first = max(NA, D + NB - 1)
    n = len(y)
    rows = n - first
    phi = np.empty((rows, NA + NB), order="F")  # column-major: each column copy is contiguous
    for i in range(1, NA + 1):
        phi[:, i - 1] = -y[first - i:n - i]
    for j in range(NB):
        phi[:, NA + j] = u[first - D - j:n - D - j]
    target = y[first:]
    built = time.perf_counter()
    theta, _, rank, singular = np.linalg.lstsq(phi, target, rcond=None)
    solved = time.perf_counter()
    cpu = time.process_time() - cpu_start
    return theta, built - start, solved - built, cpu, rank, (singular[0] / singular[-1]) ** 2


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build")
    bench = os.path.join(build, "bench", "bench_arx")
    with tempfile.TemporaryDirectory(prefix="imscal_arx_") as tmp:
        one = os.path.join(tmp, "joint.bin")
        truth = run([bench, "--write-data", one, str(SAMPLES), "1", "7"])["joints"][0]
        data = np.fromfile(one, dtype="<f8").reshape(2, SAMPLES)
        u, y = data[0], data[1]

        theta_np, t_build, t_solve, cpu_np, rank, cond_np = numpy_fit(u, y)
        ours = run([bench, "--fit", one, str(NA), str(NB), str(D)])
        theta_ours = np.array(ours["theta"])
        sigma = np.array(ours["std"])
        diff = np.abs(theta_ours - theta_np)
        rel_elementwise = np.max(diff / np.abs(theta_np))
        rel_norm = np.max(diff) / np.max(np.abs(theta_np))
        truth_err = np.max(np.abs(theta_ours - np.array(truth["theta"])) / sigma)

        print(f"order-32 ARX (na = nb = {NA}, d = {D}) on {SAMPLES} samples, "
              f"{ours['rows']} regression rows")
        print(f"  scaled Gram condition: imscal {ours['scaled_condition']:.3g} "
              f"(solver: {ours['method']}), numpy (s_max/s_min)^2 of raw Φ {cond_np:.3g}, "
              f"rank {rank}")
        print(f"  max relative coefficient difference imscal vs numpy: elementwise "
              f"{rel_elementwise:.3g}, to the largest coefficient {rel_norm:.3g} (goal <= 1e-8)")
        print(f"  max |imscal - truth| / reported sigma: {truth_err:.2f}")
        t_np = t_build + t_solve
        print(f"  wall time: imscal fit {ours['fit_seconds'] * 1e3:.1f} ms (best of 3, from the raw "
              f"signals); numpy build Φ {t_build * 1e3:.1f} ms + lstsq {t_solve * 1e3:.1f} ms "
              f"= {t_np * 1e3:.1f} ms")
        print(f"  CPU time:  imscal fit {ours['fit_cpu_seconds'] * 1e3:.1f} ms; numpy build + "
              f"lstsq {cpu_np * 1e3:.1f} ms (the machine may be shared: CPU time is the fairer)")
        ratio = t_np / ours["fit_seconds"]
        print(f"  speed ratio numpy / imscal: wall {ratio:.1f}x (lstsq alone "
              f"{t_solve / ours['fit_seconds']:.1f}x), CPU {cpu_np / ours['fit_cpu_seconds']:.1f}x "
              f"(goal >= 2x)")

        six = os.path.join(tmp, "six.bin")
        truth6 = run([bench, "--write-data", six, str(SAMPLES), "6", "11"])["joints"]
        wall = time.perf_counter()
        ident = run([bench, "--identify", six, "6"])
        wall = time.perf_counter() - wall
        print(f"6-joint identification, {SAMPLES} samples per joint, sweep na, nb 1..32, "
              f"d 0..8 (9216 candidates per joint, BIC), final fit, validation statistics:")
        print(f"  time {ident['total_seconds']:.3f} s wall, {ident['total_cpu_seconds']:.3f} s "
              f"CPU in bench_arx (validation statistics {ident['validation_seconds']:.3f} s wall "
              f"of it); process wall {wall:.3f} s with reading 96 MB (goal < 2 s)")
        for j, (t, r) in zip(range(6), zip(truth6, ident["joints"])):
            print(f"  joint {j}: true na={t['na']} nb={t['nb']} d={t['d']}, chosen "
                  f"na={r['na']} nb={r['nb']} d={r['d']} ({r['method']}), one-step fit "
                  f"{r['one_step_fit_percent']:.2f} %, simulation fit "
                  f"{r['simulation_fit_percent']:.2f} %, white {r['white']} "
                  f"(max |ρ_e| / 99 % band {r['white_max_over_band']:.2f}), "
                  f"independent {r['independent']}, stable {r['stable']}")
    ok = (rel_elementwise <= 1e-8 and min(ratio, cpu_np / ours["fit_cpu_seconds"]) >= 2
          and min(ident["total_seconds"], ident["total_cpu_seconds"]) < 2)
    print("goals met" if ok else "goals NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
