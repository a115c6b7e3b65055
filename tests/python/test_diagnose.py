"""imscal.diagnose against `imscal diagnose` on the same files, with and without the q_internal
block of the measured joint errors."""
import json

import numpy as np
import pytest

import imscal
from test_ident import joint_motion, write_csv

NAMES = [f"A{j}" for j in range(1, 7)]
HEADER = "# imscal-joint-errors: 1\n# robot: kr16\n# cycle_s: 0.002\n"


def columns(*kinds):
    return [f"q_{kind}_{n}_rad" for kind in kinds for n in NAMES]


@pytest.fixture(scope="module")
def records(tmp_path_factory, repo, cli):
    """"real": the lagging joints of test_ident with and without the encoders' block; "sim": a
    model that predicts no joint error (q_measured = q_desired). Each diagnosed by the command
    line and by Python."""
    folder = tmp_path_factory.mktemp("diagnose")
    t, q_d, q_m = joint_motion()
    write_csv(folder / "real.csv", HEADER, columns("desired", "measured", "internal"), t,
              [q_d, q_m, q_m])
    write_csv(folder / "real_one_sensor.csv", HEADER, columns("desired", "measured"), t,
              [q_d, q_m])
    write_csv(folder / "sim.csv", HEADER, columns("desired", "measured", "internal"), t,
              [q_d, q_d, q_d])
    robot = repo / "datasets" / "robots" / "kr16.yaml"
    reports = {}
    for name in ["real", "real_one_sensor"]:
        done = cli("diagnose", "--joint-errors", folder / f"{name}.csv", "--sim-joint-errors",
                   folder / "sim.csv", "--robot", robot, "--out", folder / name)
        python = imscal.diagnose(str(folder / f"{name}.csv"), str(robot),
                                 sim_joint_errors=str(folder / "sim.csv"))
        reports[name] = (json.loads((folder / name / "report.json").read_text()),
                         (folder / name / "report.txt").read_text(), done, python)
    return folder, robot, reports


@pytest.mark.parametrize("name", ["real", "real_one_sensor"])
def test_diagnose_matches_the_command_line(records, name):
    _, _, reports = records
    report, text, done, python = reports[name]
    # The same session on the same files: report.json and report.txt equal, the verdict printed.
    assert python["report"] == report
    assert python["text"] == text
    assert python["verdict"] in done.stdout.splitlines()


def test_the_gap_is_the_joint_error_with_or_without_the_internal_block(records):
    _, _, reports = records
    _, q_d, q_m = joint_motion()
    for name in ["real", "real_one_sensor"]:
        python = reports[name][3]
        # Independent truth: the sim predicts no error, so the gap is q_desired - q_measured of
        # the generated data (the files hold the shortest repr of each double: exact).
        np.testing.assert_array_equal(python["gap_rad"], q_d - q_m)


# The parts of report.json that never read q_internal: the gap, where it lies, the model error,
# and the candidates built from q_desired, its torques or the IMS chain.
SAME_KEYS = ["samples", "cycle_s", "band_edges_hz", "gap_rms_rad", "gap_rms_per_joint_rad",
             "heldout_gap_rms_rad", "where", "model_error", "significant_gap"]
DESIRED_ONLY = {"time_offset", "structural_resonance", "gear_compliance", "kinematic_parameters",
                "sensor_mounting", "ims_scale_factor", "ims_bias"}


def test_without_the_internal_block_the_parts_that_do_not_read_it_agree(records):
    _, _, reports = records
    with_block, without = reports["real"][0], reports["real_one_sensor"][0]
    for key in SAME_KEYS:
        assert without[key] == with_block[key], key
    by_name = lambda report: {(c["effect"], c["joint"]): c for c in report["candidates"]}
    a, b = by_name(with_block), by_name(without)
    same = [k for k in a if k[0] in DESIRED_ONLY]
    assert len(same) >= 18  # time offset, resonance, compliance on the 6 joints, and the chain's
    for key in same:
        assert b[key] == a[key], key
    # The command says what it does without the block, naming the file and the columns.
    done = reports["real_one_sensor"][2]
    warning = [l for l in (done.stdout + done.stderr).splitlines() if "q_internal" in l]
    assert len(warning) == 1 and "real_one_sensor.csv" in warning[0]
    assert "transmission error is not tried" in warning[0]
    assert not any("q_internal" in l for l in reports["real"][2].stdout.splitlines())
    # The transmission error needs the motor angle: tried with the block only.
    assert any(k[0] == "transmission_error" for k in a)
    assert not any(k[0] == "transmission_error" for k in b)


def test_a_missing_sim_side_is_an_input_error(records):
    folder, robot, _ = records
    with pytest.raises(imscal.InputError) as caught:
        imscal.diagnose(str(folder / "real.csv"), str(robot))
    assert (caught.value.file, caught.value.field) == (str(folder / "real.csv"), "table")
