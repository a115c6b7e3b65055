#!/usr/bin/env python3
"""Plots a run's joint errors (q_desired - q_measured, the paper's delta q) per joint over time.

    python3 examples/python/plot_joint_errors.py [JOINT_ERRORS_CSV] [PNG]

Defaults: out/campaign/calibrate/joint_errors.csv (the main job's, `scripts/setup.sh`) and
joint_errors.png. Needs `import imscal` (scripts/setup.sh puts the module on the user's Python
path; or PYTHONPATH=build/python) and matplotlib. Prints the RMS and peak error of every joint.
"""
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import imscal  # noqa: E402


def main(argv):
    source = argv[1] if len(argv) > 1 else "out/campaign/calibrate/joint_errors.csv"
    target = argv[2] if len(argv) > 2 else "joint_errors.png"
    try:
        log = imscal.read_joint_errors(source)
    except imscal.InputError as error:  # names file, line and field, as the command line does
        print(f"error: {error}", file=sys.stderr)
        return 2
    error_mrad = (log["q_desired_rad"] - log["q_measured_rad"]) * 1e3
    names = log["joint_names"]
    figure, axes = plt.subplots(len(names), 1, sharex=True, figsize=(10, 1.6 * len(names)))
    for j, (axis, name) in enumerate(zip(np.atleast_1d(axes), names)):
        # One line per gap-free segment, so that a gap is not drawn as a straight line.
        for begin, end in log["segments"]:
            axis.plot(log["t_s"][begin:end], error_mrad[begin:end, j], lw=0.7, color="C0")
        axis.set_ylabel(f"{name} [mrad]")
        axis.grid(True, lw=0.3)
        rms = np.sqrt(np.mean(error_mrad[:, j] ** 2))
        peak = np.max(np.abs(error_mrad[:, j]))
        print(f"{name}: RMS {rms:.4f} mrad, peak {peak:.4f} mrad")
    axes[-1].set_xlabel("t [s] (robot clock)")
    figure.suptitle(f"Joint errors q_desired - q_measured: {source} (robot {log['robot']})")
    figure.tight_layout()
    figure.savefig(target, dpi=110)
    print(f"wrote {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
